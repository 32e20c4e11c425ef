"""Figures of a diagnosis (headless, Agg).

Each function builds on a :class:`matplotlib.figure.Figure` or a given Axes,
never on pyplot's global state, and returns what it drew so that tests can
inspect it (as :mod:`stcs_ident.report.plots`). matplotlib is imported only when a
figure is made.
"""

from __future__ import annotations

import math

import numpy as np

from .. import effects as registry
from .plots import Drawn, mode_axis, new_figure, set_mode_ticks

#: How the three models of the residual figure are drawn: label, colour, marker, x offset (modes).
RESIDUAL_STYLE = {
    "nominal": ("nominal model", "0.35", "o", -0.18),
    "baseline": ("baseline: tension + EI refitted", "tab:blue", "s", 0.0),
    "corrected": ("corrected: named cause", "tab:red", "^", 0.18),
}


def _models(diagnosis) -> dict:
    """{"nominal" | "baseline" | "corrected": (fit, label)} of the models to compare."""
    d = diagnosis
    out = {"nominal": d.nominal}
    if d.baseline is not None:
        out["baseline"] = d.baseline
    out["corrected"] = d.corrected
    return out


def plot_residuals(diagnosis, fig=None) -> Drawn:
    """Error in % per mode for each test: nominal, baseline and corrected.

    The grey band is ± one standard uncertainty of the measured frequency,
    in % of it: a model inside the band agrees with the measurement.

    Parameters
    ----------
    diagnosis : Diagnosis
    fig : matplotlib.figure.Figure, optional

    Returns
    -------
    dict with the figure, the axes (one per test), the plotted lines by
    model (``lines``: {model: [Line2D per test]}) and the uncertainty bands.
    """
    d = diagnosis
    n = len(d.measurements)
    ncols = 1 if n == 1 else 2
    nrows = math.ceil(n / ncols)
    fig = fig or new_figure(figsize=(5.2 * ncols, 2.7 * nrows + 0.9), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False).ravel())
    models = _models(d)
    if models["corrected"] is models["nominal"]:
        models.pop("corrected")  # the cause is empty: corrected is the nominal model
    per_test = {key: d.per_test(fit) for key, fit in models.items()}
    lines: dict[str, list] = {key: [] for key in models}
    bands = []
    for i, (m, ax) in enumerate(zip(d.measurements, axes)):
        k, _ = mode_axis(m.modes, getattr(m, "planes", None))  # out-of-plane modes after the in-plane ones
        u = m.uncertainty / m.frequencies * 100.0
        edges = np.concatenate([[k[0] - 0.4], (k[:-1] + k[1:]) / 2, [k[-1] + 0.4]])
        bands.append(ax.stairs(u, edges, baseline=-u, fill=True, color="0.85", lw=0,
                               label="measurement uncertainty (±1σ)"))
        ax.axhline(0.0, color="0.5", lw=0.6)
        for key in models:
            label, colour, marker, dx = RESIDUAL_STYLE[key]
            err = (per_test[key][i] - m.frequencies) / m.frequencies * 100.0
            xs, ys = _broken_between_planes(k + dx, err, getattr(m, "planes", None))
            lines[key].append(ax.plot(xs, ys, marker=marker, color=colour, lw=0.8, ms=5, label=label)[0])
        ax.set_title(f"{m.name} (setup {m.test.setup}, {m.test.tension / 1e3:.4g} kN)", fontsize=9)
        set_mode_ticks(ax, m.modes, getattr(m, "planes", None))
        ax.set_xlim(k[0] - 0.6, k[-1] + 0.6)
        ax.grid(True, axis="y", lw=0.3, alpha=0.6)
        if i % ncols == 0:
            ax.set_ylabel("error (%)")
        if i >= n - ncols:
            ax.set_xlabel("mode")
    for ax in axes[n:]:
        ax.set_visible(False)
    handles, labels = axes[0].get_legend_handles_labels()
    # One test's panel is too narrow for the four entries side by side: two rows then, not a clipped row.
    fig.legend(handles, labels, loc="outside upper center", ncols=len(labels) if ncols > 1 else 2, fontsize=8,
               frameon=False)
    return Drawn({"figure": fig, "axes": list(axes[:n]), "lines": lines, "bands": bands})


#: A profile whose χ² varies by less than this over the whole span says nothing about the position
#: (Δχ² = 1 is the width of a 1σ interval): it is not drawn.
FLAT_PROFILE = 1.0


def cause_profiles(diagnosis) -> dict:
    """{effect: PositionProfile} of each unmodeled attachment of the named cause whose profile is informative
    (χ² varies by at least :data:`FLAT_PROFILE` along the span): :func:`stcs_ident.diagnose.profile.cause_profile`,
    every other parameter of the cause refitted at each position."""
    from ..diagnose.profile import cause_profiles as profiles

    return {e: p for e, p in profiles(diagnosis).items() if np.ptp(p.chi2) >= FLAT_PROFILE}


