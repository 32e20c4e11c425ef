"""The result of :func:`~stcs_ident.track.api.track`: the records table, each cable's history and events.

:class:`TrackResult` holds the data (the table of every record, per cable
its :class:`~stcs_ident.track.events.History`); ``summary()`` is the
``track`` JSON of the interface, ``tables()`` the records, the cables and
the events as DataFrames. The report (:mod:`stcs_ident.report.track`) is
drawn from it; this module does not import it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from ..core.result import Result
from ..core.settings import Settings
from .archive import CableSpec
from .events import History

__all__ = ["TrackResult"]

#: Columns of the ``events`` table.
EVENT_COLUMNS = ["cable", "start_time", "change", "uncertainty", "alarm_time"]


@dataclass(frozen=True, repr=False)
class TrackResult(Result):
    """Tension histories of an archive's cables.

    Attributes
    ----------
    archive : str
        The archive directory, as given.
    out : Path
        The output directory: the table of every record processed so far
        (``records.parquet``), the state of the incremental runs.
    specs : tuple of CableSpec
        The cables tracked, in order.
    table : DataFrame
        One row per record of these cables (``track.process.COLUMNS``, with
        ``size`` and ``mtime_ns``), with each record's
        ``tension_normalised`` (to the cable's mean temperature) and the
        ``level`` between lasting changes (N; NaN for a record without a
        tension).
    histories : dict
        {cable: (row labels of ``table`` with a tension, in time order,
        :class:`~stcs_ident.track.events.History`)}.
    counts : dict
        What this run did, per kind of slot (:data:`~stcs_ident.track.state.COUNTS`: ``new``, ``changed``,
        ``stale``, ``removed``, ``retried``, ``unchanged``); :meth:`run_line` says it in one line.
    settings : Settings
        The model settings every record was identified with.
    notes : tuple of Note
    """

    archive: str
    out: Path
    specs: tuple[CableSpec, ...]
    table: pd.DataFrame
    histories: dict[str, tuple[pd.Index, History]]
    counts: dict[str, int] = field(default_factory=dict)
    settings: Settings = field(default_factory=Settings)
    notes: tuple = ()

    main_table = "cables"

    @property
    def cables(self) -> dict[str, dict]:
        """Per cable, its summary (the ``cables`` object of :meth:`summary`)."""
        return {spec.name: self._cable_summary(spec) for spec in self.specs}

    def history(self, cable: str) -> History:
        """The tension history of the cable called ``cable``."""
        if cable not in self.histories:
            raise KeyError(f"no cable named {cable!r} (tracked: {', '.join(self.histories)})")
        return self.histories[cable][1]

    def _cable_summary(self, spec: CableSpec) -> dict:
        mine = self.table[self.table["cable"] == spec.name]
        rows, history = self.histories[spec.name]
        times = self.table.loc[rows, "start_time"].to_numpy()
        failed = mine["status"] != "ok"
        return {
            "records": len(mine), "processed": int((~failed).sum()), "failed": int(failed.sum()),
            "reference_tension": spec.reference_tension, "EI": spec.campaign.cable.EI,
            "thermal_coefficient": None if math.isnan(history.mean_temperature) else history.thermal_coefficient,
            "scatter": None if math.isnan(history.scatter) else history.scatter,
            "state": history.state,
            "events": [{"start_time": pd.Timestamp(times[e.index]).isoformat(),
                        "change": e.change, "uncertainty": e.uncertainty,
                        "alarm_time": pd.Timestamp(times[e.alarm]).isoformat()} for e in history.events],
            "failures": [{"record": r, "reason": why} for r, why in
                         zip(mine.loc[failed, "record"], mine.loc[failed, "reason"])],
        }

    def summary(self) -> dict:
        """The ``track`` JSON of the interface (plain data): the archive and, per cable, its counts,
        reference tension, EI held, thermal coefficient, scatter, events and failed records."""
        return {"archive": str(self.archive), "cables": self.cables}

    def tables(self) -> dict[str, pd.DataFrame]:
        """``cables`` (one row per cable, the main table), ``events`` (one row per lasting change) and
        ``records`` (one row per record: :attr:`table`)."""
        cables = self.cables
        summary = pd.DataFrame([
            {"cable": name, "records": c["records"], "processed": c["processed"], "failed": c["failed"],
             "reference_tension_kN": c["reference_tension"] / 1e3, "EI_Nm2": c["EI"],
             "thermal_coefficient_per_C": c["thermal_coefficient"], "scatter": c["scatter"],
             "events": len(c["events"]), "state": c["state"]}
            for name, c in cables.items()])
        events = pd.DataFrame([{"cable": name, **e} for name, c in cables.items() for e in c["events"]],
                              columns=EVENT_COLUMNS)
        return {"cables": summary, "events": events, "records": self.table}

    def run_line(self) -> str:
        """What this run did: ``track: 3 new, 1 changed, 2 stale, 1 removed, 2 retried, 590 unchanged``."""
        return "track: " + ", ".join(f"{n} {kind}" for kind, n in self.counts.items())

    def headline(self) -> str:
        """Archive, cables, records with a tension and failed, lasting changes found."""
        status = self.table.loc[self.table["cable"].isin([s.name for s in self.specs]), "status"]
        events = sum(len(h.events) for _, h in self.histories.values())
        n = len(self.specs)
        return (f"{self.archive}: {n} cable{'s' if n != 1 else ''}, {len(self.table)} records "
                f"({int((status == 'ok').sum())} with a tension, {int((status != 'ok').sum())} failed), "
                f"{events} lasting change{'s' if events != 1 else ''}")
