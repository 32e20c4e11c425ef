"""Acceleration records in NI LabVIEW Measurement files (``.lvm``), parsed by the ``lvm-read`` package.

An LVM file is text: a file header (``LabVIEW Measurement``, ``Separator``, ``Decimal_Separator``,
``X_Columns``, ``Date``, ``Time``, ... up to ``***End_of_Header***``), then a data segment with its own header
(``Channels``, ``Samples``, ``Date``, ``Time``, ``Y_Unit_Label``, ``X0``, ``Delta_X``, one value per channel, up
to ``***End_of_Header***``), a line of column names (``X_Value``, the channels' names, ``Comment``) and the
rows. The channels keep their names; their positions come from the campaign's channel table. ``Delta_X`` (s)
gives the sampling rate (every channel's must agree), else a uniform ``X_Value`` column, else the option
``sampling_rate``; the segment's (else the file's) ``Date`` and ``Time`` give the start time, as written (the
logging computer's clock: a time without zone is read as UTC, as every record's; give ``start_time`` to
correct it). ``Y_Unit_Label`` gives each channel's unit: as in a TOA5 file (:mod:`~.columns`), a channel whose
unit is not one of acceleration is left out and listed in the record's ``notes``, unless the option
``channels`` names the channels; without unit labels every channel is read, in ``unit`` (default m/s²).

Only one data segment is read: a file of several (a header before each block) is refused. ``X_Columns =
Multi`` (one X column per channel) is refused too.

Safety: the package's ``read(filename)`` loads ``<filename>.pkl`` when such a file lies beside the record (a
pickle runs code when loaded) and may write one. This reader never calls it: it reads the file's text itself
and hands it to ``lvm_read.read_str``, which parses a string and touches no file. An input is only read.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from typing import Any

import lvm_read
import numpy as np

from ...core.errors import InputError
from ...core.record import Record
from .base import RecordReader, file_head
from .columns import by_channels, by_units, text_positions
from .rates import STORED_RTOL, FileRate, printed_resolution, resolved_rate
from .validation import TIME_TOLERANCE, one_line, rate_from_time, validated_record

__all__ = ["READER", "LvmReader", "record_from_lvm"]

#: The options of this reader.
LVM_OPTIONS = ("unit", "sampling_rate", "channels", "override_sampling_rate")
#: The first bytes of an LVM file.
MAGIC = b"LabVIEW Measurement"
#: A Delta_X printed so coarsely that its rate is known to worse than this (relative) gets a note: 1e-4 in the
#: rate is 2e-4 in the tension, what an identification resolves at best (0.010000 s, 5e-5, says nothing).
ROUNDED_NOTE = 1e-4
#: Most bytes of an LVM file read (its text is parsed in memory, several times its size).
MAX_BYTES = 1 << 30
_DATE = re.compile(r"^\s*(\d{4})[/-](\d{1,2})[/-](\d{1,2})\s*$")
_TIME = re.compile(r"^\s*(\d{1,2}):(\d{2})(?::(\d{2})(?:[.,](\d+))?)?\s*$")


class LvmReader(RecordReader):
    """LVM records (:func:`record_from_lvm`). By content: a first line ``LabVIEW Measurement``."""

    name = "lvm"
    suffixes = (".lvm",)

    def can_open(self, path: str | os.PathLike) -> bool:
        return file_head(path, 32).removeprefix(b"\xef\xbb\xbf").startswith(MAGIC)

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`record_from_lvm` with the options ``unit``, ``sampling_rate``, ``channels`` and
        ``override_sampling_rate``."""
        return record_from_lvm(path, positions, **{k: v for k, v in options.items() if k in LVM_OPTIONS})


READER = LvmReader()


