"""Figures (headless, Agg). Each function builds on a matplotlib Figure or a
given Axes, never on pyplot's global state, and returns what it drew so
that tests can inspect it. matplotlib is imported only here."""

from __future__ import annotations

import numpy as np

from ..core.files import write_figure
from ..core.planes import PLANE_NAMES


class Drawn(dict):
    """What a plotting function drew: its ``"figure"`` and the artists by name (``"axes"``, ``"lines"``...).

    A dict, so that tests and callers reach each artist by name, that also behaves as its figure where a
    user meets it: ``drawn.figure``, ``drawn.savefig(path)``, and in a notebook it shows as the picture
    (``_repr_png_``), not as a dict of artists.
    """

    @property
    def figure(self):
        """The :class:`matplotlib.figure.Figure` drawn on."""
        return self["figure"]

    def savefig(self, *args, **kwargs):
        """:meth:`matplotlib.figure.Figure.savefig` of the figure."""
        return self["figure"].savefig(*args, **kwargs)

    def _repr_png_(self) -> bytes:
        import io

        buffer = io.BytesIO()
        self["figure"].savefig(buffer, format="png")
        return buffer.getvalue()


def new_figure(**kwargs):
    """A :class:`matplotlib.figure.Figure` (``kwargs`` as its constructor's), never pyplot's: the one
    place the figure modules get a figure from, so matplotlib is imported only when one is drawn."""
    from matplotlib.figure import Figure

    return Figure(**kwargs)


def plot_test_spectra(spectra, fig=None) -> Drawn:
    """Combined and per-channel spectra of one test, picked peaks labelled by mode, the nominal model marked.

    The upper panel is the combined spectrum: each channel's PSD divided by
    its noise floor, averaged over the channels (1 where there is only
    noise), on which peaks are picked. A blue triangle at its top marks each
    frequency of the nominal model the peaks were numbered against, so that
    how far the cable is from its model shows at a glance. A record picked
    per plane (channel directions) gets the pair of panels per plane, each
    with its own channels, modes, unnumbered peaks and nominal model.

    Parameters
    ----------
    spectra : stcs_ident.spectra.pipeline.TestSpectra
    fig : matplotlib.figure.Figure, optional

    Returns
    -------
    dict with the figure, the axes (combined and channels of the first plane, then of the next), the first
    plane's spectrum lines, the peak labels (``labels``: list of matplotlib Text, one per picked peak, every
    plane's), the first plane's nominal model's markers (``nominal``: Line2D, or None without them) and the
    planes drawn (``planes``: None for a record without directions).
    """
    planes = list(getattr(spectra, "plane_peaks", ()) or ())
    if len(planes) < 2:
        planes = [(None, spectra.peaks)]
    fig = fig or new_figure(figsize=(10, 6.5 if len(planes) == 1 else 11.0), layout="constrained")
    axes = fig.subplots(2 * len(planes), 1, sharex=True, height_ratios=[3, 2] * len(planes))
    mode_planes = getattr(spectra, "mode_planes", None) or ("in",) * len(spectra.modes)
    unassigned_planes = getattr(spectra, "unassigned_planes", None) or ("in",) * len(spectra.unassigned)
    nominal_by_plane = dict(getattr(spectra, "plane_nominal", ()) or ())
    drawn = {"labels": [], "planes": None if planes[0][0] is None else [p for p, _ in planes]}
    for n, (plane, result) in enumerate(planes):
        ax_c, ax_ch = axes[2 * n], axes[2 * n + 1]
        mine = [i for i, q in enumerate(mode_planes) if plane is None or q == plane]
        nominal_f = nominal_by_plane.get(plane, getattr(spectra, "nominal_frequencies", None) if n == 0 else None)
        combined, channel_lines, nominal = _spectra_pair(ax_c, ax_ch, spectra, result, mine, drawn["labels"],
                                                          [f for (f, _), q in zip(spectra.unassigned, unassigned_planes)
                                                           if plane is None or q == plane], nominal_f)
        what = "" if plane is None else f"{PLANE_NAMES[plane]}: "
        ax_c.set_title(f"{spectra.name}: {what}{len(mine)} modes picked ({result.kind}); "
                       "red = mode number, orange ? = doubtful, dotted = unassigned"
                       + ("; green dashed = structural" if getattr(spectra, "structural", ()) else "")
                       + ("; blue ▼ = nominal model" if nominal is not None else ""), fontsize=9)
        if n == 0:
            drawn.update(combined=combined, channels=channel_lines, nominal=nominal)
    axes[-1].set_xlabel("frequency (Hz)")
    return Drawn({"figure": fig, "axes": tuple(axes), **drawn})


