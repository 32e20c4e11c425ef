"""Figures of cables with dampers: Krenk's universal curve with the exact model's points, complex mode
shapes (modulus and phase), and the tension bias of a model that ignores the damper. Headless, on
matplotlib Figures (never pyplot), as :mod:`.plots`."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from .plots import Drawn, new_figure


def krenk(eta) -> np.ndarray:
    """Krenk's asymptote of a taut string with a damper near an end: ζ / (x_d/l) = η / (1 + η²)."""
    eta = np.asarray(eta, float)
    return eta / (1.0 + eta**2)


def plot_universal_curve(series: Mapping[str, tuple[np.ndarray, np.ndarray]], fig=None) -> Drawn:
    """ζ_n/(x_d/l) against η_n = c π n x_d/(l √(H m)): Krenk's curve, and the exact model's points.

    Parameters
    ----------
    series : {label: (eta, zeta_over_xd)}
        The exact model's modes (several modes and dashpots per series).
    """
    fig = fig or new_figure(figsize=(7.5, 4.6), layout="constrained")
    ax = fig.subplots()
    eta = np.logspace(-2, 2, 400)
    line = ax.semilogx(eta, krenk(eta), color="k", lw=1.2, label="Krenk (taut string, x_d/l → 0)")[0]
    points = {}
    for (label, (x, y)), marker in zip(series.items(), "osD^v"):
        points[label] = ax.semilogx(x, y, marker, ms=4, mfc="none", label=label)[0]
    ax.axhline(0.5, color="0.6", lw=0.6, ls=":")
    ax.set_xlabel("damper parameter η_n = c π n x_d / (l √(H m))")
    ax.set_ylabel("damping ratio ζ_n / (x_d / l)")
    ax.set_title("Universal curve: the exact complex modes over Krenk's asymptote", fontsize=10)
    ax.legend(fontsize=8, loc="upper left")
    ax.set_ylim(0, 0.6)
    return Drawn({"figure": fig, "axes": ax, "curve": line, "points": points})


def plot_complex_shapes(shapes, length: float, dampers: Sequence[float], n_modes: int = 4, fig=None) -> Drawn:
    """Modulus and phase of the first ``n_modes`` complex mode shapes along the span.

    Parameters
    ----------
    shapes : stcs_ident.forward.damped_shapes.ComplexShapes
    length : float
        m.
    dampers : sequence of float
        Damper positions (m), marked.
    """
    fig = fig or new_figure(figsize=(9, 6), layout="constrained")
    ax_m, ax_p = fig.subplots(2, 1, sharex=True)
    x = np.linspace(0.0, length, 1201)
    phi = shapes(x)[:, :n_modes]
    lines = []
    for k in range(phi.shape[1]):
        label = f"mode {k + 1}: {shapes.frequency[k]:.3f} Hz, ζ = {100 * shapes.damping[k]:.2f} %"
        lines.append(ax_m.plot(x, np.abs(phi[:, k]), lw=1.0, label=label)[0])
        inside = (x > 0) & (x < length)
        phase = np.degrees(np.unwrap(np.angle(phi[inside, k]), period=math.pi))  # a sign change is not a phase
        ax_p.plot(x[inside], phase - phase[len(phase) // 2], lw=1.0)
    for xd in dampers:
        for ax in (ax_m, ax_p):
            ax.axvline(xd, color="tab:red", lw=0.8, ls="--")
    ax_m.set_ylabel("|φ(x)| (peak 1)")
    ax_m.legend(fontsize=8, loc="upper right")
    ax_m.set_title("Complex mode shapes: modulus and phase (red dashed: damper)", fontsize=10)
    ax_p.set_ylabel("phase (deg, from mid-span)")
    ax_p.set_xlabel("position from end A (m)")
    return Drawn({"figure": fig, "axes": (ax_m, ax_p), "lines": lines})


def plot_tension_bias(eta: np.ndarray, bias: Mapping[str, np.ndarray], fig=None) -> Drawn:
    """Tension bias (%) of models that ignore the damper, against mode 1's damper parameter η₁.

    Parameters
    ----------
    eta : ndarray
        η₁ of each dashpot (0 for none: drawn at the left edge).
    bias : {label: ndarray}
        Bias (%) per dashpot, one curve per cable and method.
    """
    fig = fig or new_figure(figsize=(7.5, 4.6), layout="constrained")
    ax = fig.subplots()
    shown = np.where(eta > 0, eta, np.min(eta[eta > 0]) / 3)
    lines = {label: ax.semilogx(shown, b, marker=".", lw=1.0, label=label)[0] for label, b in bias.items()}
    ax.axhline(0.0, color="k", lw=0.6)
    ax.axvline(1.0, color="0.6", lw=0.6, ls=":")
    ax.set_xlabel("damper parameter of mode 1, η₁ (leftmost point: no damper)")
    ax.set_ylabel("tension error when the damper is ignored (%)")
    ax.set_title("Tension identified from modes 1–10 with a model without the damper", fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    return Drawn({"figure": fig, "axes": ax, "lines": lines})
