"""Figures of the identification step (headless, Agg), after the source paper's Figs. 23-25.

- :func:`plot_surfaces`: the frequency surfaces of two modes over the grid
  of two parameter ratios, each with its contour at the measured value
  (Fig. 23);
- :func:`plot_contours`: every measured mode's contour projected on the
  parameter plane, the intersection region and the estimate, with a zoom
  on the region (Figs. 24-25); optionally the least-squares estimate and
  its 1σ ellipse beside it;
- :func:`plot_errors`: errors before and after the correction, per mode;
- :func:`save_identify_figures`: all that apply, as PNG files.

Each function builds on a :class:`matplotlib.figure.Figure` (never pyplot)
and returns a dict of what it drew so tests can inspect it.
"""

from __future__ import annotations

import os
import textwrap

import numpy as np

from ..identify.measurement import mode_label
from .plots import Drawn, mode_axis, new_figure, save_figure, set_mode_ticks


def parameter_label(p) -> str:
    """Axis label of a parameter's variable: ``H̃/H (case1-L4)``, ``ẼI/EI``, ``x̃/x (W1)``; a zero-nominal
    value in its kind's unit, ``coefficient (N s/m)``."""
    if p.is_fixity:
        text = "end fixity φ = k/(k + √(EI·H))"
    elif p.is_ratio:
        s = p.spec.symbol
        text = f"{s}\u0303/{s}" if len(s) == 1 else f"{s[0]}\u0303{s[1:]}/{s}"
    else:
        text = f"{p.kind} ({p.unit})"
    return f"{text} ({p.member})" if p.member else text


def _sweep_of(result):
    if result.sweep is None:
        raise ValueError("the result has no contour sweep: use method 'contour'")
    return result.sweep


def _mode_indices(sweep, modes, test):
    labels = sweep.labels
    test = test or labels[0].rsplit(" mode ", 1)[0]
    found = []
    for k in modes:
        label = f"{test} mode {k}"
        if label not in labels and f"{label} out-of-plane" in labels:  # an out-of-plane mode alone by that number
            label = f"{label} out-of-plane"
        if label not in labels:
            raise ValueError(f"{label!r} is not among the measured frequencies")
        found.append(labels.index(label))
    return found


