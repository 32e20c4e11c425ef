"""Acceleration records from CSV and text files, as data loggers write them.

A header line names the columns: a time column and one column per channel.
The options (a campaign's ``record_format``) say how the file is written:
``separator`` (default ``,``), ``decimal`` (default ``.``), ``skip_rows``
(line numbers counted from the header to skip, a units row: ``[1]``),
``time_column`` (default ``time``), ``unit`` (default m/s²), ``header_row``
(the header's line, 0-based, after a preamble of metadata lines; without it
the header is looked for, :mod:`~stcs_ident.io.records.preamble`) and
``channels`` (the columns that are acceleration channels; the others are
left out, :mod:`~stcs_ident.io.records.columns`).

The time column holds seconds or date-times (ISO 8601, read by pandas; the
first row is then the record's start time). Without ``sampling_rate`` the
rate comes from the time column, which must be uniform: seconds within
:data:`~stcs_ident.io.records.validation.TIME_TOLERANCE`, date-times within
the resolution they are printed to. With ``sampling_rate`` the time column
need not be uniform (a time column printed to a few digits is no
obstacle), but the rate of its span must agree with the given one within
its printed resolution, else the file is refused unless
``override_sampling_rate`` (:mod:`~stcs_ident.io.records.rates`). The
channel positions are given by the caller (the campaign's channel table).
Then the checks of every record source apply
(:mod:`~stcs_ident.io.records.validation`). A refusal says which option
would fix it, where one would. The record's ``notes`` say where a header
was found after a preamble and which columns were left out.
"""

from __future__ import annotations

import csv
import itertools
import os
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from ...core.errors import InputError
from ...core.record import Record
from .base import HEAD_BYTES, RecordReader, file_head, readers
from .columns import Selection, by_channels, text_positions
from .preamble import find_header
from .rates import FileRate, printed_resolution, resolved_rate
from .validation import (
    TIME_TOLERANCE,
    Positions,
    one_line,
    position_list,
    positions_by_name,
    rate_from_time,
    validated_record,
)

__all__ = ["READER", "CsvReader", "record_from_csv"]

#: The options of this reader (the others a campaign gives are for other formats).
CSV_OPTIONS = ("time_column", "unit", "sampling_rate", "separator", "decimal", "skip_rows", "header_row", "channels",
               "override_sampling_rate")
_DECIMAL_COMMA = re.compile(r"^\s*[-+]?\d*,\d+([eE][-+]?\d+)?\s*$")
_FRACTION = re.compile(r"\d:\d\d:\d\d[.,](\d+)")
#: First bytes of text layouts that have their own reader (a TOA5 or an LVM file named .csv or .txt).
_OTHER_LAYOUTS = {b"TOA5": "toa5", b'"TOA5"': "toa5", b"LabVIEW Measurement": "lvm"}


def other_layout(head: bytes) -> str | None:
    """The name of the reader of a text layout that is not a plain table (TOA5, LVM), from its first bytes."""
    head = head.removeprefix(b"\xef\xbb\xbf").lstrip(b" \t")
    return next((name for mark, name in _OTHER_LAYOUTS.items() if head.startswith(mark)), None)


