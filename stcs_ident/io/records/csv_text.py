"""Acceleration records from CSV and text files, as data loggers write them.

A header line names the columns: a time column and one column per channel.
The options (a campaign's ``record_format``) say how the file is written:
``separator`` (default ``,``), ``decimal`` (default ``.``), ``skip_rows``
(0-based line numbers after the header to skip, a units row: ``[1]``),
``time_column`` (default ``time``) and ``unit`` (default m/s²).

The time column holds seconds or date-times (ISO 8601, read by pandas; the
first row is then the record's start time). Without ``sampling_rate`` the
rate comes from the time column, which must be uniform: seconds within
:data:`~stcs_ident.io.records.validation.TIME_TOLERANCE`, date-times within
the resolution they are printed to. With ``sampling_rate`` the time column
gives the start time only (date-times), so a time column printed to a few
digits is no obstacle. The channel positions are given by the caller (the
campaign's channel table). Then the checks of every record source apply
(:mod:`~stcs_ident.io.records.validation`). A refusal says which option
would fix it, where one would.
"""

from __future__ import annotations

import csv
import os
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from ...core.errors import InputError
from ...core.record import Record
from .base import HEAD_BYTES, RecordReader, file_head
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
CSV_OPTIONS = ("time_column", "unit", "sampling_rate", "separator", "decimal", "skip_rows")
_DECIMAL_COMMA = re.compile(r"^\s*[-+]?\d*,\d+([eE][-+]?\d+)?\s*$")
_FRACTION = re.compile(r"\d:\d\d:\d\d[.,](\d+)")


class CsvReader(RecordReader):
    """CSV and text records (:func:`record_from_csv`): the channel positions come from the caller.

    By content: text whose first line is a header separated by commas, semicolons or tabs (not JSON).
    """

    name = "csv"
    suffixes = (".csv", ".txt")

    def can_open(self, path: str | os.PathLike) -> bool:
        head = file_head(path)
        if not head or b"\0" in head:
            return False
        first = head.split(b"\n", 1)[0].removeprefix(b"\xef\xbb\xbf").strip()  # a BOM is tolerated
        try:
            first.decode("utf-8")
        except UnicodeDecodeError as err:  # unless the head only cut a long header line inside a character
            if b"\n" in head or len(head) < HEAD_BYTES or err.start < len(first) - 3:
                return False
        return any(mark in first for mark in (b",", b";", b"\t")) and first[:1] not in (b"[", b"{")

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`record_from_csv`; a channel without a position is refused, saying where positions are given."""
        try:
            return record_from_csv(path, positions or {}, **{k: v for k, v in options.items() if k in CSV_OPTIONS})
        except InputError as err:
            if err.field != "channel_position" or not err.message.startswith("no position"):
                raise
            hint = "a CSV record gives no positions: list its channels in the test's [test.channels] (m from end A)"
            raise InputError(f"{err.message}; {hint}", field=err.field, file=err.file) from None


READER = CsvReader()


def record_from_csv(
    path: str | os.PathLike, positions: Positions, *, time_column: str = "time", unit: str = "m/s^2",
    sampling_rate: float | None = None, separator: str = ",", decimal: str = ".", skip_rows: Sequence[int] = (),
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
        Hz; given, the time column is not used for the rate (and may be missing).
    separator, decimal : str
        The column separator and the decimal mark, one character each.
    skip_rows : sequence of int
        0-based line numbers (the header is line 0) not read: a units row under the header is ``[1]``.

    Raises
    ------
    InputError
        As :func:`~stcs_ident.io.records.hdf5.read_record`; a missing or non-uniform time has field ``time``;
        the message names the option that would fix it, where one would.
    """
    file = str(path)
    skip = sorted(set(skip_rows))
    header, table = _read_csv(file, separator, skip)
    if len(set(header)) != len(header):
        duplicate = next(name for name in header if header.count(name) > 1)
        raise InputError(f"duplicate column {duplicate!r}", field="channel_name", file=file)
    has_time = time_column in header
    if not has_time and sampling_rate is None:
        raise InputError(f"no {time_column!r} column among {', '.join(map(repr, header))}; "
                         f"{_separator_hint(header, separator) or _TIME_HINT}", field="time", file=file)
    names = [name for name in header if name != time_column]
    if not skip:
        _check_units_row(table, header, file)
    rate, start_time, replaced = None, None, []
    if has_time:
        column = table.iloc[:, header.index(time_column)]
        rate, start_time = _time_axis(column, time_column, decimal, skip, file, need_rate=sampling_rate is None)
    if sampling_rate is not None:
        if rate is not None and abs(rate - sampling_rate) > TIME_TOLERANCE * sampling_rate:
            replaced.append(("sampling_rate", sampling_rate, rate))
        rate = sampling_rate
    acceleration = np.column_stack(
        [_numeric_column(table, header, name, "acceleration", decimal, skip, file) for name in names]
        or [np.empty((len(table), 0))]
    )
    channel_positions = position_list(names, positions_by_name(names, positions, file), file)
    return validated_record(acceleration, rate, names, channel_positions, unit=unit, start_time=start_time,
                            source=file, replaced=replaced)


_TIME_HINT = "name the time column with time_column, or give sampling_rate (the time column is then not needed)"