def plot_surfaces(result, modes=(1, 6), test: str | None = None, fig=None) -> Drawn:
    """Frequency surfaces of two modes with their contours at the measured values (Fig. 23).

    Parameters
    ----------
    result : IdentificationResult
        Of the contour method.
    modes : two ints
        Mode numbers of ``test``.
    test : str, optional
        Default: the first test.
    fig : matplotlib.figure.Figure, optional

    Returns
    -------
    dict
        ``figure``, ``axes`` (two 3-D axes), ``surfaces`` (Poly3DCollection
        per mode), ``contours`` (the contour sets at the measured values,
        drawn on the surface, which a translucent plane at the measured
        value cuts), ``planes`` (the same contours projected on the floor).
    """
    sweep = _sweep_of(result)
    idx = _mode_indices(sweep, modes, test)
    fig = fig or new_figure(figsize=(11, 4.8), layout="constrained")
    X, Y = np.meshgrid(sweep.axes[0], sweep.axes[1], indexing="ij")
    step = max(1, X.shape[0] // 50)
    axes, surfaces, contours, floors = [], [], [], []
    for n, k in enumerate(idx):
        ax = fig.add_subplot(1, len(idx), n + 1, projection="3d")
        ax.computed_zorder = False  # draw in call order, so the contour stays on top of the surface
        Z = sweep.surfaces[..., k]
        level = float(sweep.measured[k])
        zmin = float(np.nanmin(Z))
        floors.append(ax.contour(X, Y, Z, levels=[level], colors="red", linewidths=1.0, linestyles="--",
                                 zdir="z", offset=zmin, zorder=1))
        surf = ax.plot_surface(X[::step, ::step], Y[::step, ::step], Z[::step, ::step], cmap="viridis",
                               linewidth=0, antialiased=True, alpha=0.8, rstride=1, cstride=1, zorder=2)
        ax.plot_surface(X[[0, -1]][:, [0, -1]], Y[[0, -1]][:, [0, -1]], np.full((2, 2), level), color="red",
                        alpha=0.15, zorder=3)
        contours.append(ax.contour(X, Y, Z, levels=[level], colors="red", linewidths=2.2, zorder=4))
        zmax = float(np.nanmax(Z))
        if zmax > zmin:
            ax.set_zlim(zmin, zmax)
        ax.set_xlabel(parameter_label(sweep.parameters[0]), fontsize=8)
        ax.set_ylabel(parameter_label(sweep.parameters[1]), fontsize=8)
        ax.set_zlabel("frequency (Hz)", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.set_title(f"{sweep.labels[k]}: surface cut at the measured {level:.2f} Hz", fontsize=9)
        axes.append(ax)
        surfaces.append(surf)
    return Drawn({"figure": fig, "axes": axes, "surfaces": surfaces, "contours": contours, "planes": floors})


def plot_contours(result, fig=None, lsq=None, zoom: bool = True) -> Drawn:
    """Contours of every measured mode at its measured value, their intersection region and the estimate.

    Parameters
    ----------
    result : IdentificationResult
        Of the contour method.
    fig : matplotlib.figure.Figure, optional
    lsq : IdentificationResult, optional
        A least-squares result with the same two parameters: its estimate
        and 1σ ellipse are drawn too.
    zoom : bool
        Add a second panel zoomed on the region (from the finer grid when
        one was computed).

    Returns
    -------
    dict
        ``figure``, ``axes`` (one or two), ``contours`` (per panel, one
        QuadContourSet per measured frequency; the legend lists the modes
        whose contour crosses the grid), ``region`` (per panel, the
        filled region), ``estimate`` (per panel, the marker Line2D),
        ``errorbar`` (per panel), ``lsq`` (per panel, (marker, ellipse) or
        None).
    """
    sweep = _sweep_of(result)
    fig = fig or new_figure(figsize=(12, 5.4) if zoom else (6.5, 5.4), layout="constrained")
    axes = fig.subplots(1, 2 if zoom else 1)
    axes = list(np.atleast_1d(axes))
    panels = [sweep, sweep.zoom if sweep.zoom is not None else sweep][: len(axes)]
    out = Drawn({"figure": fig, "axes": axes, "contours": [], "region": [], "estimate": [], "errorbar": [], "lsq": []})
    styles = _styles(sweep.labels)
    for n, (ax, sw) in enumerate(zip(axes, panels)):
        X, Y = np.meshgrid(sw.axes[0], sw.axes[1], indexing="ij")
        region = ax.contourf(X, Y, sw.region.astype(float), levels=[0.5, 1.5], colors=["0.8"], alpha=0.8)
        sets = []
        for k, label in enumerate(sw.labels):
            color, dash = styles[k]
            cs = ax.contour(X, Y, sw.surfaces[..., k], levels=[float(sw.measured[k])], colors=[color],
                            linewidths=1.3, linestyles=dash)
            sets.append(cs)
        nominal = ax.plot([sw.parameters[0].start], [sw.parameters[1].start], "k+", ms=10, mew=1.5,
                          label="nominal")[0]
        x, y = result.estimate
        ex, ey = result.uncertainty
        bar = ax.errorbar([x], [y], xerr=[ex], yerr=[ey], fmt="none", ecolor="k", capsize=4, lw=1.2)
        est = ax.plot([x], [y], "k*", ms=12, label=f"contour estimate ({x:.4g}, {y:.4g})")[0]
        lsq_drawn = _draw_lsq(ax, lsq) if lsq is not None else None
        drawn = [k for k in range(len(sw.labels)) if sweep.contour_lines(k)]
        handles = [_proxy(*styles[k], sw.labels[k]) for k in drawn]
        handles += [_patch("0.8", f"intersection region (every mode within {sw.level:.2f} band widths)"), est,
                    nominal]
        if lsq_drawn is not None:
            handles.append(lsq_drawn[0])
        if n == 0:
            if len(handles) <= 11:
                ax.legend(handles=handles, fontsize=7, loc="best", framealpha=0.85)
            else:
                fig.legend(handles=handles, fontsize=7, loc="outside lower center", ncols=5)
        if n == 1 and sw is not sweep:
            ax.set_xlim(sw.axes[0][0], sw.axes[0][-1])
            ax.set_ylim(sw.axes[1][0], sw.axes[1][-1])
        elif n == 1:
            _zoom_limits(ax, sw, result)
        ax.set_xlabel(parameter_label(sw.parameters[0]))
        ax.set_ylabel(parameter_label(sw.parameters[1]))
        ax.grid(True, lw=0.3, alpha=0.5)
        ax.set_title("contours at the measured frequencies" if n == 0 else "zoom on the intersection region",
                     fontsize=10)
        out["contours"].append(sets)
        out["region"].append(region)
        out["estimate"].append(est)
        out["errorbar"].append(bar)
        out["lsq"].append(lsq_drawn)
    return out


def plot_errors(result, fig=None) -> Drawn:
    """Signed errors before and after the correction, per test and mode (bars, %), with the measurement's 1σ.

    One panel per test (up to three side by side). The error is
    (computed − measured) / measured × 100, so its sign shows on which side
    each model lies; the whisker on each bar is ± one standard uncertainty
    of the measured frequency in % of it (the error can be no better known).

    Parameters
    ----------
    result : IdentificationResult
    fig : matplotlib.figure.Figure, optional

    Returns
    -------
    dict with the figure, the axes (one per test), the bars ``before`` and
    ``after`` (Rectangles, in test and mode order) and the ``errorbars``.
    """
    tests = list(result.tests)
    ncols = min(3, len(tests))
    nrows = -(-len(tests) // ncols)
    width = max(7.5, 4.2 * ncols + 0.4)  # one test's panel alone is wide enough for the legend's one row
    fig = fig or new_figure(figsize=(width, 2.6 * nrows + 0.7), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False).ravel())
    before, after, errorbars = [], [], []
    for i, (t, ax) in enumerate(zip(tests, axes)):
        x, _ = mode_axis(t.modes, getattr(t, "mode_planes", None))
        sigma = np.asarray(t.uncertainty, float) / np.asarray(t.measured, float) * 100.0
        for errors, dx, colour, bars in ((t.before_error, -0.2, "tab:gray", before),
                                         (t.after_error, 0.2, "tab:blue", after)):
            drawn = ax.bar(x + dx, errors, 0.4, color=colour)
            bars.extend(drawn.patches)
            errorbars.append(ax.errorbar(x + dx, errors, yerr=sigma, fmt="none", ecolor="k", elinewidth=0.8,
                                         capsize=2))
        ax.axhline(0.0, color="0.4", lw=0.6)
        set_mode_ticks(ax, t.modes, getattr(t, "mode_planes", None))
        ax.set_title(f"{t.name}: rms {t.rms_before:.2f} % before, {t.rms_after:.2f} % corrected", fontsize=8)
        ax.grid(True, axis="y", lw=0.3, alpha=0.6)
        if i % ncols == 0:
            ax.set_ylabel("error (%)")
        if i >= len(tests) - ncols:
            ax.set_xlabel("mode")
    for ax in axes[len(tests):]:
        ax.set_visible(False)
    handles = [_patch("tab:gray", ""), _patch("tab:blue", ""), errorbars[0]]
    labels = [f"before (rms {result.rms_before:.2f} %)", f"corrected (rms {result.rms_after:.2f} %)",
              "± 1σ of the measured frequency"]
    fig.legend(handles, labels, loc="outside lower center", ncols=3, fontsize=8, frameon=False)
    fig.suptitle(textwrap.fill(f"{result.method}: {', '.join(result.names)} fitted; error = (computed − measured) "
                               f"/ measured", int(12 * width)), fontsize=9)
    return Drawn({"figure": fig, "axes": list(axes[:len(tests)]), "before": before, "after": after,
            "errorbars": errorbars})


def save_identify_figures(result, directory, lsq=None) -> list[str]:
    """Write the figures that apply to ``result`` into ``directory`` (created); return the paths.

    ``errors.png`` always; for the contour method also ``surfaces.png``
    (the first and last measured mode of the first test) and
    ``contours.png``.
    """
    os.makedirs(directory, exist_ok=True)
    paths = []

    def save(fig, name):
        path = os.path.join(directory, name)
        save_figure(fig, path)
        paths.append(path)

    if result.sweep is not None:
        first = _most_sensitive_test(result)
        modes = (first.modes[0], first.modes[-1]) if len(first.modes) > 1 else (first.modes[0],)
        save(plot_surfaces(result, modes, first.name)["figure"], "surfaces.png")
        save(plot_contours(result, lsq=lsq)["figure"], "contours.png")
    save(plot_errors(result)["figure"], "errors.png")
    return paths


def _most_sensitive_test(result):
    """The test whose frequency surfaces vary most over the grid (relative)."""
    sweep = result.sweep
    best, spread = result.tests[0], -1.0
    for t in result.tests:
        idx = [sweep.labels.index(f"{t.name} {mode_label(k, p)}") for k, p in zip(t.modes, t.mode_planes)]
        Z = sweep.surfaces[..., idx]
        s = float(np.nanmax((np.nanmax(Z, axis=(0, 1)) - np.nanmin(Z, axis=(0, 1))) / t.measured))
        if s > spread:
            best, spread = t, s
    return best


def _styles(labels):
    """(colour, line style) per ``"<test> mode <k>"`` label: one colour per label for one test,
    else one colour per mode number and one line style per test."""
    from matplotlib import colormaps

    cmap = colormaps["tab10"]
    tests = list(dict.fromkeys(label.rsplit(" mode ", 1)[0] for label in labels))
    if len(tests) == 1:
        return [(cmap(i % cmap.N), "solid") for i in range(len(labels))]
    dashes = ["solid", "dashed", "dotted", "dashdot"]
    out = []
    for label in labels:
        test, mode = label.rsplit(" mode ", 1)
        out.append((cmap((int(mode) - 1) % cmap.N), dashes[tests.index(test) % len(dashes)]))
    return out


def _proxy(color, dash, label):
    from matplotlib.lines import Line2D

    return Line2D([], [], color=color, lw=1.3, ls=dash, label=label)


def _patch(color, label):
    from matplotlib.patches import Patch

    return Patch(color=color, label=label)


def _draw_lsq(ax, lsq):
    """The least-squares estimate and its 1σ ellipse (None if it has no covariance)."""
    from matplotlib.patches import Ellipse

    x, y = lsq.estimate[:2]
    marker = ax.plot([x], [y], "o", color="tab:red", mfc="none", ms=8,
                     label=f"lsq estimate ± 1σ ({x:.4g} ± {lsq.uncertainty[0]:.2g}, "
                           f"{y:.4g} ± {lsq.uncertainty[1]:.2g})")[0]
    cov = lsq.covariance
    if cov is None or not np.all(np.isfinite(cov[:2, :2])):
        return marker, None
    vals, vecs = np.linalg.eigh(cov[:2, :2])
    angle = float(np.degrees(np.arctan2(vecs[1, 1], vecs[0, 1])))
    ell = Ellipse((x, y), 2 * np.sqrt(max(vals[1], 0)), 2 * np.sqrt(max(vals[0], 0)), angle=angle,
                  fill=False, color="tab:red", lw=1.0, ls="--")
    ax.add_patch(ell)
    return marker, ell


def _zoom_limits(ax, sweep, result):
    ii, jj = np.nonzero(sweep.region)
    cx = sweep.axes[0][ii]
    cy = sweep.axes[1][jj]
    pad_x = max(cx.max() - cx.min(), 4 * (sweep.axes[0][1] - sweep.axes[0][0]))
    pad_y = max(cy.max() - cy.min(), 4 * (sweep.axes[1][1] - sweep.axes[1][0]))
    ax.set_xlim(cx.min() - pad_x / 2, cx.max() + pad_x / 2)
    ax.set_ylim(cy.min() - pad_y / 2, cy.max() + pad_y / 2)
