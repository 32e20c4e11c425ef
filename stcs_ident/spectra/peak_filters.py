"""What is not reported among the fitted peaks: mains hum, and a second fit of the same mode.

Used by :func:`.peaks.find_peaks` after the fits.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .peak_result import Peak

__all__ = ["at_mains_harmonic", "deduplicate", "is_mains_hum"]

DEDUPLICATE_MAX_STD = 0.005  # relative: a wider 1σ does not widen the window in which two peaks are one
MAINS_FREQUENCIES = (50.0, 60.0)  # Hz
MAINS_TOLERANCE = 0.002  # relative: grids keep within ±0.1 % of their nominal frequency, with margin
MAX_HUM_DAMPING = 5e-4  # a line this undamped at a mains harmonic is hum (cable modes: ζ ≥ 1e-3)


def is_mains_hum(peak: Peak) -> bool:
    """Whether a peak is mains hum: a line at a harmonic of 50 or 60 Hz with no damping.

    Hum is a sinusoid of constant amplitude through the whole record, so
    its fit (free decay or ambient) gives ζ ≈ 0 (within MAX_HUM_DAMPING),
    which no cable mode has; the frequency must also lie within
    MAINS_TOLERANCE of h · 50 or h · 60 Hz. It stays in the fits as a
    neighbour of the modes beside it (they were fitted with it) and is not
    reported.
    """
    if peak.damping is None or peak.damping >= MAX_HUM_DAMPING:
        return False
    return at_mains_harmonic(peak.frequency)


def at_mains_harmonic(frequency: float) -> bool:
    """Whether ``frequency`` lies within MAINS_TOLERANCE of a harmonic of 50 or 60 Hz."""
    for mains in MAINS_FREQUENCIES:
        harmonic = round(frequency / mains)
        if harmonic >= 1 and abs(frequency - harmonic * mains) <= MAINS_TOLERANCE * harmonic * mains:
            return True
    return False


def deduplicate(peaks: list[Peak]) -> list[Peak]:
    """Two detections that converged on the same mode keep the stronger one.

    The same mode means within 3σ, each σ counted at most
    DEDUPLICATE_MAX_STD of its frequency: one poor fit's wide σ must not
    swallow its well-located neighbours (a cable's modes lie a fundamental
    apart, several percent below mode 30).
    """

    def reach(p: Peak) -> float:
        return min(p.uncertainty, DEDUPLICATE_MAX_STD * p.frequency)

    out: list[Peak] = []
    for p in sorted(peaks, key=lambda p: p.frequency):
        if out and abs(p.frequency - out[-1].frequency) < 3.0 * max(reach(p), reach(out[-1])):
            if p.snr_db > out[-1].snr_db:
                out[-1] = p
            continue
        out.append(p)
    return out
