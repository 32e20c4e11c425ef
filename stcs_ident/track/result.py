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

from ..core.model import Damper
from ..core.result import Result
from ..core.settings import Settings
from .archive import CableSpec
from .events import History, state_note

__all__ = ["TrackResult"]

#: Columns of the ``events`` table: ``change_ratio`` (after / before − 1) and its 1σ ``uncertainty_ratio``;
#: ``kind`` is ``tension`` or ``damper`` (a lasting change of the damper's coefficient).
EVENT_COLUMNS = ["cable", "start_time", "change_ratio", "uncertainty_ratio", "alarm_time", "kind"]

#: Columns of the ``cables`` table: counts of records, the reference tension, the EI held, the thermal coefficient
#: (relative change per °C) and the scatter (relative), the events found and the state.
CABLE_COLUMNS = ["cable", "n_records", "n_processed", "n_failed", "reference_tension_N", "EI_Nm2",
                 "thermal_coefficient_per_degC", "scatter_ratio", "n_events", "state"]
#: Columns added to ``cables`` when a cable of the run has one damper (empty for the others).
DAMPER_CABLE_COLUMNS = ["reference_coefficient_Ns_per_m", "damper_thermal_coefficient_per_degC",
                        "damper_scatter_ratio", "damper_n_events", "damper_state"]


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
        ``version``, ``size_bytes`` and ``mtime_ns``), with each record's
        ``tension_normalised_N`` (to the cable's mean temperature) and the
        ``tension_level_N`` between lasting changes (NaN for a record without a
        tension), and for a damped cable ``coefficient_normalised_Ns_per_m`` and
        ``coefficient_level_Ns_per_m`` (NaN for a record without a coefficient).
        List cells (``modes``, ``frequencies_Hz``, ...) hold one value per mode;
        ``records.csv`` writes them joined by ``;``.
    histories : dict
        {cable: (row labels of ``table`` with a tension, in time order,
        :class:`~stcs_ident.track.events.History`)}.
    counts : dict
        What this run did, per kind of slot (:data:`~stcs_ident.track.state.COUNTS`: ``new``, ``changed``,
        ``stale``, ``removed``, ``retried``, ``unchanged``); :meth:`run_line` says it in one line.
    settings : Settings
        The model settings every record was identified with.
    notes : tuple of Note
    dampers : dict
        {cable: (row labels of ``table`` with a coefficient, in time order, the coefficient's
        :class:`~stcs_ident.track.events.History` from :mod:`~stcs_ident.track.damper_history`)}, for the
        cables whose setup has one damper.
    """

    archive: str
    out: Path
    specs: tuple[CableSpec, ...]
    table: pd.DataFrame
    histories: dict[str, tuple[pd.Index, History]]
    counts: dict[str, int] = field(default_factory=dict)
    settings: Settings = field(default_factory=Settings)
    notes: tuple = ()
    dampers: dict[str, tuple[pd.Index, History]] = field(default_factory=dict)

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
            "thermal_coefficient": None if math.isnan(history.mean_temperature) or math.isnan(
                history.thermal_coefficient) else history.thermal_coefficient,
            "scatter": None if math.isnan(history.scatter) else history.scatter,
            "state": history.state, "state_note": state_note(history), "records_needed": history.records_needed,
            "events": _events(history, times, "tension"),
            "failures": [{"record": r, "reason": why} for r, why in
                         zip(mine.loc[failed, "record"], mine.loc[failed, "reason"])],
            **({"damper": self._damper_summary(spec)} if spec.name in self.dampers else {}),
        }

    def _damper_summary(self, spec: CableSpec) -> dict:
        rows, history = self.dampers[spec.name]
        mine = self.table[(self.table["cable"] == spec.name) & (self.table["status"] == "ok")]
        missing = mine[~(mine["coefficient_Ns_per_m"] > 0)]
        return {
            "reference_coefficient": _reference_coefficient(spec),
            "records": len(rows),
            "thermal_coefficient": None if math.isnan(history.mean_temperature) or math.isnan(
                history.thermal_coefficient) else history.thermal_coefficient,
            "scatter": None if math.isnan(history.scatter) else history.scatter,
            "state": history.state, "state_note": state_note(history), "records_needed": history.records_needed,
            "events": _events(history, self.table.loc[rows, "start_time"].to_numpy(), "damper"),
            "failures": [{"record": r, "reason": why} for r, why in
                         zip(missing["record"], missing["coefficient_reason"])],
        }

    def summary(self) -> dict:
        """The ``track`` JSON of the interface (plain data): the archive and, per cable, its counts,
        reference tension, EI held, thermal coefficient, scatter, state (``state``; ``state_note`` in words,
        :func:`~stcs_ident.track.events.state_note`, the command's line and the report say the same;
        ``records_needed`` before change detection starts), events and failed records; for a cable with
        one damper, ``damper``: its reference coefficient, the records with a coefficient, the coefficient's
        thermal coefficient (relative, per °C), scatter, state, events (``kind`` ``damper``) and the records
        with a tension but no coefficient (``failures``, the reason)."""
        return {"archive": str(self.archive), "cables": self.cables}

    def tables(self) -> dict[str, pd.DataFrame]:
        """``cables`` (one row per cable, the main table; with a damped cable among them, the damper's columns,
        empty for a cable without one damper), ``events`` (one row per lasting change of a tension or a damper's coefficient, ``kind``) and
        ``records`` (one row per record: :attr:`table`)."""
        cables = self.cables
        summary = pd.DataFrame([
            {"cable": name, "n_records": c["records"], "n_processed": c["processed"], "n_failed": c["failed"],
             "reference_tension_N": c["reference_tension"], "EI_Nm2": c["EI"],
             "thermal_coefficient_per_degC": c["thermal_coefficient"], "scatter_ratio": c["scatter"],
             "n_events": len(c["events"]), "state": c["state"], **_damper_columns(c, bool(self.dampers))}
            for name, c in cables.items()], columns=CABLE_COLUMNS + (DAMPER_CABLE_COLUMNS if self.dampers else []))
        events = pd.DataFrame([{"cable": name, "start_time": e["start_time"], "change_ratio": e["change"],
                                "uncertainty_ratio": e["uncertainty"], "alarm_time": e["alarm_time"],
                                "kind": e["kind"]}
                               for name, c in cables.items()
                               for e in c["events"] + c.get("damper", {}).get("events", [])],
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
        line = (f"{self.archive}: {n} cable{'s' if n != 1 else ''}, {len(self.table)} records "
                f"({int((status == 'ok').sum())} with a tension, {int((status != 'ok').sum())} failed), "
                f"{events} lasting change{'s' if events != 1 else ''}")
        if self.dampers:
            damper = sum(len(h.events) for _, h in self.dampers.values())
            line += f", {damper} of a damper"
        return line


def _damper_columns(cable: dict, any_damper: bool) -> dict:
    if not any_damper:
        return {}
    d = cable.get("damper", {})
    return {"reference_coefficient_Ns_per_m": d.get("reference_coefficient"),
            "damper_thermal_coefficient_per_degC": d.get("thermal_coefficient"),
            "damper_scatter_ratio": d.get("scatter"), "damper_n_events": len(d["events"]) if d else None,
            "damper_state": d.get("state")}


def _events(history: History, times, kind: str) -> list[dict]:
    return [{"start_time": pd.Timestamp(times[e.index]).isoformat(), "change": e.change,
             "uncertainty": e.uncertainty, "alarm_time": pd.Timestamp(times[e.alarm]).isoformat(), "kind": kind}
            for e in history.events]


def _reference_coefficient(spec: CableSpec) -> float:
    return next(float(a.coefficient) for a in spec.campaign.setup(spec.setup).attachments if isinstance(a, Damper))
