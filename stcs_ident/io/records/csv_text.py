"""Acceleration records from CSV: a header line, a time column, one column per channel.

The sampling rate comes from the time column, which must be uniform within
:data:`~stcs_ident.io.records.validation.TIME_TOLERANCE`; the channel
positions are given by the caller. Then the checks of every record source
apply (:mod:`~stcs_ident.io.records.validation`). A problem with the time
column has field ``time``; a file that is missing or not CSV has no field.
"""

from __future__ import annotations

import csv
import os
from collections.abc import Mapping

import numpy as np
import pandas as pd

from ...core.errors import InputError
from ...core.record import Record
from .base import HEAD_BYTES, RecordReader, file_head
from .validation import Positions, one_line, position_list, positions_by_name, rate_from_time, validated_record

__all__ = ["READER", "CsvReader", "record_from_csv"]


class CsvReader(RecordReader):
    """CSV records (:func:`record_from_csv`): the channel positions come from the caller.

    By content: text whose first line is a comma-separated header (not a JSON document).
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
        return b"," in first and first[:1] not in (b"[", b"{")

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None,
             time_column: str = "time", unit: str = "m/s^2") -> Record:
        """:func:`record_from_csv`; a channel without a position is refused, saying where positions are given."""
        try:
            return record_from_csv(path, positions or {}, time_column=time_column, unit=unit)
        except InputError as err:
            if err.field != "channel_position" or not err.message.startswith("no position"):
                raise
            hint = "a CSV record gives no positions: list its channels in the test's [test.channels] (m from end A)"
            raise InputError(f"{err.message}; {hint}", field=err.field, file=err.file) from None


READER = CsvReader()


def record_from_csv(
    path: str | os.PathLike, positions: Positions, *, time_column: str = "time", unit: str = "m/s^2"
) -> Record:
    """Read a record from CSV: a header line, a time column, one column per channel.

    Parameters
    ----------
    path : str or path-like
        The CSV file; the header names the channels.
    positions : mapping or sequence of float
        m from end A: ``{name: position}``, or one per channel in file order.
    time_column : str
        Sample times, s: uniform within ``TIME_TOLERANCE`` (relative).
    unit : str
        The samples' unit, a spelling of :data:`.validation.UNITS` (m/s^2, m/s2, mm/s^2, g, G, mg, ...).

    Raises
    ------
    InputError
        As :func:`~stcs_ident.io.records.hdf5.read_record`; a missing or non-uniform time has field ``time``.
    """
    file = str(path)
    header, table = _read_csv(file)
    if len(set(header)) != len(header):
        duplicate = next(name for name in header if header.count(name) > 1)
        raise InputError(f"duplicate column {duplicate!r}", field="channel_name", file=file)
    if time_column not in header:
        raise InputError(f"no {time_column!r} column among {', '.join(header)}", field="time", file=file)
    time = _numeric_column(table, header, time_column, "time", file)
    sampling_rate = rate_from_time(time, "time", file)
    names = [name for name in header if name != time_column]
    acceleration = np.column_stack(
        [_numeric_column(table, header, name, "acceleration", file) for name in names] or [np.empty((time.size, 0))]
    )
    channel_positions = position_list(names, positions_by_name(names, positions, file), file)
    return validated_record(
        acceleration, sampling_rate, names, channel_positions, unit=unit, start_time=None, source=file
    )


def _read_csv(file: str) -> tuple[list[str], pd.DataFrame]:
    """The header and the data rows of ``file`` (columns by place, so duplicates survive)."""
    try:
        with open(file, newline="", encoding="utf-8-sig") as stream:  # -sig: tolerate a BOM
            header = [name.strip() for name in next(csv.reader(stream), [])]
        if not header:
            raise InputError("empty file: no header line", file=file)
        table = pd.read_csv(file, header=None, skiprows=1, skipinitialspace=True, encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError("file not found", file=file) from None
    except pd.errors.EmptyDataError:
        raise InputError("has no samples", field="acceleration", file=file) from None
    except (OSError, UnicodeDecodeError, pd.errors.ParserError) as err:
        raise InputError(f"cannot read the file as CSV: {one_line(err)}", file=file) from err
    if table.shape[1] != len(header):
        raise InputError(f"the header has {len(header)} columns, the rows {table.shape[1]}", file=file)
    return header, table


def _numeric_column(table: pd.DataFrame, header: list[str], name: str, field: str, file: str) -> np.ndarray:
    """Column ``name`` as floats; empty cells become NaN, text is refused."""
    column = table.iloc[:, header.index(name)]
    values = pd.to_numeric(column, errors="coerce").to_numpy(dtype=float)
    text = np.flatnonzero(np.isnan(values) & column.notna().to_numpy())
    if text.size:
        row = int(text[0])
        raise InputError(f"column {name!r}, line {row + 2}: {column.iloc[row]!r} is not a number",
                         field=field, file=file)
    return values