def record_from_lvm(path: str | os.PathLike, positions: Mapping[str, float] | None = None, *,
                    unit: str | None = None, sampling_rate: float | None = None,
                    channels: Sequence[str] | None = None, override_sampling_rate: bool = False) -> Record:
    """Read a record from an LVM file (see the module docstring).

    Raises
    ------
    InputError
        Naming the file: not an LVM file, a file the package cannot parse, several segments, channels that
        disagree on ``Delta_X`` (field ``sampling_rate``), no rate and no ``sampling_rate``, a start time that
        is not a date and time (field ``start_time``), and the checks of every record.
    """
    file = os.fspath(path)
    text = _text(file)
    if not text.lstrip("\ufeff").startswith("LabVIEW Measurement"):
        first = text.lstrip("\ufeff").split("\n", 1)[0].strip()
        raise InputError(f"not an LVM file: its first line is {first[:60]!r}, expected 'LabVIEW Measurement'",
                         file=file)
    try:
        lvm = lvm_read.read_str(text)
    except Exception as err:  # noqa: BLE001 (the package raises what its parsing meets: ValueError, IndexError...)
        raise InputError(f"cannot read the file as LVM (a header cut short or malformed?): {type(err).__name__} "
                         f"{one_line(err)}", file=file) from None
    if str(lvm.get("X_Columns", "One")).strip() == "Multi":
        raise InputError("X_Columns = Multi (an X column per channel) is not read: write the measurement with one "
                         "X column (or none)", field="X_Columns", file=file)
    segments = lvm.get("Segments", 0)
    if segments != 1:
        raise InputError(f"holds {segments} data segments (a header before each); this toolkit reads a file of one: "
                         "write the measurement with one header only", field="acceleration", file=file)
    segment = lvm[0]
    data = np.asarray(segment.get("data", np.empty((0, 0))), dtype=float)
    columns = [str(name).strip() for name in segment.get("Channel names", [])]
    has_x = str(lvm.get("X_Columns", "One")).strip() != "No"
    if data.ndim != 2 or data.shape[0] == 0 or not columns:
        raise InputError("the data segment holds no rows (no X_Value line, or a wrong separator?)",
                         field="acceleration", file=file)
    width = min(data.shape[1], len(columns))
    times = data[:, 0] if has_x and columns[0] == "X_Value" else None
    first = 1 if times is not None else 0
    names = [name for name in columns[first:width] if name != "Comment"]
    count = len(names)
    if len(set(names)) != count or not all(names):
        duplicate = next((name for name in names if names.count(name) > 1 or not name), "")
        raise InputError(f"channel names must be unique and non-empty, got {duplicate!r} twice or blank "
                         f"(names: {', '.join(map(repr, names))})", field="channel_name", file=file)
    values = data[:, first:first + count]
    labels = _per_channel(segment, "Y_Unit_Label", count)
    if labels is not None and any(labels):
        selection = by_units(names, labels, channels, unit, file)
    else:
        selection = by_channels(names, channels, unit or "m/s^2", file)
    replaced = list(selection.replaced)
    found = _file_rate(segment, text, count, times, sampling_rate, file)
    rate = resolved_rate(sampling_rate, found, override=override_sampling_rate, file=file, replaced=replaced)
    if rate is None:
        raise InputError("no sampling rate: the segment has no Delta_X and no X_Value column; give sampling_rate in "
                         "record_format", field="sampling_rate", file=file)
    notes = list(selection.notes())
    if found is not None and found.source == "Delta_X" and sampling_rate is None and found.rtol > ROUNDED_NOTE:
        notes.append(f"sampling rate {rate:.9g} Hz from Delta_X {found.detail}, printed to a few digits only "
                     f"({found.rtol:.1e} relative): give sampling_rate in record_format if the exact rate is known")
    keep = [names.index(name) for name in selection.names]
    acceleration = values[:, keep] * np.asarray(selection.scales)
    channel_positions = text_positions(selection, positions, file, channels is not None)
    return validated_record(acceleration, rate, list(selection.names), channel_positions, unit="m/s^2",
                            start_time=_start_time(segment, lvm, file), source=file, replaced=replaced,
                            notes=notes)


def _text(file: str) -> str:
    """The file's text: UTF-8, else Windows-1252 (LabVIEW writes the computer's code page)."""
    try:
        size = os.path.getsize(file)
        if size > MAX_BYTES:
            raise InputError(f"holds {size} bytes; at most {MAX_BYTES} are read", field="acceleration", file=file)
        with open(file, "rb") as stream:
            raw = stream.read()
    except FileNotFoundError:
        raise InputError("file not found", file=file) from None
    except OSError as err:
        raise InputError(f"cannot read the file: {one_line(err)}", file=file) from None
    if b"\0" in raw[:4096]:
        raise InputError("not an LVM file: it holds binary data (LVM is text)", file=file)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("cp1252", errors="replace")


def _per_channel(segment: Mapping[str, Any], key: str, count: int) -> list[str] | None:
    """The segment header's ``key`` values, one per channel, as text (None if the header has no such line)."""
    values = segment.get(key)
    if values is None:
        return None
    values = [str(v).strip() for v in (values if isinstance(values, list) else [values])]
    return (values + [""] * count)[:count]