def flat_sentence(effects) -> str:
    """Why the profile figure has no panel for ``effects`` (their profiles are flat)."""
    nouns = " and ".join(registry.get(e).noun for e in effects)
    return f"No profile of the {nouns} position: χ² varies by less than {FLAT_PROFILE:g} along the span."


def plot_profile(diagnosis, effect: str | None = None, ax=None, profile=None) -> Drawn:
    """χ² of the named cause against the position of one of its unmodeled masses or supports.

    The position is held at each point of a grid over the span and every
    other parameter of the cause is refitted
    (:func:`stcs_ident.diagnose.profile.cause_profile`); the cause's
    estimate is a point of the curve (its χ², by construction), marked with
    its standard uncertainty. On a configuration symmetric about midspan the
    curve is symmetric and the mirror of the estimate is marked too.

    Parameters
    ----------
    diagnosis : Diagnosis
    effect : str, optional
        An unmodeled effect (mass or support) of the cause. Default: the first one.
    ax : matplotlib Axes, optional
    profile : PositionProfile, optional
        The profile of ``effect`` when already computed.

    Returns
    -------
    dict with the figure, the axes, the profile line, the estimate's marks (``estimate``: the star at the
    estimate, on the curve) and the profile drawn (``scan``).

    Raises
    ------
    ValueError
        When the cause has no such effect or its profile is flat.
    """
    d = diagnosis
    if profile is None:
        scans = cause_profiles(d)
        effect = effect if effect is not None else next(iter(scans), None)
        if effect not in scans:
            raise ValueError(f"no informative profile of {effect!r} in the named cause {d.selection.effects}")
        profile = scans[effect]
    effect = profile.effect
    if ax is None:
        fig = new_figure(figsize=(9.5, 3.8), layout="constrained")
        ax = fig.subplots()
    fig = ax.figure
    line = ax.semilogy(profile.positions, profile.chi2, "o-", color="k", lw=0.9, ms=4,
                       label="χ² of the cause with this position held,\nevery other parameter refitted")[0]
    sigma = d.parameters(d.corrected)[1].get(effect, {}).get("position")
    length = d.campaign.cable.length
    marks = sorted([profile.estimate, length - profile.estimate]) if d.symmetric else [profile.estimate]
    for k, x in enumerate(marks):
        if sigma is not None and math.isfinite(sigma):
            ax.axvspan(x - sigma, x + sigma, color="tab:red", alpha=0.15, lw=0,
                       label="estimate ± 1σ" if k == 0 else None)
    estimate = ax.plot(marks, [profile.estimate_chi2] * len(marks), "*", color="tab:red", ms=12, zorder=5,
                       label=(f"named cause: {' / '.join(f'{x:.3g}' for x in marks)} m, χ² = {profile.estimate_chi2:.4g}"
                              + (" (mirror images)" if len(marks) > 1 else "")))[0]
    ax.axhline(d.nominal.chi2, color="0.5", lw=0.8, ls="--", label=f"nominal model (χ² = {d.nominal.chi2:.4g})")
    ax.set_xlim(0.0, length)
    ax.set_xlabel("position from end A (m)" + (": setup symmetric about midspan, x and l − x alike" if d.symmetric
                                               else ""))
    ax.set_ylabel("χ²")
    ax.set_title(f"{' + '.join(d.corrected.effects)}: χ² against the {registry.get(effect).noun}'s position "
                 f"({profile.positions.size} positions)", fontsize=9)
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)  # never over the data
    return Drawn({"figure": fig, "axes": ax, "profile": line, "estimate": estimate, "scan": profile})


def plot_profiles(diagnosis, fig=None, profiles: dict | None = None) -> Drawn:
    """:func:`plot_profile` of every unmodeled attachment of the cause, one above the other.

    An unmodeled attachment of the cause whose profile is flat gets no panel; the figure's title says so.
    ``profiles``: :func:`cause_profiles` when already computed.

    Returns
    -------
    dict with the figure, the :func:`plot_profile` results by effect (``panels``) and the effects left
    out (``unscanned``).
    """
    profiles = cause_profiles(diagnosis) if profiles is None else profiles
    if not profiles:
        raise ValueError("the named cause has no unmodeled attachment with an informative profile")
    fig = fig or new_figure(figsize=(9.5, 3.6 * len(profiles)), layout="constrained")
    axes = np.atleast_1d(fig.subplots(len(profiles), 1))
    panels = {e: plot_profile(diagnosis, e, ax, p) for (e, p), ax in zip(profiles.items(), axes)}
    missing = [e for e in diagnosis.selection.effects if registry.get(e).unmodeled and e not in profiles]
    if missing:
        fig.suptitle(flat_sentence(missing), fontsize=8, color="0.3")
    return Drawn({"figure": fig, "panels": panels, "unscanned": missing})


