"""The table of processed records: Parquet parts written whole, read back as one tidy DataFrame.

Each finished batch of records becomes one part file, ``OUT/parts/<first
record id>-<n>.parquet``, written whole or not at all (beside its target,
then renamed): a run killed at any moment keeps every batch finished before,
and the next run skips their records (known by content). ``records.parquet``
is the union, rewritten whole at the end of each run, for the user to open
(pandas, pyarrow, DuckDB, Spark, ...). Parquet keeps the types (times, lists
of modes and frequencies) and is read column by column. The files are
written and read by :mod:`~stcs_ident.io.tables`; this module keeps the rows' types and order.
"""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from ..io.tables import instant_column, parquet_parts, write_parquet
from .process import COLUMNS

__all__ = ["append_part", "processed_table", "write_table"]

PARTS = "parts"
TABLE = "records.parquet"
#: A row's columns: the record's (:data:`~stcs_ident.track.process.COLUMNS`), and its file's size and
#: modification time (ns) when processed, which spare hashing it again on a rerun.
ROW_COLUMNS = (*COLUMNS, "size", "mtime_ns")


def _frame(rows: list[dict]) -> pd.DataFrame:
    frame = pd.DataFrame(rows, columns=list(ROW_COLUMNS))
    frame["start_time"] = instant_column(frame["start_time"])  # the readers' rule for times (core/times.py)
    for name in ("temperature", "tension", "tension_sigma"):
        frame[name] = frame[name].astype(float)
    for name in ("n_modes", "size", "mtime_ns"):
        frame[name] = frame[name].astype("int64")
    return frame


def append_part(out: str | os.PathLike, rows: list[dict]) -> Path:
    """Write ``rows`` as one new part, whole or not at all."""
    directory = Path(out) / PARTS
    directory.mkdir(parents=True, exist_ok=True)
    target = directory / f"{rows[0]['record_id']}-{len(rows)}.parquet"
    write_parquet(_frame(rows), target)
    return target


def processed_table(out: str | os.PathLike) -> pd.DataFrame:
    """Every part's rows, one per record (the latest row of a record processed twice), sorted by cable and time."""
    frame = parquet_parts(Path(out) / PARTS)
    if frame is None:
        return _frame([])
    frame = frame.drop_duplicates(["cable", "record_id"], keep="last")
    return frame.sort_values(["cable", "start_time", "record"], kind="stable").reset_index(drop=True)


def write_table(out: str | os.PathLike, frame: pd.DataFrame) -> Path:
    """``records.parquet``, whole or not at all."""
    target = Path(out) / TABLE
    write_parquet(frame, target)
    return target
