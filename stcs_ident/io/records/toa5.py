"""Acceleration records in Campbell Scientific TOA5 files (``.dat``, the ASCII table of a CR logger).

Four header lines, comma-separated and quoted, then one row per sample::

    "TOA5","CR1000X_Stay3","CR1000X","12345","CR1000X.Std.04.02","CPU:stay.CR1X","34567","Accel"
    "TIMESTAMP","RECORD","BattV","acc1","acc2"
    "TS","RN","Volts","g","m/s^2"
    "","","Smp","Smp","Smp"
    "2026-03-01 00:00:00.01",0,12.5,0.0012,-0.0113

Line 1 is the environment (station, logger, program, table), line 2 the column names, line 3 their units,
line 4 the processing. ``TIMESTAMP`` gives the start time and the sampling interval, uniform within the
resolution it is printed to (as a CSV time column of date-times, :mod:`~.csv_text`); ``RECORD`` and every
other column whose unit is not one of acceleration are left out, and the record's ``notes`` list them
(the ``RECORD`` counter must step by one: a lost sample, which timestamps printed to the sampling interval
cannot show, is refused unless ``sampling_rate`` is given)
(:mod:`~.columns`); each acceleration column keeps its own unit. The option ``channels`` names the channels
instead (their unit then must be one of acceleration, or ``unit`` gives it); ``unit`` replaces the units of the
channels read, ``sampling_rate`` stands in for or must agree with the timestamps' rate
(:mod:`~.rates`). Positions come from the campaign's channel table. A ``NAN`` sample is refused as any
non-finite sample. The file is recognised by its content (a first line starting with ``TOA5``) whatever its
suffix; a ``.dat`` of another kind is read by the reader its content names, as a text table if it is text,
else refused in one line naming the layouts expected.
"""

from __future__ import annotations

import csv
import itertools
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from ...core.errors import InputError
from ...core.record import Record
from . import csv_text
from .base import RecordReader, file_head
from .columns import by_units
from .csv_text import read_table, table_record
from .validation import one_line

__all__ = ["READER", "TIME_COLUMN", "Toa5Reader", "record_from_toa5"]

#: The time column of a TOA5 table.
TIME_COLUMN = "TIMESTAMP"
#: The record counter of a TOA5 table: one more each row, unless samples were lost.
RECORD_COLUMN = "RECORD"
#: The options of this reader.
TOA5_OPTIONS = ("unit", "sampling_rate", "channels", "override_sampling_rate")


def is_toa5(head: bytes) -> bool:
    """Whether a file's first bytes are a TOA5 header (``TOA5`` or ``"TOA5"`` opening the first line)."""
    head = head.removeprefix(b"\xef\xbb\xbf")
    return head.startswith((b'"TOA5"', b"TOA5,", b"TOA5\r")) or head == b"TOA5"