def _broken_between_planes(x: np.ndarray, y: np.ndarray, planes) -> tuple[np.ndarray, np.ndarray]:
    """``x, y`` with a gap (NaN) where the out-of-plane modes start, so no line joins the two planes."""
    if planes is None:
        return x, y
    out = np.asarray(planes) == "out"
    if not out.any() or out.all():
        return x, y
    first = int(np.argmax(out))
    return np.insert(np.asarray(x, float), first, np.nan), np.insert(np.asarray(y, float), first, np.nan)


#: How the damping figure draws the models: label, colour, marker, x offset (modes).
DAMPING_STYLE = {
    "nominal": ("nominal model", "0.35", "o", -0.15),
    "corrected": ("corrected: chosen hypothesis", "tab:red", "^", 0.15),
}


def plot_damping(table, fig=None) -> Drawn:
    """Damping ratio (%) per mode for each test: measured with ±1σ error bars, the nominal and the corrected
    model's; below, each model's ratio minus the measured one (% points) over the measured ±1σ band (the
    ratios grow with the mode, and a misfit of a few hundredths of a per cent is lost at their scale).

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`~stcs_ident.diagnose.tables.damping_table` (not empty).
    fig : matplotlib.figure.Figure, optional

    Returns
    -------
    dict with the figure, the axes (``axes``: (ratio, difference) per test), the measured error bars
    (``measured``: one per test) and the models' points (``lines``: {model: [Line2D per test]}, the ratios;
    ``corrected`` absent when it is the nominal model).
    """
    tests = list(dict.fromkeys(table["test"]))
    n = len(tests)
    ncols = 1 if n == 1 else 2
    nrows = math.ceil(n / ncols)
    fig = fig or new_figure(figsize=(5.2 * ncols, 3.6 * nrows + 0.6), layout="constrained")
    panels = np.atleast_1d(fig.subfigures(nrows, ncols, squeeze=False).ravel())
    same = np.array_equal(table["nominal_damping_ratio"].to_numpy(), table["corrected_damping_ratio"].to_numpy(),
                          equal_nan=True)
    models = ["nominal"] if same else ["nominal", "corrected"]
    lines: dict[str, list] = {key: [] for key in models}
    measured, axes = [], []
    for i, (test, panel) in enumerate(zip(tests, panels)):
        rows = table[table["test"] == test]
        modes, planes = rows["mode"].to_numpy(int), rows["plane"].to_numpy(str)
        k, _ = mode_axis(modes, planes)
        zeta, sigma = (100 * rows["measured_damping_ratio"].to_numpy(float),
                        100 * rows["damping_ratio_uncertainty"].to_numpy(float))
        ax, ax_d = panel.subplots(2, 1, sharex=True, height_ratios=(2, 1))
        measured.append(ax.errorbar(k, zeta, yerr=sigma, fmt="s", ms=5, color="tab:blue", capsize=3, lw=1.0,
                                    label="measured (±1σ)"))
        edges = np.concatenate([[k[0] - 0.4], (k[:-1] + k[1:]) / 2, [k[-1] + 0.4]])
        ax_d.stairs(np.nan_to_num(sigma), edges, baseline=-np.nan_to_num(sigma), fill=True, color="0.85", lw=0)
        ax_d.axhline(0.0, color="tab:blue", lw=0.8)
        ax_d.use_sticky_edges = False  # the band's edges must not clip the points at zero
        for key in models:
            label, colour, marker, dx = DAMPING_STYLE[key]
            model = 100 * rows[f"{key}_damping_ratio"].to_numpy(float)
            lines[key].append(ax.plot(k + dx, model, ls="none", marker=marker, color=colour, ms=5, label=label)[0])
            ax_d.plot(k + dx, model - zeta, ls="none", marker=marker, color=colour, ms=4)
        ax.set_title(f"{test} (setup {rows['setup'].iloc[0]})", fontsize=9)
        set_mode_ticks(ax_d, modes, planes)
        ax_d.set_xlim(k.min() - 0.6, k.max() + 0.6)
        for a in (ax, ax_d):
            a.grid(True, axis="y", lw=0.3, alpha=0.6)
        ax.set_ylabel("damping ratio (%)")
        ax_d.set_ylabel("model − measured (%)", fontsize=8)
        ax_d.set_xlabel("mode")
        axes.append((ax, ax_d))
    for panel in panels[n:]:
        panel.set_visible(False)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside upper center", ncols=len(labels), fontsize=8, frameon=False)
    return Drawn({"figure": fig, "axes": axes, "measured": measured, "lines": lines})
