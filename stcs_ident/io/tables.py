"""Tables in Parquet: written whole or not at all, read back with their types.

Parquet keeps the column types (times, lists of modes and frequencies) and
is read column by column; ``track`` keeps its table of processed records in
it (:mod:`~stcs_ident.track.store`). Reading and writing files is io's job,
so the numerics floors hand frames here.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import pandas as pd

from ..core.files import atomic_path
from ..core.times import check_instant

__all__ = ["instant_column", "parquet_parts", "read_parquet_files", "write_parquet"]


def write_parquet(frame: pd.DataFrame, path: str | os.PathLike) -> None:
    """Write ``frame`` (without its index) to ``path``, whole or not at all.

    The frame is serialised in memory first, then written beside ``path``
    under a temporary name and renamed: a failure at any point leaves
    ``path`` as it was.
    """
    buffer = io.BytesIO()
    frame.to_parquet(buffer, index=False)
    with atomic_path(path, suffix=".parquet") as tmp:
        tmp.write_bytes(buffer.getvalue())


def parquet_parts(directory: str | os.PathLike) -> pd.DataFrame | None:
    """The rows of every Parquet file in ``directory``, concatenated in file-name order (None if there is none).

    A writer's temporary (a name starting with ``.``) is not a part: it is
    either renamed whole or removed.
    """
    parts = sorted(p for p in Path(directory).glob("*.parquet") if not p.name.startswith("."))
    if not parts:
        return None
    return pd.concat([pd.read_parquet(p) for p in parts], ignore_index=True)


def read_parquet_files(paths) -> tuple[list[tuple[Path, pd.DataFrame]], list[tuple[Path, str]]]:
    """Read each Parquet file of ``paths``: ([(path, frame)] of those read, [(path, why)] of those that cannot be).

    A file that cannot be read (truncated, empty, not Parquet, gone since listed) is returned with the
    reason in one line instead of raising: the caller decides what it means.
    """
    read, unreadable = [], []
    for path in paths:
        try:
            read.append((Path(path), pd.read_parquet(path)))
        except Exception as err:  # noqa: BLE001 (pyarrow raises its own types: ArrowInvalid, OSError, ...)
            unreadable.append((Path(path), " ".join(f"{type(err).__name__}: {err}".split())))
    return read, unreadable


def instant_column(values) -> pd.Series:
    """Start times (ISO 8601 text, a time stamp of the table, or None) as a column of UTC time stamps to the
    nanosecond, by the rule the readers apply (:mod:`stcs_ident.core.times`): None is ``NaT``; a text the
    rule refuses raises :class:`~stcs_ident.core.errors.InputError` (it never becomes ``NaT`` silently)."""
    values = pd.Series(values, dtype=object)
    present = values.notna()
    for value in values[present]:
        if not isinstance(value, pd.Timestamp):  # a time stamp is a row of the table already: held, so valid
            check_instant(value)
    column = pd.Series(pd.NaT, index=values.index, dtype="datetime64[ns, UTC]")
    if present.any():
        column[present] = pd.to_datetime(values[present], utc=True, format="ISO8601").astype("datetime64[ns, UTC]")
    return column