def _spectra_pair(ax_c, ax_ch, spectra, result, mine, labels, unassigned, nominal_f):
    """One plane's combined spectrum (its modes labelled) over its channels' PSDs: (combined line, channel lines,
    nominal markers or None)."""
    f = result.frequency_axis
    combined = ax_c.semilogy(f, result.combined_spectrum, color="k", lw=0.8, label="combined spectrum")[0]
    names = list(result.channel_names) if hasattr(result, "channel_names") else None
    channel_lines = [ax_ch.semilogy(f, result.channel_spectra[:, i], lw=0.7,
                                    label=names[i] if names else f"channel {i + 1}")[0]
                     for i in range(result.channel_spectra.shape[1])]
    freqs = np.asarray(spectra.frequencies, float)[mine]
    top = np.interp(freqs, f, result.combined_spectrum) if len(f) else []
    for i, fk, yk in zip(mine, freqs, top):
        doubt = spectra.doubtful[i]
        ax_c.axvline(fk, color="tab:red", lw=0.5, alpha=0.5)
        labels.append(ax_c.annotate(f"{spectra.modes[i]}?" if doubt else f"{spectra.modes[i]}", (fk, yk),
                                    xytext=(0, 6), textcoords="offset points", ha="center", fontsize=8,
                                    color="tab:orange" if doubt else "tab:red"))
    for fu in unassigned:
        ax_c.axvline(fu, color="0.6", lw=0.5, ls=":")
    for fs, _, _ in getattr(spectra, "structural", ()) or ():  # the deck's or a pylon's: never numbered
        ax_c.axvline(fs, color="tab:green", lw=0.8, ls="--")
    if len(top):
        low, high = ax_c.get_ylim()
        ax_c.set_ylim(low, max(high, 3.0 * float(np.max(top))))  # headroom for the labels on a log axis
    nominal = _nominal_markers(ax_c, nominal_f, f)
    ax_c.set_ylabel("combined spectrum\n(PSD / noise floor, channel mean)")
    ax_ch.set_ylabel("channel PSD (m/s²)²/Hz")
    ax_ch.legend(fontsize=7, ncols=4, loc="upper right")
    return combined, channel_lines, nominal


def _nominal_markers(ax, nominal, f):
    """Triangles at the top of ``ax`` at the nominal model's frequencies inside the plotted band (or None)."""
    if nominal is None or not len(f):
        return None
    shown = np.asarray(nominal, float)
    shown = shown[(shown >= f[0]) & (shown <= f[-1])]
    if not shown.size:
        return None
    return ax.plot(shown, np.full(shown.size, 0.97), "v", color="tab:blue", ms=6,
                   transform=ax.get_xaxis_transform(), label="nominal model's frequencies")[0]


def mode_axis(modes, planes=None) -> tuple[np.ndarray, list[str]]:
    """Where a figure puts each mode along its x axis, and the tick labels: an in-plane mode at its number,
    the out-of-plane ones after a gap past the highest in-plane mode (labelled ``3 out``), as measurements
    list them (in-plane first)."""
    k = np.asarray(modes, float)
    out = np.zeros(k.size, bool) if planes is None else np.asarray(planes) == "out"
    shift = (k[~out].max() + 1.0) if (~out).any() and out.any() else 0.0
    x = np.where(out, k + shift, k)
    labels = [f"{int(m)} out" if o else f"{int(m)}" for m, o in zip(k, out)]
    return x, labels


def set_mode_ticks(ax, modes, planes=None) -> np.ndarray:
    """The x ticks of a figure by mode (:func:`mode_axis`): numbers only, and where both planes are shown a
    dashed line between them with "in-plane" and "out-of-plane" over each group (a label "3 out" per tick
    overlaps its neighbours from about ten modes a plane). Returns the x positions."""
    x, _ = mode_axis(modes, planes)
    ax.set_xticks(x, [str(int(m)) for m in np.asarray(modes)])
    out = np.zeros(x.size, bool) if planes is None else np.asarray(planes) == "out"
    if out.any() and (~out).any():
        split = (x[~out].max() + x[out].min()) / 2
        ax.axvline(split, color="0.6", lw=0.6, ls="--")
        where = ax.get_xaxis_transform()  # x in data, y in axes fractions
        for group, text in ((~out, "in-plane"), (out, "out-of-plane")):
            ax.text(x[group].mean(), 0.98, text, transform=where, ha="center", va="top", fontsize=7, color="0.35")
    return x


def save_figure(fig, path) -> None:
    """Save a PNG whole or not at all, with the permissions of any other output
    (:func:`stcs_ident.core.files.write_figure`)."""
    write_figure(fig, path)