def _file_rate(segment: Mapping[str, Any], text: str, count: int, times: np.ndarray | None, given: float | None,
               file: str) -> FileRate | None:
    """The rate of ``Delta_X`` (every channel's agreeing within its printed digits), else of the X_Value column."""
    steps = segment.get("Delta_X")
    printed = _printed_delta_x(text, count)
    if isinstance(steps, list) and steps[:count]:
        steps = [float(s) if isinstance(s, int | float) and not isinstance(s, bool) else np.nan for s in steps[:count]]
        given = [s for s in steps if np.isfinite(s)]
        if given:
            if len(given) != count or min(given) <= 0:
                raise InputError(f"Delta_X must be one number > 0 s per channel, got {steps}; give sampling_rate in "
                                 "record_format", field="sampling_rate", file=file)
            resolution = max((printed_resolution(p) or 0.0) for p in printed) if printed else 0.0
            step = given[0]
            rtol = 0.5 * resolution / step + STORED_RTOL  # half a unit of the last printed digit
            if max(given) - min(given) > rtol * step:
                raise InputError(f"the channels have different Delta_X ({', '.join(map(str, printed or given))} s)",
                                 field="sampling_rate", file=file)
            return FileRate(1.0 / step, "Delta_X", rtol=rtol, detail=f"{printed[0] if printed else f'{step:g}'} s")
    if times is not None and times.size >= 2:
        return _x_rate(times, text, given, file)
    return None


def _x_rate(times: np.ndarray, text: str, given: float | None, file: str) -> FileRate | None:
    """The rate of the X_Value column: uniform within TIME_TOLERANCE (as a CSV time column in seconds), or, with
    a ``given`` rate to compare, from its span, to the resolution its first and last values are printed to."""
    span = float(times[-1] - times[0])
    if given is not None:
        if not np.isfinite(span) or span <= 0:
            return None
        rows = [line for line in text.splitlines() if line.strip()]
        start = next((k for k, line in enumerate(rows) if line.startswith("X_Value")), len(rows) - 1) + 1
        ends = [re.split(r"[\t,;]", rows[k], maxsplit=1)[0] for k in (start, -1) if start < len(rows)]
        resolution = max([printed_resolution(end.replace(",", ".")) or 0.0 for end in ends] or [0.0])
        rate = (times.size - 1) / span
        return FileRate(rate, "X_Value column", rtol=resolution / span + TIME_TOLERANCE,
                        detail=f"{times.size} samples over {span:.9g} s, printed to {resolution:g} s")
    try:
        rate = rate_from_time(times, "X_Value", file)
    except InputError as err:
        raise InputError(f"{err.message}; the segment has no Delta_X: give sampling_rate in record_format",
                         field="sampling_rate", file=file) from None
    return FileRate(rate, "X_Value column", detail=f"steps of {1 / rate:.6g} s")


def _printed_delta_x(text: str, count: int) -> list[str]:
    """``Delta_X`` of the first segment header as printed (its digits say how far it is rounded)."""
    for line in text.splitlines()[:200]:
        if line.startswith("Delta_X"):
            fields = [f.strip() for f in re.split(r"[\t,;]", line)[1:]]
            return [f for f in fields if f][:count]
    return []


def _start_time(segment: Mapping[str, Any], lvm: Mapping[str, Any], file: str) -> str | None:
    """ISO 8601 of the segment's first Date and Time (else the file header's), to the microsecond."""
    dates, times = segment.get("Date"), segment.get("Time")
    date = (dates[0] if isinstance(dates, list) and dates else dates) or lvm.get("Date")
    time = (times[0] if isinstance(times, list) and times else times) or lvm.get("Time")
    if not date:
        return None
    day, clock = _DATE.match(str(date)), _TIME.match(str(time or "00:00"))
    if day is None or clock is None:
        raise InputError(f"Date {date!r} and Time {time!r} are not a date (YYYY/MM/DD) and a time (hh:mm:ss.f); "
                         "give start_time in record_format", field="start_time", file=file)
    year, month, mday = (int(g) for g in day.groups())
    hour, minute = int(clock.group(1)), int(clock.group(2))
    second = int(clock.group(3) or 0)
    fraction = (clock.group(4) or "")[:6]
    stamp = f"{year:04d}-{month:02d}-{mday:02d}T{hour:02d}:{minute:02d}:{second:02d}"
    return stamp + (f".{fraction.ljust(6, '0')}" if fraction.strip("0") else "")
