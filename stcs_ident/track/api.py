"""``track``: an archive of field records into tension histories, on local processes or a Dask cluster.

1. The cables and their records (:mod:`.archive`); a record already in the
   output's table (known by content, with its path, size and modification
   time as a shortcut that spares hashing it again) is skipped.
2. The new records, in batches, each into a row (:mod:`.process`), on
   ``workers`` local processes or on the Dask cluster at ``scheduler``: the
   same function on the same inputs, so the same rows. Each finished batch
   is written as a part of the table (:mod:`.store`) before the next is
   awaited: memory holds a batch, never the archive, and a killed run keeps
   what it finished.
3. Per cable, the history of the records that gave a tension: normalised for
   temperature and its lasting changes found (:mod:`.events`).
4. The table (``records.parquet``) and a :class:`~.result.TrackResult`
   (the summary of the interface's JSON, the tables); the report is drawn
   from it by :func:`stcs_ident.report.track.write_report`.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np
import pandas as pd

from ..core.files import remove_stale
from .archive import CableSpec, content_id, discover, record_paths
from .events import analyse_history
from .process import process_record
from .result import TrackResult
from .store import append_part, processed_table, write_table

__all__ = ["BATCH", "default_out", "track"]

BATCH = 16  # records per task: a part of the table each


def default_out(archive: str | os.PathLike) -> Path:
    """Where ``track`` writes when no ``--out`` is given: ``<ARCHIVE>.track`` beside the archive."""
    root = Path(archive).resolve()
    return root.parent / f"{root.name}.track"


def process_batch(spec: CableSpec, items: list[tuple[str, str, int, int]]) -> list[dict]:
    """Rows of a batch of one cable's records: (path, record id or "", size, mtime_ns) each."""
    rows = []
    for path, record_id, size, mtime in items:
        row = process_record(spec, path, record_id or content_id(path))
        row.update(size=size, mtime_ns=mtime)
        rows.append(row)
    return rows


def track(archive: str | os.PathLike, out: str | os.PathLike | None = None, *, cables: list[str] | None = None,
          workers: int = 1, scheduler: str | None = None, batch: int = BATCH,
          progress: bool | Callable = False) -> TrackResult:
    """Process an archive's new records and analyse every cable's history (see the module docstring).

    Parameters
    ----------
    archive : path
    out : path, optional
        The output directory (default :func:`default_out`); it holds the
        state of the incremental runs.
    cables : list of str, optional
        Only these cables.
    workers : int
        Local processes (1: in this process).
    scheduler : str, optional
        Address of a Dask distributed scheduler (``tcp://host:8786``) that
        runs the batches instead of local processes.
    batch : int
        Records per task.
    progress : bool or callable(done, total)
        True: a progress bar with ETA on standard error (tqdm).

    Returns
    -------
    TrackResult
        The records table, each cable's history and events; ``.summary()`` is the ``track`` JSON of the
        interface. :func:`stcs_ident.report.track.write_report` writes the report from it.
    """
    specs = discover(archive, cables)
    out = Path(out) if out is not None else default_out(archive)
    out.mkdir(parents=True, exist_ok=True)
    remove_stale(out / "parts")  # what a killed run left, even if this one has nothing new to write there
    known = processed_table(out)
    pending = _pending(specs, known)
    total = sum(len(items) for _, items in pending)
    _run(_batches(pending, batch), total, workers, scheduler, out, progress)
    table = processed_table(out)
    table, histories = _histories(specs, table)
    write_table(out, table)
    return TrackResult(str(archive), out, tuple(specs), table, histories)


def _pending(specs: list[CableSpec], known: pd.DataFrame) -> list[tuple[CableSpec, list]]:
    """Per cable, the records not yet in the table: (path, id if already hashed, size, mtime_ns)."""
    seen = {(c, r) for c, r in zip(known["cable"], known["record_id"])}
    stats = {}
    if "size" in known:
        stats = {(c, p): (s, m, i) for c, p, s, m, i in
                 zip(known["cable"], known["record"], known["size"], known["mtime_ns"], known["record_id"])}
    out = []
    for spec in specs:
        items = []
        for path in record_paths(spec):
            st = path.stat()
            relative = path.relative_to(spec.directory).as_posix()
            cached = stats.get((spec.name, relative))
            if cached is not None and cached[0] == st.st_size and cached[1] == st.st_mtime_ns:
                continue  # the same file as when it was processed
            record_id = content_id(path)
            if (spec.name, record_id) in seen:
                continue  # processed before, under another name or time stamp
            items.append((str(path), record_id, int(st.st_size), int(st.st_mtime_ns)))
        out.append((spec, items))
    return out


def _batches(pending, size: int) -> Iterable[tuple[CableSpec, list]]:
    for spec, items in pending:
        for k in range(0, len(items), size):
            yield spec, items[k:k + size]


def _run(batches, total: int, workers: int, scheduler: str | None, out: Path, progress) -> None:
    bar = _progress_bar(total, progress)
    batches = list(batches)
    try:
        if scheduler is not None:
            _run_dask(batches, scheduler, out, bar)
        elif workers > 1 and len(batches) > 1:
            _run_local(batches, workers, out, bar)
        else:
            for spec, items in batches:
                rows = process_batch(spec, items)
                append_part(out, rows)
                bar(len(rows))
    finally:
        bar(None)


def _run_local(batches, workers: int, out: Path, bar) -> None:
    from .execution import run_local  # Ctrl-C and a killed parent handled there

    run_local(batches, workers, process_batch, _part_writer(out, bar))


def _run_dask(batches, scheduler: str, out: Path, bar) -> None:
    from .execution import run_dask  # the address checked, the scheduler probed, Ctrl-C handled there

    run_dask(batches, scheduler, process_batch, _part_writer(out, bar))


def _take(iterator, n: int) -> list:
    out = []
    for item in iterator:
        out.append(item)
        if len(out) >= n:
            break
    return out


def _progress_bar(total: int, progress) -> Callable:
    if callable(progress):
        done = [0]

        def report(n):
            if n is not None:
                done[0] += n
                progress(done[0], total)
        return report
    if not progress or total == 0:
        return lambda n: None
    from tqdm import tqdm

    bar = tqdm(total=total, unit="record", file=sys.stderr, desc="track", dynamic_ncols=True)

    def update(n):
        if n is None:
            bar.close()
        else:
            bar.update(n)
    return update


def _histories(specs: list[CableSpec], table: pd.DataFrame):
    """The table with each record's normalised tension and level, and each cable's History."""
    table = table.copy()
    table["tension_normalised"] = np.nan
    table["level"] = np.nan
    histories = {}
    for spec in specs:
        rows = table.index[(table["cable"] == spec.name) & (table["status"] == "ok")]
        rows = table.loc[rows].sort_values("start_time", kind="stable").index
        history = analyse_history(table.loc[rows, "tension"].to_numpy(), table.loc[rows, "temperature"].to_numpy(),
                                  spec.reference_tension)
        table.loc[rows, "tension_normalised"] = history.normalised
        table.loc[rows, "level"] = spec.reference_tension * (1 + history.level)
        histories[spec.name] = (rows, history)
    return table, histories


def _part_writer(out: Path, bar) -> Callable[[list], None]:
    """A finished batch's rows into a part of the table, then the progress advanced."""
    def write(rows: list) -> None:
        append_part(out, rows)
        bar(len(rows))
    return write
