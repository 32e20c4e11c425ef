"""The tension formulas of the quick answer (:mod:`.quick`), each inverted for the tension (N); arrays broadcast.

The taut string and the tensioned beam the exact solver is checked against (:mod:`stcs_ident.forward.reference`):
pinned ends exactly, clamped ends by the large-ξ expansion.
"""

from __future__ import annotations

import math

import numpy as np

from .quick_exact import bracketed_root

__all__ = ["clamped_beam_frequency", "clamped_beam_tension", "pinned_beam_tension", "taut_string_tension"]


def taut_string_tension(length, mass_per_length, frequencies, modes):
    """Taut string: T = 4 m l² f_n² / n² (inverse of f_n = (n / 2l) √(T/m))."""
    f, n = np.asarray(frequencies, float), np.asarray(modes, float)
    return 4.0 * mass_per_length * length**2 * f**2 / n**2


def pinned_beam_tension(length, mass_per_length, frequencies, modes, EI):
    """Pinned–pinned tensioned beam, exact: T = 4 m l² f_n² / n² − n² π² EI / l²
    (inverse of f_n = f_n^string √(1 + n²π² EI/(T l²)), :func:`stcs_ident.forward.reference.beam_pinned`)."""
    n = np.asarray(modes, float)
    return taut_string_tension(length, mass_per_length, frequencies, modes) - n**2 * math.pi**2 * EI / length**2


def clamped_beam_frequency(length, mass_per_length, tension, EI, mode):
    """Clamped tensioned beam for large ξ = l √(T/EI): f_n ≈ (n / 2l) √(T/m) (1 + 2/ξ + (4 + n²π²/2)/ξ²)
    (:func:`stcs_ident.forward.reference.beam_clamped_asymptotic`, one mode, scalar)."""
    xi = length * math.sqrt(tension / EI)
    return mode / (2 * length) * math.sqrt(tension / mass_per_length) * (
        1 + 2 / xi + (4 + mode * mode * math.pi**2 / 2) / xi**2)


def clamped_beam_tension(length, mass_per_length, frequency_hz, mode, EI):
    """Tension of a clamped tensioned beam from one frequency, by inverting :func:`clamped_beam_frequency`.

    The expansion grows with T only where ξ² > 4 + n²π²/2; the root is sought there. Returns NaN when
    the frequency is below that branch (a beam too stiff for the expansion).
    """
    c = 4 + mode * mode * math.pi**2 / 2
    lo = c * EI / length**2 * (1 + 1e-12)

    def g(t):
        return clamped_beam_frequency(length, mass_per_length, t, EI, mode) - frequency_hz

    g_lo = g(lo)
    if g_lo >= 0:
        return math.nan
    hi = max(2 * lo, float(taut_string_tension(length, mass_per_length, frequency_hz, mode)))
    while g(hi) < 0:
        hi *= 2
    return bracketed_root(g, lo, hi, g_lo, g(hi), rtol=1e-14)