def _read_csv(file: str, separator: str, skip: list[int]) -> tuple[list[str], pd.DataFrame]:
    """The header and the data rows of ``file`` as text (columns by place, so duplicates survive)."""
    hint = ""
    try:
        with open(file, newline="", encoding="utf-8-sig") as stream:  # -sig: tolerate a BOM
            header = [name.strip() for name in next(csv.reader(stream, delimiter=separator), [])]
        if not header:
            raise InputError("empty file: no header line", file=file)
        hint = _separator_hint(header, separator)
        table = pd.read_csv(file, sep=separator, header=None, skiprows=[0, *skip], skipinitialspace=True,
                            encoding="utf-8-sig", dtype=str, keep_default_na=False, na_values=[""])
    except FileNotFoundError:
        raise InputError("file not found", file=file) from None
    except pd.errors.EmptyDataError:
        raise InputError("has no samples", field="acceleration", file=file) from None
    except (OSError, UnicodeDecodeError, pd.errors.ParserError, csv.Error) as err:
        hint = (f"; {hint}" if hint else "; if the columns are separated otherwise, give separator in "
                "record_format" if separator == "," else "")
        raise InputError(f"cannot read the file as CSV: {one_line(err)}{hint}", file=file) from err
    if table.shape[1] != len(header):
        hint = (f"; {_separator_hint(header, separator)}" if _separator_hint(header, separator) else
                '; decimal commas in a comma-separated file? such a file cannot be read: write it with '
                'separator ";"' if separator == "," else "")
        raise InputError(f"the header has {len(header)} columns, the rows {table.shape[1]}{hint}", file=file)
    return header, table


def _separator_hint(header: list[str], separator: str) -> str:
    """'give separator = ...' when the header is one column that another separator would split."""
    if len(header) == 1:
        for mark in (";", "\t", ",", "|"):
            if mark != separator and mark in header[0]:
                return f"give separator = {mark!r} in record_format"
    return ""


def _line(row: int, skip: list[int]) -> int:
    """The 1-based line of the file of data row ``row`` (0-based), the header being line 1."""
    line, seen = 1, -1  # 0-based file line numbers; line 0 is the header
    while True:
        if line not in skip:
            seen += 1
            if seen == row:
                return line + 1
        line += 1


def _check_units_row(table: pd.DataFrame, header: list[str], file: str) -> None:
    """Refuse a first data row with no number in it (a units row under the header), saying how to skip it."""
    if len(table) and table.iloc[0].notna().all():
        first = table.iloc[0].astype(str)
        if pd.to_numeric(first.str.strip(), errors="coerce").isna().all():
            cells = ", ".join(repr(v) for v in first.tolist()[:4])
            raise InputError(f"line 2 ({cells}) holds no number: a units row under the header? give "
                             "skip_rows = [1] in record_format", field="acceleration", file=file)


def _numbers(column: pd.Series, decimal: str) -> np.ndarray:
    text = column.str.strip()
    if decimal != ".":
        text = text.str.replace(decimal, ".", regex=False)
    return pd.to_numeric(text, errors="coerce").to_numpy(dtype=float)


def _numeric_column(table: pd.DataFrame, header: list[str], name: str, field: str, decimal: str, skip: list[int],
                    file: str) -> np.ndarray:
    """Column ``name`` as floats; empty cells become NaN, text is refused (with the option that reads it)."""
    column = table.iloc[:, header.index(name)]
    values = _numbers(column, decimal)
    text = np.flatnonzero(np.isnan(values) & column.notna().to_numpy())
    if text.size:
        row = int(text[0])
        value = column.iloc[row]
        hint = ""
        if decimal != "," and _DECIMAL_COMMA.match(value):
            hint = '; decimal commas? give decimal = "," in record_format'
        elif row == 0 and not skip:
            hint = "; a units row under the header? give skip_rows = [1] in record_format"
        raise InputError(f"column {name!r}, line {_line(row, skip)}: {value!r} is not a number{hint}",
                         field=field, file=file)
    return values


def _time_axis(column: pd.Series, name: str, decimal: str, skip: list[int], file: str,
               need_rate: bool) -> tuple[float | None, str | None]:
    """The sampling rate (None when not ``need_rate``) and the start time (date-times only) of the time column."""
    if column.isna().any():
        row = int(np.argmax(column.isna().to_numpy()))
        raise InputError(f"column {name!r}, line {_line(row, skip)}: no time", field="time", file=file)
    seconds = _numbers(column, decimal)
    if not np.isnan(seconds).any():
        return (_rate_from_seconds(seconds, name, file) if need_rate else None), None
    try:
        stamps = pd.to_datetime(column.str.strip(), format="ISO8601")
    except (ValueError, TypeError, OverflowError) as err:
        if not need_rate:
            return None, None  # the rate is given: a time column that is neither is not used
        row = int(np.argmax(np.isnan(seconds)))
        hint = ('; decimal commas? give decimal = "," in record_format' if _DECIMAL_COMMA.match(column.iloc[row])
                else f"; or give sampling_rate (and start_time) in record_format ({one_line(err)})")
        raise InputError(f"column {name!r}, line {_line(row, skip)}: {column.iloc[row]!r} is neither a time in "
                         f"seconds nor an ISO 8601 date-time{hint}", field="time", file=file) from None
    if stamps.isna().any():
        row = int(np.argmax(stamps.isna().to_numpy()))
        raise InputError(f"column {name!r}, line {_line(row, skip)}: no date-time", field="time", file=file)
    start = stamps.iloc[0].floor("us").to_pydatetime().isoformat()  # Python's: no fraction when it is zero
    if not need_rate:
        return None, start
    ns = (stamps - stamps.iloc[0]).to_numpy().astype("timedelta64[ns]").astype(np.int64)
    digits = column.str.extract(_FRACTION, expand=False).str.len().max()  # the finest the date-times are printed to
    return _rate_from_stamps(ns, 0 if pd.isna(digits) else int(digits), name, file), start


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
            "give sampling_rate in record_format to use the samples as they are", field=name, file=file)
    return 1e9 * (ns.size - 1) / span  # from the whole span: the printed resolution spread over every step
