"""Refinement of detected peaks: the band each is fitted in, and which detections are modes.

Each candidate is fitted (by a band fitter given by the caller: the
free-decay or the ambient likelihood) in a band of about eight
half-power widths around it, never wider than 0.45 of the distance to the
next candidate nor a quarter of its frequency; the nearest candidate on
each side enters the fit as a fixed pole. The overview's width is only a
guess, so a fit whose peak is wider than its band, or that fails, is
repeated once in a wider band; one still doubtful is tried last in a band
reaching 0.9 of the way to its neighbours (a heavily damped mode between
close neighbours: within 0.45 of the gap its skirts pass for background
and the fit settles on ripple).

A fit describes a mode when it converged, its damping ratio is below
10 % (wider shapes are the colour of the noise, not a cable mode), it
lies within two half-power widths of the detection, and it is
significant (a z-like score of at least 6 against the background alone).
Detections that are not modes are dropped one at a time, the weakest
first, and their neighbours refitted without them (a spurious neighbour
narrows a true mode's band), until every remaining one is a mode or is
too strong (10 dB above the floor, and no wider than a mode with 10 %
damping) to drop: those are reported from the overview, unless they lie
within two half-power widths of a fitted mode (ripple on its resonance).
Proposals of the coarser overviews (multi-resolution detection) are
never reported from the overview: only a fit confirms them.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .detection import Candidate
from .options import RefineOptions

__all__ = ["refine"]

# The bands' sizes and what a mode is (significance, damping, fallback) are :class:`.options.RefineOptions`.

# A band fitter: (centre Hz, half-width Hz, neighbour poles [(f, σ)], -3 dB width Hz) -> fit or None; a fit
# has .frequency, .decay_rate, .damping, .significance and .converged.
BandFitter = Callable[[float, float, list, float], object]


def _candidate_pole(c: Candidate, resolution: float) -> tuple[float, float]:
    """(frequency, decay rate) of a candidate from its -3 dB width less the resolution."""
    return c.frequency, np.pi * max(c.half_power_width - resolution, 0.25 * resolution)


def _band_limit(c: Candidate, neighbours: list[Candidate], nyquist: float, fraction: float,
                max_relative: float) -> float:
    gaps = [abs(n.frequency - c.frequency) for n in neighbours]
    return min([fraction * g for g in gaps] + [max_relative * c.frequency, nyquist - c.frequency])


def _plausible(c: Candidate, fit, cell_width: float, max_damping: float) -> bool:
    """A converged fit that describes the detected peak: a cable mode (ζ < `max_damping`) near the candidate.

    Near means within two half-power widths (the candidate's or the
    fitted one, 2σ/2π), or three resolution cells: on a randomly excited
    resonance the highest bin can lie well off the pole.
    """
    if fit is None or not fit.converged or fit.damping >= max_damping:
        return False
    width = max(c.half_power_width, fit.decay_rate / np.pi)
    return abs(fit.frequency - c.frequency) <= max(2.0 * width, 3.0 * cell_width)


def _strong(c: Candidate, cell_width: float, options: RefineOptions) -> bool:
    """A peak to report even when its fit fails: ``fallback_snr_db`` high and as narrow as a cable mode (2ζf).

    (Or no wider than four resolution cells: the overview cannot resolve a narrower peak.) A proposal of
    a coarser overview is never strong: only its fit can confirm it.
    """
    narrow = c.half_power_width <= max(2 * options.max_damping * c.frequency, 4 * cell_width)
    return c.snr_db >= options.fallback_snr_db and narrow and not c.proposal


def _fit_candidate(
    c: Candidate, neighbours: list[Candidate], fit_band: BandFitter, resolution, min_half_width, nyquist, cell_width,
    options: RefineOptions,
):
    """Fit one candidate in a band of about eight half-power widths.

    The overview's width is only a guess (ripple, resolution): when the
    fitted peak is wider than the band allows for, or the fit fails or is
    insignificant, the band is widened once (up to its limit) and the fit
    repeated. A fit still doubtful is tried last in a band reaching 0.9 of
    the way to the neighbours (kept only if it then describes a significant
    mode near the detection).
    """
    o = options
    limit = _band_limit(c, neighbours, nyquist, o.band_neighbour_fraction, o.band_max_relative)
    width = max(o.band_half_power_widths * max(c.half_power_width - resolution, resolution), min_half_width)
    half_width = min(width, limit)
    poles = [_candidate_pole(n, resolution) for n in neighbours]
    fit = fit_band(c.frequency, half_width, poles, c.half_power_width)
    if _plausible(c, fit, cell_width, o.max_damping) and fit.significance >= o.min_significance:
        wanted = min(o.band_half_power_widths * fit.decay_rate / np.pi, limit)
        start = fit.frequency
    else:
        wanted, start = limit, c.frequency
    if wanted > 1.5 * half_width:
        wider = fit_band(start, wanted, poles, c.half_power_width)
        if _plausible(c, wider, cell_width, o.max_damping):
            fit = wider
    if neighbours and not (_plausible(c, fit, cell_width, o.max_damping) and fit.significance >= o.min_significance):
        # A broad mode between close neighbours: within 0.45 of the gap its skirts look like the background
        # (constant, slope, the neighbours' tails) and the fit settles on ripple. Reaching over to the
        # neighbours' peaks pins the background down.
        widest = _band_limit(c, neighbours, nyquist, o.band_neighbour_fraction_wide, o.band_max_relative)
        if widest > 1.2 * max(half_width, wanted):
            wide = fit_band(c.frequency, widest, poles, c.half_power_width)
            if _plausible(c, wide, cell_width, o.max_damping) and wide.significance >= o.min_significance:
                fit = wide
    return fit


def refine(
    candidates: list[Candidate],
    fit_band: BandFitter,
    resolution: float,
    min_half_width: float,
    nyquist: float,
    cell_width: float,
    cache: dict | None = None,
    options: RefineOptions | None = None,
) -> list[tuple[Candidate, object]]:
    """Fit every candidate with its active neighbours, dropping non-modes one at a time (module docstring).

    Parameters
    ----------
    candidates : list of Candidate
        In frequency order.
    fit_band : BandFitter
    resolution : float
        Resolution of the overview spectrum, Hz (subtracted from its peak widths).
    min_half_width : float
        Narrowest band half-width, Hz.
    nyquist : float
        Hz.
    cell_width : float
        Width of an independent cell of the overview spectrum, Hz.
    cache : dict, optional
        Fits by candidate and neighbours, shared between calls on the same
        record (a second call with more candidates refits only the
        candidates whose neighbours changed, so it is only shared between
        calls with the same `options`).
    options : RefineOptions, optional
        Bands and what a mode is (default: the calibrated values).

    Returns
    -------
    list of (Candidate, fit or None)
        The candidates kept, in frequency order; None where the fit failed
        on a peak too strong to drop.
    """
    options = RefineOptions() if options is None else options
    active = list(range(len(candidates)))
    cache = {} if cache is None else cache
    fits: dict = {}

    def doubtful(i):
        fit = fits[i]
        if not _plausible(candidates[i], fit, cell_width, options.max_damping):
            return not _strong(candidates[i], cell_width, options)
        return fit.significance < options.min_significance

    while True:
        for pos, i in enumerate(active):
            near = tuple(active[j] for j in (pos - 1, pos + 1) if 0 <= j < len(active))
            key = (candidates[i], tuple(candidates[j] for j in near))
            if key not in cache:
                cache[key] = _fit_candidate(
                    candidates[i],
                    [candidates[j] for j in near],
                    fit_band,
                    resolution,
                    min_half_width,
                    nyquist,
                    cell_width,
                    options,
                )
            fits[i] = cache[key]
        weak = [i for i in active if doubtful(i)]
        if not weak:
            return _without_satellites([(candidates[i], fits[i]) for i in active], cell_width, options.max_damping)
        active.remove(min(weak, key=lambda i: candidates[i].snr_db))


def _without_satellites(pairs, cell_width: float, max_damping: float) -> list[tuple[Candidate, object]]:
    """Failed fits become None; a failed one within two half-power widths of a fitted mode is ripple on it: dropped."""
    modes = [fit for c, fit in pairs if _plausible(c, fit, cell_width, max_damping)]
    out = []
    for c, fit in pairs:
        if _plausible(c, fit, cell_width, max_damping):
            out.append((c, fit))
        elif all(abs(c.frequency - m.frequency) > 2 * max(c.half_power_width, m.decay_rate / np.pi) for m in modes):
            out.append((c, None))
    return out
