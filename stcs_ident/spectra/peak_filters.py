"""What is not reported among the fitted peaks: mains hum, and a second fit of the same mode.

Used by :func:`.peaks.find_peaks` after the fits.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .options import FilterOptions

if TYPE_CHECKING:
    from .peak_result import Peak

__all__ = ["at_mains_harmonic", "deduplicate", "is_mains_hum"]

_DEFAULT = FilterOptions()


def is_mains_hum(peak: Peak, options: FilterOptions = _DEFAULT) -> bool:
    """Whether a peak is mains hum: a line at a harmonic of 50 or 60 Hz with no damping.

    Hum is a sinusoid of constant amplitude through the whole record, so
    its fit (free decay or ambient) gives ζ ≈ 0 (below
    ``options.max_hum_damping``), which no cable mode has; the frequency
    must also lie within ``options.mains_tolerance`` of h · 50 or h · 60 Hz
    (``options.mains_frequencies``). It stays in the fits as a neighbour
    of the modes beside it (they were fitted with it) and is not reported.
    """
    if peak.damping is None or peak.damping >= options.max_hum_damping:
        return False
    return at_mains_harmonic(peak.frequency, options)


def at_mains_harmonic(frequency: float, options: FilterOptions = _DEFAULT) -> bool:
    """Whether ``frequency`` lies within ``options.mains_tolerance`` of a harmonic of 50 or 60 Hz."""
    for mains in options.mains_frequencies:
        harmonic = round(frequency / mains)
        if harmonic >= 1 and abs(frequency - harmonic * mains) <= options.mains_tolerance * harmonic * mains:
            return True
    return False


def deduplicate(peaks: list[Peak], options: FilterOptions = _DEFAULT) -> list[Peak]:
    """Two detections that converged on the same mode keep the stronger one.

    The same mode means within 3σ, each σ counted at most
    ``options.deduplicate_max_std`` of its frequency: one poor fit's wide σ
    must not swallow its well-located neighbours (a cable's modes lie a
    fundamental apart, several percent below mode 30).
    """

    def reach(p: Peak) -> float:
        return min(p.uncertainty, options.deduplicate_max_std * p.frequency)

    out: list[Peak] = []
    for p in sorted(peaks, key=lambda p: p.frequency):
        if out and abs(p.frequency - out[-1].frequency) < 3.0 * max(reach(p), reach(out[-1])):
            if p.snr_db > out[-1].snr_db:
                out[-1] = p
            continue
        out.append(p)
    return out