class CsvReader(RecordReader):
    """CSV and text records (:func:`record_from_csv`): the channel positions come from the caller.

    By content: text whose first line is a header separated by commas, semicolons or tabs (not JSON, not a
    TOA5 or LVM file: a ``.csv`` or ``.txt`` of those is read by their readers).
    """

    name = "csv"
    suffixes = (".csv", ".txt")

    def can_open(self, path: str | os.PathLike) -> bool:
        head = file_head(path)
        if not head or b"\0" in head or other_layout(head):
            return False
        first = head.split(b"\n", 1)[0].removeprefix(b"\xef\xbb\xbf").strip()  # a BOM is tolerated
        try:
            first.decode("utf-8")
        except UnicodeDecodeError as err:  # unless the head only cut a long header line inside a character
            if b"\n" in head or len(head) < HEAD_BYTES or err.start < len(first) - 3:
                return False
        return any(mark in first for mark in (b",", b";", b"\t")) and first[:1] not in (b"[", b"{")

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`record_from_csv`; a TOA5 or LVM file (by its first line) is read by its own reader."""
        layout = other_layout(file_head(path))
        if layout is not None:  # their readers build on this module: found in the registry, not imported
            reader = next((r for r in readers() if r.name == layout), None)
            if reader is None:
                raise InputError(f"a {layout.upper()} file, and no {layout!r} reader is registered",
                                 file=os.fspath(path))
            return reader.read(path, positions=positions, **options)
        return record_from_csv(path, positions or {}, **{k: v for k, v in options.items() if k in CSV_OPTIONS})


READER = CsvReader()


def record_from_csv(
    path: str | os.PathLike, positions: Positions, *, time_column: str = "time", unit: str = "m/s^2",
    sampling_rate: float | None = None, separator: str = ",", decimal: str = ".", skip_rows: Sequence[int] = (),
    header_row: int | None = None, channels: Sequence[str] | None = None, override_sampling_rate: bool = False,
) -> Record:
    """Read a record from CSV: a header line, a time column, one column per channel.

    Parameters
    ----------
    path : str or path-like
        The CSV file; the header names the channels.
    positions : mapping or sequence of float
        m from end A: ``{name: position}``, or one per channel in file order.
    time_column : str
        Sample times: seconds, uniform within ``TIME_TOLERANCE`` (relative), or ISO 8601 date-times
        (the first gives the start time), uniform within their printed resolution.
    unit : str
        The samples' unit, a spelling of :data:`.validation.UNITS` (m/s^2, m/s2, mm/s^2, g, G, mg, ...).
    sampling_rate : float, optional
        Hz; given, the time column need not be uniform (and may be missing), but a rate it gives that differs
        beyond its printed resolution is refused (:mod:`~stcs_ident.io.records.rates`).
    separator, decimal : str
        The column separator and the decimal mark, one character each.
    skip_rows : sequence of int
        Line numbers counted from the header (the header is line 0) not read: a units row under it is ``[1]``.
    header_row : int, optional
        The file's line (0-based) that names the columns, after a preamble; without it the header is looked
        for (:func:`~stcs_ident.io.records.preamble.find_header`), and the record's ``notes`` say where it
        was found when it is not line 0.
    channels : sequence of str, optional
        The columns that are acceleration channels; the others are left out (listed in ``notes``).
    override_sampling_rate : bool
        Whether ``sampling_rate`` replaces a time column's rate that differs from it.

    Raises
    ------
    InputError
        As :func:`~stcs_ident.io.records.hdf5.read_record`; a missing or non-uniform time has field ``time``;
        the message names the option that would fix it, where one would.
    """
    file = str(path)
    skip = sorted(set(skip_rows))
    notes: list[str] = []
    if header_row is None:
        header_row, found = find_header(file, separator, decimal)
        notes.extend(found)
    header, table = read_table(file, separator, header_row, skip)
    has_time = time_column in header
    if not has_time and sampling_rate is None:
        raise InputError(f"no {time_column!r} column among {', '.join(map(repr, header))}; "
                         f"{_separator_hint(header, separator) or _TIME_HINT}", field="time", file=file)
    selection = by_channels(header, channels, unit, file, excluded={time_column: "the time column"} if has_time else {})
    if not skip:
        _check_units_row(table, decimal, header_row, file)
    return table_record(file, header, table, selection, positions, time_column=time_column if has_time else None,
                        sampling_rate=sampling_rate, override=override_sampling_rate, decimal=decimal,
                        header_row=header_row, skip=skip, notes=notes, channels_given=channels is not None)


def table_record(file: str, header: list[str], table: pd.DataFrame, selection: Selection, positions: Positions,
                 *, time_column: str | None, sampling_rate: float | None, override: bool, decimal: str,
                 header_row: int, skip: list[int], notes: Sequence[str], channels_given: bool,
                 replaced: Sequence[tuple[str, Any, Any]] = ()) -> Record:
    """The record of a text table read by :func:`read_table`: its channels (``selection``) scaled to m/s², its
    rate and start time from the time column and ``sampling_rate`` (:func:`~.rates.resolved_rate`)."""
    replaced = list(replaced) + list(selection.replaced)
    found, start_time = None, None
    if time_column is not None:
        column = table.iloc[:, header.index(time_column)]
        found, start_time = _time_axis(column, time_column, decimal, header_row, skip, file, given=sampling_rate)
    rate = resolved_rate(sampling_rate, found, override=override, file=file, replaced=replaced)
    columns = [_numeric_column(table, header, name, "acceleration", decimal, header_row, skip, file)
               for name in selection.names]
    acceleration = np.column_stack(columns) if columns else np.empty((len(table), 0))
    if any(scale != 1.0 for scale in selection.scales):
        acceleration *= np.asarray(selection.scales)
    if isinstance(positions, Mapping) or positions is None:
        channel_positions = text_positions(selection, positions, file, channels_given)
    else:
        names = list(selection.names)
        channel_positions = position_list(names, positions_by_name(names, positions, file), file)
    return validated_record(acceleration, rate, list(selection.names), channel_positions, unit="m/s^2",
                            start_time=start_time, source=file, replaced=replaced,
                            notes=(*notes, *selection.notes()))


_TIME_HINT = "name the time column with time_column, or give sampling_rate (the time column is then not needed)"


def read_table(file: str, separator: str, header_row: int, skip: list[int]) -> tuple[list[str], pd.DataFrame]:
    """The header (line ``header_row``) and the data rows after it of ``file``, as text (columns by place);
    ``skip`` counts lines from the header. A duplicate column name is refused."""
    hint = ""
    try:
        with open(file, newline="", encoding="utf-8-sig") as stream:  # -sig: tolerate a BOM
            line = next(itertools.islice(stream, header_row, None), "")
        header = [name.strip() for name in next(csv.reader([line], delimiter=separator), [])]
        if not header:
            raise InputError("empty file: no header line" if header_row == 0 else
                             f"line {header_row} (0-based, header_row) is empty or past the end of the file",
                             file=file)
        hint = _separator_hint(header, separator)
        table = pd.read_csv(file, sep=separator, header=None,
                            skiprows=[*range(header_row + 1), *(header_row + k for k in skip)],
                            skipinitialspace=True, encoding="utf-8-sig", dtype=str, keep_default_na=False,
                            na_values=[""])
    except FileNotFoundError:
        raise InputError("file not found", file=file) from None
    except pd.errors.EmptyDataError:
        raise InputError("has no samples", field="acceleration", file=file) from None
    except (OSError, UnicodeDecodeError, pd.errors.ParserError, csv.Error) as err:
        hint = (f"; {hint}" if hint else "; if the columns are separated otherwise, give separator in "
                "record_format" if separator == "," else "")
        if isinstance(err, pd.errors.ParserError) and header_row == 0:
            hint += _PREAMBLE_HINT
        raise InputError(f"cannot read the file as CSV: {one_line(err)}{hint}", file=file) from err
    if table.shape[1] != len(header):
        hint = (f"; {_separator_hint(header, separator)}" if _separator_hint(header, separator) else
                '; decimal commas in a comma-separated file? such a file cannot be read: write it with '
                'separator ";"' if separator == "," and table.shape[1] > len(header) else "")
        if header_row == 0:
            hint += _PREAMBLE_HINT
        raise InputError(f"the header (line {header_row + 1}) has {len(header)} columns, the rows {table.shape[1]}"
                         f"{hint}", file=file)
    if len(set(header)) != len(header):
        duplicate = next(name for name in header if header.count(name) > 1)
        fix = _PREAMBLE_HINT if header_row == 0 else "; give header_row, the line that names the columns"
        raise InputError(f"duplicate column {duplicate!r} in the header (line {header_row + 1}){fix}",
                         field="channel_name", file=file)
    return header, table


_PREAMBLE_HINT = ("; metadata lines before the header (a preamble)? give header_row = <the header's line, 0-based> "
                  "in record_format")


def _separator_hint(header: list[str], separator: str) -> str:
    """'give separator = ...' when the header is one column that another separator would split."""
    if len(header) == 1:
        for mark in (";", "\t", ",", "|"):
            if mark != separator and mark in header[0]:
                return f"give separator = {mark!r} in record_format"
    return ""


def _line(row: int, header_row: int, skip: list[int]) -> int:
    """The 1-based line of the file of data row ``row`` (0-based), the header being line ``header_row + 1`` and
    ``skip`` counted from the header."""
    line, seen = 1, -1  # lines counted from the header (the header is 0)
    while True:
        if line not in skip:
            seen += 1
            if seen == row:
                return header_row + line + 1
        line += 1


def _check_units_row(table: pd.DataFrame, decimal: str, header_row: int, file: str) -> None:
    """Refuse a first data row with no number in it (a units row under the header), saying how to skip it."""
    if len(table) and table.iloc[0].notna().all():
        first = table.iloc[0].astype(str)
        if np.isnan(_numbers(first, decimal)).all():
            cells = ", ".join(repr(v) for v in first.tolist()[:4])
            raise InputError(f"line {header_row + 2} ({cells}) holds no number: a units row under the header? give "
                             "skip_rows = [1] in record_format", field="acceleration", file=file)


def _numbers(column: pd.Series, decimal: str) -> np.ndarray:
    text = column.str.strip()
    if decimal != ".":
        text = text.str.replace(decimal, ".", regex=False)
    return pd.to_numeric(text, errors="coerce").to_numpy(dtype=float)


def _numeric_column(table: pd.DataFrame, header: list[str], name: str, field: str, decimal: str, header_row: int,
                    skip: list[int], file: str) -> np.ndarray:
    """Column ``name`` as floats; empty cells become NaN, text is refused (with the option that reads it)."""
    column = table.iloc[:, header.index(name)]
    values = _numbers(column, decimal)
    spelled_nan = column.str.strip().str.lower().isin(("nan", "-nan", "+nan")).to_numpy(dtype=bool)
    text = np.flatnonzero(np.isnan(values) & column.notna().to_numpy() & ~spelled_nan)  # NAN: refused as non-finite
    if text.size:
        row = int(text[0])
        value = column.iloc[row]
        hint = ""
        if decimal != "," and _DECIMAL_COMMA.match(value):
            hint = '; decimal commas? give decimal = "," in record_format'
        elif row == 0 and not skip:
            hint = "; a units row under the header? give skip_rows = [1] in record_format"
        else:
            hint = "; if it is not an acceleration channel, give channels in record_format naming those that are"
        raise InputError(f"column {name!r}, line {_line(row, header_row, skip)}: {value!r} is not a number{hint}",
                         field=field, file=file)
    return values


def _time_axis(column: pd.Series, name: str, decimal: str, header_row: int, skip: list[int], file: str,
               given: float | None) -> tuple[FileRate | None, str | None]:
    """The time column's rate (uniform unless ``given``: then from its span, to compare) and start time
    (date-times only)."""
    if column.isna().any():
        row = int(np.argmax(column.isna().to_numpy()))
        raise InputError(f"column {name!r}, line {_line(row, header_row, skip)}: no time", field="time", file=file)
    need_rate = given is None
    seconds = _numbers(column, decimal)
    if not np.isnan(seconds).any():
        if need_rate:
            rate = _rate_from_seconds(seconds, name, file)
            return FileRate(rate, f"time column {name!r}", detail=f"steps of {1 / rate:.6g} s"), None
        try:  # uniform within TIME_TOLERANCE: printed finely enough for its rate to be known to that
            rate = rate_from_time(seconds, name, file)
            return FileRate(rate, f"time column {name!r}", rtol=TIME_TOLERANCE,
                            detail=f"steps of {1 / rate:.6g} s"), None
        except InputError:  # rounded (or a gap): the rate of its span, known to the printed digits of its ends
            ends = [0.0 if seconds[k] == 0 else 0.5 * (printed_resolution(column.iloc[k].replace(decimal, ".")) or 0.0)
                    for k in (0, -1)]
            return _span_rate(seconds[-1] - seconds[0], seconds.size, sum(ends), name), None
    try:
        stamps = pd.to_datetime(column.str.strip(), format="ISO8601")
    except (ValueError, TypeError, OverflowError) as err:
        if not need_rate:
            return None, None  # the rate is given: a time column that is neither is not used
        row = int(np.argmax(np.isnan(seconds)))
        hint = ('; decimal commas? give decimal = "," in record_format' if _DECIMAL_COMMA.match(column.iloc[row])
                else f"; or give sampling_rate (and start_time) in record_format ({one_line(err)})")
        raise InputError(f"column {name!r}, line {_line(row, header_row, skip)}: {column.iloc[row]!r} is neither a "
                         f"time in seconds nor an ISO 8601 date-time{hint}", field="time", file=file) from None
    if stamps.isna().any():
        row = int(np.argmax(stamps.isna().to_numpy()))
        raise InputError(f"column {name!r}, line {_line(row, header_row, skip)}: no date-time", field="time",
                         file=file)
    start = stamps.iloc[0].floor("us").to_pydatetime().isoformat()  # Python's: no fraction when it is zero
    ns = (stamps - stamps.iloc[0]).to_numpy().astype("timedelta64[ns]").astype(np.int64)
    digits = column.str.extract(_FRACTION, expand=False).str.len().max()  # the finest the date-times are printed to
    digits = 0 if pd.isna(digits) else int(digits)
    if not need_rate:  # each end off by up to half a unit of the last printed digit
        return _span_rate(int(ns[-1]) / 1e9, ns.size, 10.0 ** -min(digits, 9), name), start
    rate = _rate_from_stamps(ns, digits, name, file)
    return FileRate(rate, f"time column {name!r}", detail=f"steps of {1 / rate:.6g} s"), start


def _span_rate(span: float, n: int, uncertainty: float, name: str) -> FileRate | None:
    """The rate of ``n`` samples over ``span`` s of a time column whose span is known to ``uncertainty`` s (the
    rounding of its two ends; None: no span), agreeing with a given rate within the uncertainty over the span
    plus TIME_TOLERANCE (:mod:`.rates`)."""
    if n < 2 or not np.isfinite(span) or span <= 0:
        return None
    rate = (n - 1) / span
    return FileRate(rate, f"time column {name!r}", rtol=uncertainty / span + TIME_TOLERANCE,
                    detail=f"{n} samples over {span:.9g} s give steps of {span / (n - 1):.6g} s; the span is "
                           f"known to {uncertainty:g} s, the rounding of its ends")


def _rate_from_seconds(time: np.ndarray, name: str, file: str) -> float:
    try:
        return rate_from_time(time, name, file)
    except InputError as err:
        if time.size < 2 or not np.all(np.isfinite(time)) or time[-1] <= time[0]:
            raise
        estimate = (time.size - 1) / (time[-1] - time[0])
        raise InputError(f"{err.message}; times printed to few digits? give sampling_rate (about {estimate:.7g} Hz) "
                         "in record_format", field=err.field, file=file) from None


def _rate_from_stamps(ns: np.ndarray, digits: int, name: str, file: str) -> float:
    """Sampling rate, Hz, of date-times ``ns`` (ns from the first) printed with ``digits`` decimals of a
    second, uniform within that resolution."""
    if ns.size < 2:
        raise InputError("needs at least two samples to give the sampling rate", field=name, file=file)
    resolution = 10 ** (9 - min(digits, 9))  # ns
    span = int(ns[-1])
    steps = np.diff(ns)
    mean = span / (ns.size - 1)
    worst = int(np.argmax(np.abs(steps - mean)))
    if span <= 0 or abs(steps[worst] - mean) > resolution + TIME_TOLERANCE * mean:
        raise InputError(
            f"date-times not uniformly spaced: step {worst} is {steps[worst] / 1e9:.9g} s against "
            f"{mean / 1e9:.9g} s on average (resolution {resolution / 1e9:g} s); a gap or a clock jump? "
            "give sampling_rate and override_sampling_rate = true in record_format to use the samples as they are",
            field=name, file=file)
    return 1e9 * (ns.size - 1) / span  # from the whole span: the printed resolution spread over every step
