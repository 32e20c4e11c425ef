"""``track``: an archive of field records into tension histories, on local processes or a Dask cluster.

1. The cables and their records (:mod:`.archive`), against the rows of the
   output's parts: per record's path, unchanged, new, changed, stale (another
   campaign, settings or toolkit: :func:`cable_version`) or retried (it
   failed), and the paths gone (:mod:`.state`).
2. The new records, in batches, each into a row (:mod:`.process`), on
   ``workers`` local processes or on the Dask cluster at ``scheduler``: the
   same function on the same inputs, so the same rows. Each finished batch
   is written as a part of the table (:mod:`.store`) before the next is
   awaited: memory holds a batch, never the archive, and a killed run keeps
   what it finished.
3. Per cable, its rows (one per record of the archive) into one part when
   they changed, and the history of the records that gave a tension:
   normalised for temperature and its lasting changes found
   (:mod:`.events`); for a cable with one damper, the history of its
   coefficient too, normalised for temperature with its lasting changes
   (:mod:`.damper_history`). With ``cables``, the other cables keep their rows.
4. The table (``records.parquet``) and a :class:`~.result.TrackResult`
   (the summary of the interface's JSON, the tables); the report is drawn
   from it by :func:`stcs_ident.report.track.write_report`.
"""

from __future__ import annotations

import hashlib
import os
import re
import sys
import warnings
from collections.abc import Callable, Iterable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from ..core.errors import InputError, TrackWarning
from ..core.files import remove_stale
from ..core.model import Damper, has_dampers
from ..core.version import __version__
from ..identify.plausibility import IMPLAUSIBLE
from .archive import CableSpec, cable_names, content_id, discover
from .damper_history import analyse_coefficient
from .events import analyse_history
from .process import MAX_MODES, process_record
from .result import TrackResult
from .state import COUNTS, current_rows, plan_cable
from .store import append_part, cable_key, read_parts, replace_parts, sort_rows, write_table

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
        if not record_id:  # hashed here, in the worker, while the file is read for the record
            try:
                record_id = content_id(path)
            except OSError:  # gone since the plan: the record's row says why it failed
                record_id = ""
        row = process_record(spec, path, record_id)
        row.update(version=spec.version, size_bytes=size, mtime_ns=mtime)
        rows.append(row)
    return rows


def cable_version(spec: CableSpec) -> str:
    """The version of what shapes a cable's rows: its campaign as parsed (not where it lies), the reference
    test's setup and tension, the reader options, the modes picked per record and the toolkit's version."""
    shaping = (replace(spec.campaign, directory=None), spec.setup, spec.reference_tension, spec.channels,
               spec.record_format, MAX_MODES, __version__)
    if has_dampers(spec.campaign.setup(spec.setup).attachments):  # rows from before the coefficient lack it
        shaping += ("damper coefficient",)
    shaping += ("doubtful numbers out of the fit",)  # rows from before fitted them
    return hashlib.sha256(repr(shaping).encode("utf-8")).hexdigest()[:16]


