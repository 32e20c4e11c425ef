"""The ``track`` report: per cable the tension history and its modes, a summary of the cables, the events.

    OUT/records.parquet          one row per record (written by the run)
    OUT/records.csv              the same table as CSV (lists of modes and frequencies joined by ';')
    OUT/report.md                the summary table, the events, the failed records
    OUT/events.csv               one row per lasting change
    OUT/cables.csv               one row per cable
    OUT/<cable>.png              tension (as identified and normalised for temperature, 1σ band,
                                 events marked), temperature, the frequency of each mode and, for a
                                 cable with one damper, its coefficient (fitted, normalised, level,
                                 damper events marked)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..core.files import write_atomic, write_csv, write_figure
from ..core.model import Damper
from .plots import Drawn, new_figure

__all__ = ["joined", "plot_cable_history", "records_csv_table", "write_report"]

#: Markers of the frequency panel, one per ten modes (the colours repeat every ten: tab10).
MODE_MARKERS = (".", "x", "+", "1", "d")


def write_report(result, out: str | Path | None = None) -> Path:
    """Write the report of a :class:`~stcs_ident.track.result.TrackResult` into ``out`` (default the run's
    output directory, ``result.out``): the tables as CSV, one figure per cable and ``report.md``.

    Returns
    -------
    Path
        The directory written.
    """
    out = Path(result.out if out is None else out)
    tables = result.tables()
    cables, events = tables["cables"], tables["events"]
    write_csv(records_csv_table(result.table), out / "records.csv", index=False)
    write_csv(cables, out / "cables.csv", index=False)
    write_csv(events, out / "events.csv", index=False)
    for spec in result.specs:
        rows, history = result.histories[spec.name]
        damper = getattr(result, "dampers", {}).get(spec.name)
        write_figure(plot_cable_history(spec, result.table, rows, history, damper=damper)["figure"],
                     out / f"{spec.name}.png")
    write_atomic(out / "report.md", _markdown(result.summary(), cables, events))
    return out


def records_csv_table(table: pd.DataFrame) -> pd.DataFrame:
    """The records table (``records.parquet``) with plain cells for CSV.

    The per-record lists (``modes``, ``planes``, ``frequencies_Hz``, ``frequency_sigma_Hz``, ``doubtful``,
    ``damping_ratio``, ``damping_ratio_sigma``) become their values joined by ``;`` (:func:`joined`: ``doubtful``
    as ``True``/``False``, floats in their shortest exact form) and ``start_time`` an ISO 8601 string; every
    other column is as in the Parquet table.
    """
    plain = table.copy()
    for name, cast in (("modes", int), ("planes", str), ("frequencies_Hz", float), ("frequency_sigma_Hz", float),
                       ("doubtful", bool), ("damping_ratio", float), ("damping_ratio_sigma", float)):
        if name in plain:
            plain[name] = [joined(values, cast) for values in plain[name]]
    if "start_time" in plain:
        plain["start_time"] = [None if pd.isna(t) else t.isoformat() for t in plain["start_time"]]
    return plain


def joined(values, cast=None) -> str:
    """A list as one CSV cell: its values joined by ``;``, each as Python writes it plainly (``str`` of a float
    is its shortest exact form, of a bool ``True``/``False``), never a numpy repr; ``cast`` (``int``, ``float``,
    ``bool``, ``str``) first makes each value a Python one."""
    return ";".join(str(x if cast is None else cast(x)) for x in values)


def plot_cable_history(spec, table: pd.DataFrame, rows, history, fig=None, damper=None) -> Drawn:
    """One cable's history: tension (identified, normalised, level, events), temperature, frequency / mode.

    Parameters
    ----------
    spec : the cable's specification in the run (``name``, ``campaign``, ``reference_tension``)
    table : DataFrame
        One row per record (``start_time``, ``tension_N``, ``tension_sigma_N``,
        ``tension_level_N``, ``temperature_degC``, ``modes``, ``planes``, ``frequencies_Hz``).
    rows : the labels of this cable's rows in ``table``
    history : the cable's tension history (``normalised``, ``mean_temperature``, ``events``)
    fig : matplotlib.figure.Figure, optional
    damper : (row labels, History), optional
        The damper's coefficient history (``coefficient_Ns_per_m``, ``coefficient_sigma_Ns_per_m``,
        ``coefficient_level_Ns_per_m`` of
        ``table``): a fourth panel.

    Returns
    -------
    dict with the figure, the axes (``axes``: tension, temperature, frequency, and the damper's coefficient
    when given) and the frequency
    panel's lines by mode (``modes``: {mode: Line2D}, an out-of-plane mode under ``"<mode> out"``); past mode 10
    the colours repeat with another marker.
    """
    data = table.loc[rows]
    if not data["tension_N"].notna().any():  # every record failed: say so; the reasons are in report.md
        fig = fig or new_figure(figsize=(10, 1.2), layout="constrained")
        ax = fig.subplots()
        ax.set_axis_off()
        ax.text(0.5, 0.5, f"{spec.name}: no record with a tension (the failed records and their reasons are "
                "listed in report.md)", ha="center", va="center", transform=ax.transAxes)
        return Drawn({"figure": fig, "axes": (ax,), "modes": {}})
    if damper is None:
        fig = fig or new_figure(figsize=(10, 7.5), layout="constrained")
        top, middle, bottom = fig.subplots(3, 1, sharex=True, height_ratios=(3, 1.2, 2))
    else:
        fig = fig or new_figure(figsize=(10, 10), layout="constrained")
        top, middle, bottom, lowest = fig.subplots(4, 1, sharex=True, height_ratios=(3, 1.2, 2, 2.5))
    t = data["start_time"].dt.tz_convert(None) if len(data) else data["start_time"]
    kN = 1e-3
    tension, sigma = data["tension_N"].to_numpy() * kN, data["tension_sigma_N"].to_numpy() * kN
    top.fill_between(t, tension - sigma, tension + sigma, color="tab:blue", alpha=0.25, lw=0, label="1σ")
    top.plot(t, tension, ".", ms=2.5, color="tab:blue", label="identified")
    top.plot(t, history.normalised * kN, ".", ms=2.5, color="tab:orange",
             label=_normalised_label(history))
    top.plot(t, data["tension_level_N"].to_numpy() * kN, "-", color="k", lw=1, label="level between changes")
    for e in history.events:
        top.axvline(t.iloc[e.index], color="tab:red", lw=1.2)
        top.annotate(f" {100 * e.change:+.2f} ± {100 * e.uncertainty:.2f} %", (t.iloc[e.index], 0.97),
                     xycoords=("data", "axes fraction"), va="top", ha="left", color="tab:red", fontsize=8)
    top.set_ylabel("tension (kN)")
    top.set_title(f"{spec.name}: {len(data)} records with a tension; reference {spec.reference_tension * kN:.1f} kN, "
                  f"EI {spec.campaign.cable.EI:.4g} N m² (held)")
    top.legend(loc="lower left", fontsize=8, ncol=4)
    if data["temperature_degC"].notna().any():
        middle.plot(t, data["temperature_degC"], "-", color="tab:green", lw=0.8)
    middle.set_ylabel("temperature (°C)")
    planes = data["planes"] if "planes" in data else [["in"] * len(ms) for ms in data["modes"]]
    keyed = [dict(zip(zip(ps, ms), f)) for ms, ps, f in zip(data["modes"], planes, data["frequencies_Hz"])]
    modes = sorted({key for k in keyed for key in k}, key=lambda key: (key[0] != "in", key[1]))
    colours = [f"C{i}" for i in range(10)]
    drawn = {}
    for i, (plane, mode) in enumerate(modes):
        pairs = [(time, k[(plane, mode)]) for time, k in zip(t, keyed) if (plane, mode) in k]
        times, freq = zip(*pairs)
        marker = MODE_MARKERS[(i // 10) % len(MODE_MARKERS)]
        key = mode if plane == "in" else f"{mode} out"  # the out-of-plane modes: their own lines
        drawn[key] = bottom.plot(times, np.asarray(freq) / mode, marker, color=colours[i % 10],
                                 ms=2 if marker == "." else 3, mew=0.6, label=f"mode {key}")[0]
    bottom.set_ylabel("frequency / mode number (Hz)")
    if modes:
        bottom.legend(loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize=7, ncol=1 + len(modes) // 12,
                      markerscale=2)
    axes = (top, middle, bottom)
    if damper is not None:
        _damper_panel(lowest, spec, table, *damper)
        axes += (lowest,)
    axes[-1].set_xlabel("time (UTC)")
    return Drawn({"figure": fig, "axes": axes, "modes": drawn})


def _damper_panel(ax, spec, table: pd.DataFrame, rows, history) -> None:
    """The damper's coefficient per record (1σ bars), normalised to the mean temperature, its level and the
    damper events."""
    data = table.loc[rows]
    if not len(data):
        ax.text(0.5, 0.5, "damper: no record with a coefficient (the reasons are in records.parquet, "
                "coefficient_reason)", ha="center", va="center", transform=ax.transAxes, fontsize=8)
        ax.set_ylabel("damper (kN s/m)")
        return
    t = data["start_time"].dt.tz_convert(None)
    k = 1e-3
    ax.errorbar(t, data["coefficient_Ns_per_m"] * k, yerr=data["coefficient_sigma_Ns_per_m"] * k, fmt=".", ms=3, lw=0.4,
                color="tab:blue", alpha=0.35, label="fitted, 1σ")
    ax.plot(t, history.normalised * k, ".", ms=2.5, color="tab:purple",
            label=_normalised_label(history))
    ax.plot(t, data["coefficient_level_Ns_per_m"] * k, "-", color="k", lw=1, label="level between changes")
    for e in history.events:
        ax.axvline(t.iloc[e.index], color="tab:red", lw=1.2)
        ax.annotate(f" {100 * e.change:+.1f} ± {100 * e.uncertainty:.1f} %", (t.iloc[e.index], 0.97),
                    xycoords=("data", "axes fraction"), va="top", ha="left", color="tab:red", fontsize=8)
    shown = np.concatenate([history.normalised, data["coefficient_Ns_per_m"].to_numpy()]) * k
    low, high = np.nanpercentile(shown, [1, 99])
    ax.set_ylim(max(0.0, low - 0.5 * (high - low)), high + 0.5 * (high - low))  # a wild record off the scale
    ax.set_ylabel("damper (kN s/m)")
    thermal = (f"{100 * history.thermal_coefficient:+.2f} % per °C; " if history.state == "monitoring"
               and np.isfinite(history.mean_temperature) else "")
    ax.set_title(f"damper {_damper_name(spec)}: {len(data)} records with a coefficient; {thermal}{history.state}",
                 fontsize=9)
    ax.legend(loc="lower left", fontsize=8, ncol=3)


def _markdown(summary: dict, cables: pd.DataFrame, events: pd.DataFrame) -> str:
    lines = [f"# Tension histories of {summary['archive']}", "",
             ("Tensions are fitted per record with EI held at the campaign's value, from the modes picked and "
             "numbered against the nominal model at the reference tension. The normalised tension removes a "
             "linear temperature effect fitted per cable; a lasting change is found by a two-sided CUSUM of the "
             "normalised tension (see the documentation of `track`)."), "", "## Cables", "",
             "| cable | records | with a tension | failed | reference (kN) | per °C | scatter | events | state |",
             "|---|---|---|---|---|---|---|---|---|"]
    for _, c in cables.iterrows():
        thermal = ("" if pd.isna(c["thermal_coefficient_per_degC"])
                   else f"{100 * c['thermal_coefficient_per_degC']:+.3f} %")
        scatter = "" if pd.isna(c["scatter_ratio"]) else f"{100 * c['scatter_ratio']:.2f} %"
        state = summary["cables"][c["cable"]]["state_note"]  # the command's line says the same
        lines.append(f"| {c['cable']} | {c['n_records']} | {c['n_processed']} | {c['n_failed']} | "
                     f"{c['reference_tension_N'] / 1e3:.1f} | {thermal} | {scatter} | {c['n_events']} | {state} |")
    lines += ["", "## Lasting changes", ""]
    if (events["kind"] != "damper").sum() == 0:
        lines.append("None found.")
    else:
        lines += ["| cable | from | change | 1σ | alarm at |", "|---|---|---|---|---|"]
        for _, e in events[events["kind"] != "damper"].iterrows():
            lines.append(f"| {e['cable']} | {e['start_time']} | {100 * e['change_ratio']:+.2f} % | "
                         f"{100 * e['uncertainty_ratio']:.2f} % | {e['alarm_time']} |")
    dampers = {name: c["damper"] for name, c in summary["cables"].items() if "damper" in c}
    if dampers:
        lines += _damper_markdown(dampers)
    failures = [(name, f) for name, c in summary["cables"].items() for f in c["failures"]]
    lines += ["", "## Records without a tension", ""]
    lines += [f"- {name}/{f['record']}: {f['reason']}" for name, f in failures] or ["None."]
    lines += ["", "Figures: " + ", ".join(f"[{n}]({n}.png)" for n in summary["cables"]), ""]
    return "\n".join(lines)


def _damper_name(spec) -> str:
    return next((a.name for a in spec.campaign.setup(spec.setup).attachments if isinstance(a, Damper)), "")


def _damper_markdown(dampers: dict) -> list[str]:
    lines = ["", "## The dampers", "",
             ("Per record, the damper's coefficient is fitted jointly with the tension from the frequencies and "
              "damping ratios; its logarithm is normalised for a linear temperature effect and its lasting "
              "changes found by the same CUSUM as the tension's, each record weighted by its 1σ."), "",
             "| cable | reference (kN s/m) | records with a coefficient | without | per °C | state | events |",
             "|---|---|---|---|---|---|---|"]
    for name, d in dampers.items():
        thermal = "" if d["thermal_coefficient"] is None else f"{100 * d['thermal_coefficient']:+.2f} %"
        lines.append(f"| {name} | {d['reference_coefficient'] / 1e3:.1f} | {d['records']} | {len(d['failures'])} | "
                     f"{thermal} | {d['state_note']} | {len(d['events'])} |")
    lines += ["", "### Damper events", ""]
    found = [(name, e) for name, d in dampers.items() for e in d["events"]]
    if not found:
        lines.append("None found.")
    else:
        lines += ["| cable | from | change | 1σ | alarm at |", "|---|---|---|---|---|"]
        lines += [f"| {name} | {e['start_time']} | {100 * e['change']:+.1f} % | {100 * e['uncertainty']:.1f} % | "
                  f"{e['alarm_time']} |" for name, e in found]
    return lines


def _normalised_label(history) -> str:
    """The legend of a history's normalised values: to which temperature, or why not (none recorded, or a history
    shorter than its training window, whose temperature terms wait for a whole day: :mod:`..track.events`)."""
    if not np.isfinite(history.mean_temperature):
        return "no temperature: not normalised"
    if not np.isfinite(history.thermal_coefficient):
        return "not normalised yet (less than a day)"
    return f"normalised to {history.mean_temperature:.1f} °C"
