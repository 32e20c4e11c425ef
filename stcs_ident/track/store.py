"""The table of processed records: Parquet parts written whole, read back as one tidy DataFrame.

Each finished batch of one cable's records becomes one part file,
``OUT/parts/<cable key>-<time>-<random>-<n>.parquet`` (the cable key: 12 hex
digits of the SHA-256 of the cable's name; the time: nanoseconds since the
epoch, in hex, which orders the parts; ``n``: its rows), written whole or
not at all (beside its target, then renamed): no two cables, runs or batches
share a name, and a run killed at any moment keeps every batch finished
before. A file of ``parts/`` whose name is not of that form is not ours and
is ignored; one of that form that cannot be read (truncated, empty, another
table) is reported (:class:`~stcs_ident.core.errors.TrackWarning`) and its
records are simply not known: they are processed again.

``records.parquet`` is the table, rewritten whole at the end of each run,
for the user to open (pandas, pyarrow, DuckDB, Spark, ...). Parquet keeps
the types (times, lists of modes, planes and frequencies) and is read column
by column. Every column of a quantity carries its unit in its name
(``tension_N``, ``frequencies_Hz``, ...): a part written before they did
(``tension``, ``frequencies``, ...) reads with its columns renamed
(:data:`OLD_NAMES`), so a run resumes on it without processing its records
again. A part written before the ``planes`` column reads with every mode
in-plane (what it was processed as); one written before the damper's columns
(``damping_ratio``, ``damping_ratio_sigma``, ``coefficient_Ns_per_m``,
``coefficient_sigma_Ns_per_m``, ``coefficient_reason``) reads with NaN damping
ratios, one per mode, and no coefficient (nothing was fitted). The files are
written and read by :mod:`~stcs_ident.io.tables`;
this module keeps the rows' types, the parts' names and their order.
"""

from __future__ import annotations

import hashlib
import os
import re
import time
import uuid
import warnings
from pathlib import Path

import pandas as pd

from ..core.errors import TrackWarning
from ..io.tables import instant_column, read_parquet_files, write_parquet
from .process import COLUMNS, DAMPER_COLUMNS

__all__ = ["append_part", "cable_key", "processed_table", "read_parts", "replace_parts", "write_table"]

PARTS = "parts"
TABLE = "records.parquet"
#: A row's columns: the record's (:data:`~stcs_ident.track.process.COLUMNS`), the version of what shaped it
#: (the cable's campaign, the settings, the toolkit) and its file's size and modification time (ns) when
#: processed, which spare hashing it again on a rerun.
ROW_COLUMNS = (*COLUMNS, "version", "size_bytes", "mtime_ns")
#: The columns of parts written before the names carried their units, and their names now.
OLD_NAMES = {"temperature": "temperature_degC", "frequencies": "frequencies_Hz",
             "frequency_sigma": "frequency_sigma_Hz", "tension": "tension_N", "tension_sigma": "tension_sigma_N",
             "damping": "damping_ratio", "damping_sigma": "damping_ratio_sigma", "coefficient": "coefficient_Ns_per_m",
             "coefficient_sigma": "coefficient_sigma_Ns_per_m", "size": "size_bytes"}
#: The name of a part of ours.
PART = re.compile(r"^(?P<cable>[0-9a-f]{12})-(?P<time>[0-9a-f]{16})-[0-9a-f]{8}-[0-9]+\.parquet$")


def cable_key(cable: str) -> str:
    """The 12 hex digits that start the names of a cable's parts."""
    return hashlib.sha256(cable.encode("utf-8")).hexdigest()[:12]


def _frame(rows: list[dict]) -> pd.DataFrame:
    frame = pd.DataFrame(rows, columns=list(ROW_COLUMNS))
    frame["start_time"] = instant_column(frame["start_time"])  # the readers' rule for times (core/times.py)
    for name in ("temperature_degC", "tension_N", "tension_sigma_N", "coefficient_Ns_per_m",
                 "coefficient_sigma_Ns_per_m"):
        frame[name] = frame[name].astype(float)
    for name in ("n_modes", "size_bytes", "mtime_ns"):
        frame[name] = frame[name].astype("int64")
    frame["version"] = frame["version"].astype(str)
    frame["coefficient_reason"] = frame["coefficient_reason"].fillna("").astype(str)
    return frame