def track(archive: str | os.PathLike, out: str | os.PathLike | None = None, *, cables: list[str] | None = None,
          workers: int = 1, scheduler: str | None = None, batch: int = BATCH,
          progress: bool | Callable = False, check_plausibility: bool = True) -> TrackResult:
    """Bring the table of an archive up to date and analyse every cable's history (see the module docstring).

    Parameters
    ----------
    archive : path
    out : path, optional
        The output directory (default :func:`default_out`); it holds the
        state of the incremental runs.
    cables : list of str, optional
        Only these cables are brought up to date; the table keeps the rows
        of the archive's other cables as their last run left them.
    workers : int
        Local processes (1: in this process).
    scheduler : str, optional
        Address of a Dask distributed scheduler (``tcp://host:8786``) that
        runs the batches instead of local processes.
    batch : int
        Records per task.
    progress : bool or callable(done, total)
        True: a progress bar with ETA on standard error (tqdm).
    check_plausibility : bool
        Refuse (InputError) a cable whose first records all say its nominal model is implausibly far from them
        (a unit or sampling-rate slip in its campaign); False keeps their failed rows and goes on
        (``--no-plausibility-check``).

    Returns
    -------
    TrackResult
        The records table, each cable's history and events, and what the run did (``counts``);
        ``.summary()`` is the ``track`` JSON of the interface. :func:`stcs_ident.report.track.write_report`
        writes the report from it.
    """
    specs = [replace(s, version=cable_version(s)) for s in discover(archive, cables)]
    out = Path(out) if out is not None else default_out(archive)
    out.mkdir(parents=True, exist_ok=True)
    remove_stale(out / "parts")  # what a killed run left, even if this one has nothing new to write there
    known, read, unreadable = read_parts(out)
    plans = [plan_cable(spec, known) for spec in specs]
    total = sum(len(p.pending) for p in plans)
    _run(_batches([(p.spec, p.pending) for p in plans], batch), total, workers, scheduler, out, progress)
    if total:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TrackWarning)  # reported once, when read first
            known, read, unreadable = read_parts(out)
    counts = dict.fromkeys(COUNTS, 0)
    tables = []
    for plan in plans:
        for key in COUNTS:
            counts[key] += plan.counts[key]
        rows = current_rows(plan, known)
        tables.append(rows)
        mine = [p for p in read + unreadable if p.name.startswith(cable_key(plan.spec.name) + "-")]
        if plan.dirty or len(mine) > 1 or len(rows) != int((known["cable"] == plan.spec.name).sum()):
            replace_parts(out, plan.spec.name, rows, mine)
    specs, others, gone = _other_cables(archive, specs, known)
    counts["removed"] += len(known[known["cable"].isin(gone)].drop_duplicates(["cable", "record"]))
    for path in read:  # the parts of cables no longer in the archive
        if path.name.split("-")[0] in {cable_key(name) for name in gone}:
            path.unlink(missing_ok=True)
    table = sort_rows(pd.concat([*tables, others], ignore_index=True).drop(columns="part"))
    if check_plausibility:
        _refuse_slips(specs, table)
    table, histories = _histories(specs, table)
    table, dampers = _damper_histories(specs, table)
    write_table(out, table)
    return TrackResult(str(archive), out, tuple(specs), table, histories, counts=counts, dampers=dampers)


#: A cable whose first this many records (by start time) all failed the record path's plausibility is refused.
FIRST_RECORDS = 3


def _refuse_slips(specs: list[CableSpec], table: pd.DataFrame) -> None:
    """Refuse (InputError, exit 2 from the command line) a cable whose first :data:`FIRST_RECORDS` records all
    say its nominal model is implausibly far from them: a unit or sampling-rate slip in its campaign, which no
    history can be made of (a cable that changed later has plausible first records)."""
    for spec in specs:
        rows = table[table["cable"] == spec.name].sort_values("start_time", na_position="last")
        first = rows.head(FIRST_RECORDS)
        if len(first) and (first["status"] == "failed").all() and \
                first["reason"].str.contains(IMPLAUSIBLE, regex=False).all():
            reason = str(first["reason"].iloc[0])
            named = re.search(r"field '([^']+)'", reason)
            field = named.group(1) if named else None
            if field is not None and field.startswith("test["):  # the record's test is the campaign's reference
                field = f"test[{spec.campaign.tests[0].name}]" + field[field.index("]") + 1:]
            raise InputError(f"cable {spec.name}: its first {len(first)} record(s) refused: "
                             f"{reason[reason.index(IMPLAUSIBLE):]}", field=field,
                             file=str(Path(spec.directory) / "campaign.toml"))