class Toa5Reader(RecordReader):
    """TOA5 records (:func:`record_from_toa5`). By content: a first line starting with ``TOA5``.

    ``.dat`` is a suffix many formats use (``generic_suffixes``): :func:`~.base.reader_for` gives a ``.dat``
    whose content another reader recognises (a CSV table, an HDF5 file) to that reader; one no reader
    recognises comes here: text is read as a text table (a header after a preamble), anything else is refused.
    """

    name = "toa5"
    suffixes = (".dat",)
    generic_suffixes = (".dat",)

    def can_open(self, path: str | os.PathLike) -> bool:
        return is_toa5(file_head(path, 16))

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`record_from_toa5` with the options ``unit``, ``sampling_rate``, ``channels`` and
        ``override_sampling_rate``. A ``.dat`` that no reader recognised is read as a text table if it is text
        (:mod:`~.csv_text`, whose refusals name the options that read it), else refused naming the layouts
        expected."""
        file = os.fspath(path)
        if os.path.exists(file) and not self.can_open(file):
            head = file_head(file)
            if _is_text(head):  # a text table in a .dat: the CSV reader's rules (and refusals) apply
                return csv_text.READER.read(path, positions=positions, **options)
            raise InputError("not a record layout this toolkit reads: expected a Campbell Scientific TOA5 table (a "
                             "first line starting with \"TOA5\") or a text table (a header line naming the columns, "
                             "after any preamble: header_row in record_format); the file holds binary data",
                             file=file)
        return record_from_toa5(path, positions, **{k: v for k, v in options.items() if k in TOA5_OPTIONS})


READER = Toa5Reader()


def record_from_toa5(path: str | os.PathLike, positions: Mapping[str, float] | None = None, *,
                     unit: str | None = None, sampling_rate: float | None = None,
                     channels: Sequence[str] | None = None, override_sampling_rate: bool = False) -> Record:
    """Read a record from a TOA5 file (see the module docstring).

    Raises
    ------
    InputError
        Naming the file: not TOA5, a header of fewer than four lines or whose units line does not match the
        names, no acceleration column (field ``channels``), no ``TIMESTAMP`` and no ``sampling_rate``
        (field ``time``), timestamps that are not uniform, and the checks of every record.
    """
    file = os.fspath(path)
    lines = _header_lines(file)
    if len(lines) < 4 or not lines[0] or lines[0][0] != "TOA5":
        raise InputError(f"not a TOA5 file: expected four header lines (\"TOA5\" and the environment, the column "
                         f"names, their units, their processing) before the data, found {len(lines)} line(s)"
                         + ("" if lines and lines[0] and lines[0][0] == "TOA5" else " not starting with \"TOA5\""),
                         file=file)
    names, units = lines[1], lines[2]
    if len(units) != len(names):
        raise InputError(f"the units line (line 3) has {len(units)} fields for {len(names)} column names (line 2)",
                         field="unit", file=file)
    header, table = read_table(file, ",", 1, [1, 2])
    has_time = TIME_COLUMN in header
    if not has_time and sampling_rate is None:
        raise InputError(f"no {TIME_COLUMN} column among {', '.join(map(repr, header))}: give sampling_rate in "
                         "record_format", field="time", file=file)
    selection = by_units(header, units, channels, unit, file,
                         excluded={TIME_COLUMN: "the time column"} if has_time else {})
    if RECORD_COLUMN in header and sampling_rate is None:
        _check_records(table.iloc[:, header.index(RECORD_COLUMN)], file)
    station = f"TOA5 table {lines[0][7]!r} of station {lines[0][1]!r}" if len(lines[0]) >= 8 else "TOA5 table"
    return table_record(file, header, table, selection, positions or {}, time_column=TIME_COLUMN if has_time else None,
                        sampling_rate=sampling_rate, override=override_sampling_rate, decimal=".", header_row=1,
                        skip=[1, 2], notes=(f"read as a {station}",), channels_given=channels is not None)


def _check_records(column: Any, file: str) -> None:
    """Refuse a RECORD counter that does not step by one (samples lost, or tables appended): the timestamps,
    printed to the sampling interval, cannot show a lost sample."""
    numbers = np.asarray(pd.to_numeric(column.str.strip(), errors="coerce"), dtype=float)
    if numbers.size < 2 or not np.isfinite(numbers).all():
        return  # a counter that is not numbers says nothing: the timestamps decide
    jumps = np.flatnonzero(np.diff(numbers) != 1)
    if jumps.size:
        row = int(jumps[0])
        raise InputError(f"RECORD goes from {numbers[row]:.0f} to {numbers[row + 1]:.0f} at lines {row + 5} to "
                         f"{row + 6}: samples lost or tables joined ({jumps.size} jump(s)); give sampling_rate in "
                         "record_format to use the samples as they are", field=RECORD_COLUMN, file=file)


def _is_text(head: bytes) -> bool:
    """Whether a file's first bytes are text (UTF-8 without NUL; a character cut at the end is no matter)."""
    if not head or b"\0" in head:
        return False
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as err:
        return err.start >= len(head) - 3
    return True


def _header_lines(file: str) -> list[list[str]]:
    """The first four lines of ``file``, split into fields (fewer if it is shorter)."""
    try:
        with open(file, newline="", encoding="utf-8-sig", errors="replace") as stream:
            return [[field.strip() for field in row] for row in csv.reader(itertools.islice(stream, 4))]
    except FileNotFoundError:
        raise InputError("file not found", file=file) from None
    except (OSError, csv.Error) as err:
        raise InputError(f"cannot read the file as TOA5: {one_line(err)}", file=file) from None