def append_part(out: str | os.PathLike, rows: list[dict]) -> Path:
    """Write ``rows`` (of one cable) as one new part, whole or not at all."""
    directory = Path(out) / PARTS
    directory.mkdir(parents=True, exist_ok=True)
    target = directory / f"{cable_key(rows[0]['cable'])}-{time.time_ns():016x}-{uuid.uuid4().hex[:8]}-{len(rows)}.parquet"
    write_parquet(_frame(rows), target)
    return target


def read_parts(out: str | os.PathLike) -> tuple[pd.DataFrame, list[Path], list[Path]]:
    """Every row of the parts of ours, oldest part first, and the parts read and those that cannot be.

    Returns
    -------
    rows : DataFrame
        The rows (``ROW_COLUMNS``) with ``part``, the name of the part that holds each (they sort in the
        order the parts were written).
    read, unreadable : list of Path
        Each unreadable part is reported once per run (a :class:`TrackWarning`); its records are not known.
    """
    directory = Path(out) / PARTS
    try:
        names = sorted((e.name for e in os.scandir(directory) if PART.match(e.name)), key=_written)
    except FileNotFoundError:
        names = []
    frames, unreadable = read_parquet_files([directory / n for n in names])
    read = []
    for path, frame in frames:
        frame = frame.rename(columns={old: new for old, new in OLD_NAMES.items() if old in frame and new not in frame})
        if "planes" not in frame and "modes" in frame:  # a part written before the planes: every mode in-plane
            frame = frame.assign(planes=[["in"] * len(m) for m in frame["modes"]])
        if "modes" in frame:  # a part written before the damper's columns: no damping ratio, no coefficient
            frame = _with_damper_columns(frame)
        if "doubtful" not in frame and "modes" in frame:  # before the flags: a row of another version, redone
            frame = frame.assign(doubtful=[[False] * len(m) for m in frame["modes"]])
        missing = [c for c in ROW_COLUMNS if c not in frame]
        cables = set(frame["cable"].map(cable_key)) if "cable" in frame else set()
        if missing or cables - {PART.match(path.name)["cable"]}:
            why = f"not a part of ours (missing {', '.join(missing)})" if missing else "rows of another cable"
            unreadable.append((path, why))
        else:
            read.append((path, frame))
    for path, why in unreadable:
        warnings.warn(TrackWarning(f"{path}: cannot be read ({why}); its records are processed again"),
                      stacklevel=3)
    if not read:
        rows = _frame([])
        rows["part"] = pd.Series(dtype=str)
    else:
        rows = pd.concat([f[list(ROW_COLUMNS)].assign(part=p.name) for p, f in read], ignore_index=True)
    return rows, [p for p, _ in read], [p for p, _ in unreadable]


def _with_damper_columns(frame: pd.DataFrame) -> pd.DataFrame:
    missing = {name: ([[float("nan")] * len(m) for m in frame["modes"]] if default is list else default)
               for name, default in DAMPER_COLUMNS.items() if name not in frame}
    return frame.assign(**missing) if missing else frame


def _written(name: str) -> tuple[int, str]:
    return int(PART.match(name)["time"], 16), name


def processed_table(out: str | os.PathLike) -> pd.DataFrame:
    """The latest row of each record (cable and path) in the parts, sorted by cable and time."""
    rows, _, _ = read_parts(out)
    rows = rows.drop_duplicates(["cable", "record"], keep="last").drop(columns="part")
    return sort_rows(rows)


def sort_rows(rows: pd.DataFrame) -> pd.DataFrame:
    """The table's order: by cable, start time, path."""
    return rows.sort_values(["cable", "start_time", "record"], kind="stable").reset_index(drop=True)


def replace_parts(out: str | os.PathLike, cable: str, rows: pd.DataFrame, old: list[Path]) -> None:
    """Write a cable's rows as one part, then remove its ``old`` parts (those read since): whole or not at
    all, as a part; killed between, the old parts only repeat or precede rows of the new one."""
    if len(rows):
        append_part(out, rows[list(ROW_COLUMNS)].to_dict("records"))
    key = cable_key(cable)
    for path in old:
        if path.name.startswith(key + "-"):
            path.unlink(missing_ok=True)


def write_table(out: str | os.PathLike, frame: pd.DataFrame) -> Path:
    """``records.parquet``, whole or not at all."""
    target = Path(out) / TABLE
    write_parquet(frame, target)
    return target