def _other_cables(archive, specs: list[CableSpec], known: pd.DataFrame):
    """The specs of every cable in the table, in the archive's order (the selected ones, and the others that
    have rows), the latest row per path of the others, and the names of the cables no longer in the archive."""
    names = cable_names(archive)
    selected = {s.name for s in specs}
    rest = known[~known["cable"].isin(selected)].drop_duplicates(["cable", "record"], keep="last")
    gone = sorted(set(rest["cable"]) - set(names))
    keep = rest["cable"].isin(names)
    by_name = {s.name: s for s in specs}
    for name in sorted(set(rest.loc[keep, "cable"])):
        try:
            spec = discover(archive, [name])[0]
        except InputError:  # a campaign that cannot be read now: its rows wait for a run of that cable
            keep &= rest["cable"] != name
            continue
        by_name[name] = replace(spec, version=cable_version(spec))
    kept = rest[keep]
    # Rows processed under another campaign or toolkit are not this archive's any more: a run of their cable
    # processes them again.
    kept = kept[kept["version"] == kept["cable"].map(lambda c: by_name[c].version)]
    ordered = [by_name[n] for n in names if n in by_name]
    return ordered, kept, gone


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
    table["tension_normalised_N"] = np.nan
    table["tension_level_N"] = np.nan
    histories = {}
    for spec in specs:
        rows = table.index[(table["cable"] == spec.name) & (table["status"] == "ok")]
        rows = table.loc[rows].sort_values("start_time", kind="stable").index
        starts = table.loc[rows, "start_time"]
        history = analyse_history(table.loc[rows, "tension_N"].to_numpy(),
                                  table.loc[rows, "temperature_degC"].to_numpy(),
                                  spec.reference_tension,
                                  times=(starts - starts.min()).dt.total_seconds().to_numpy(dtype=float))
        table.loc[rows, "tension_normalised_N"] = history.normalised
        table.loc[rows, "tension_level_N"] = spec.reference_tension * (1 + history.level)
        histories[spec.name] = (rows, history)
    return table, histories


def _damper_histories(specs: list[CableSpec], table: pd.DataFrame):
    """The table with each record's normalised coefficient and its level, and each damped cable's coefficient
    History (:mod:`.damper_history`): the cables whose setup has one damper."""
    table = table.copy()
    table["coefficient_normalised_Ns_per_m"] = np.nan
    table["coefficient_level_Ns_per_m"] = np.nan
    dampers = {}
    for spec in specs:
        damper = reference_damper(spec)
        if damper is None:
            continue
        mine = (table["cable"] == spec.name) & (table["status"] == "ok")
        usable = mine & (table["coefficient_Ns_per_m"] > 0) & (table["coefficient_sigma_Ns_per_m"] > 0)
        rows = table.loc[table.index[usable]].sort_values("start_time", kind="stable").index
        starts = table.loc[rows, "start_time"]
        history = analyse_coefficient(table.loc[rows, "coefficient_Ns_per_m"].to_numpy(),
                                      table.loc[rows, "coefficient_sigma_Ns_per_m"].to_numpy(),
                                      table.loc[rows, "temperature_degC"].to_numpy(), damper.coefficient,
                                      times=(starts - starts.min()).dt.total_seconds().to_numpy(dtype=float))
        table.loc[rows, "coefficient_normalised_Ns_per_m"] = history.normalised
        table.loc[rows, "coefficient_level_Ns_per_m"] = damper.coefficient * (1 + history.level)
        dampers[spec.name] = (rows, history)
    return table, dampers


def reference_damper(spec: CableSpec) -> Damper | None:
    """The cable's damper whose coefficient is tracked: the one damper of its setup (None: none, or several)."""
    found = [a for a in spec.campaign.setup(spec.setup).attachments if isinstance(a, Damper)]
    return found[0] if len(found) == 1 else None


def _part_writer(out: Path, bar) -> Callable[[list], None]:
    """A finished batch's rows into a part of the table, then the progress advanced."""
    def write(rows: list) -> None:
        append_part(out, rows)
        bar(len(rows))
    return write
