"""The record's mean frequency from free decays at a few instants: the events' disagreement as a variance.

The tension, and with it every frequency, wanders within a record
(temperature, traffic), and the frequency sought is the record's mean.
Blows minutes apart ring at frequencies that differ by more than their
noise, and the mean is then known only as well as the events' scatter
allows. Two estimates of that scatter, both random-effects
(DerSimonian–Laird) and both taken only where Cochran's Q shows that the
events disagree (level ``heterogeneity_level`` of
:class:`.options.FitOptions`, 0.05; without the test, chance
scatter of two or three clean events made the 1σ too large, 78–88 %
within 1σ on clean records):

- per mode (:func:`between_events_addition`): the events' frequencies of
  one mode;
- across modes (:func:`common_wander`): a tension change moves every
  mode by about the same relative amount, so each event's relative offset,
  pooled over all modes, is measured far better than by one mode; its
  scatter τ is relative and applies to every mode (τ f_k).

A single event cannot show the wander: its 1σ covers the frequency while
it rang, not the record's mean.
"""

from __future__ import annotations

import numpy as np
from scipy import stats

from .options import FitOptions

__all__ = ["between_events_addition", "common_wander", "random_effects_variance", "with_common_wander"]

def random_effects_variance(variances: np.ndarray, tau2: float) -> float:
    """Variance of the random-effects mean of estimates of variance ``variances`` scattered by τ²: 1 / Σ 1/(v_i + τ²)."""
    v = np.asarray(variances, float)
    return 1.0 / float(np.sum(1.0 / (v + tau2)))


def _dersimonian_laird(values: np.ndarray, variances: np.ndarray, level: float) -> float:
    """τ² of the values' scatter beyond their variances, 0 unless Cochran's Q rejects agreement at `level`."""
    w = 1.0 / variances
    mean = np.sum(w * values) / np.sum(w)
    q = float(np.sum(w * (values - mean) ** 2))
    if q <= stats.chi2.isf(level, values.size - 1):
        return 0.0
    return max(0.0, (q - (values.size - 1)) / float(np.sum(w) - np.sum(w**2) / np.sum(w)))


def between_events_addition(frequencies: np.ndarray, variances: np.ndarray, joint_variance: float,
                            level: float = FitOptions.heterogeneity_level) -> float:
    """What to add to a joint fit's frequency variance for its events' disagreement (0 with fewer than two).

    ``frequencies`` and ``variances`` are the events' own fits of the mode
    (NaN where one failed); the joint estimate is given the random-effects
    variance of the mean where that exceeds ``joint_variance``, if Cochran's
    Q rejects the events' agreement at ``level``.
    """
    f, v = _usable(frequencies, variances)
    if f.size < 2:
        return 0.0
    tau2 = _dersimonian_laird(f, v, level)
    return max(0.0, random_effects_variance(v, tau2) - joint_variance) if tau2 > 0 else 0.0


def common_wander(modes: list[tuple[float, np.ndarray, np.ndarray]], level: float = FitOptions.heterogeneity_level) -> float:
    """Relative τ² of the events' common frequency offset, pooled over modes (0 where the events agree).

    Parameters
    ----------
    modes : list of (frequency, event frequencies, event variances)
        Per mode, its joint estimate and its events' own fits (Hz, Hz²;
        NaN where an event's fit failed), the events in the same order
        for every mode.
    level : float
        Level of Cochran's Q test of the events' agreement.

    The offset of event i is the weighted mean over modes of
    f_ik / f_k − 1; their scatter about their weighted mean is tested
    (Cochran's Q, n_events − 1 degrees of freedom) and measured
    (DerSimonian–Laird).
    """
    rows = [(f0, *_aligned(fe, ve)) for f0, fe, ve in modes]
    rows = [r for r in rows if np.sum(np.isfinite(r[1])) >= 2]
    if len(rows) < 2:
        return 0.0
    n_events = len(rows[0][1])
    if any(len(r[1]) != n_events for r in rows):
        return 0.0
    num, den = np.zeros(n_events), np.zeros(n_events)
    for f0, fe, ve in rows:
        ok = np.isfinite(fe)
        # Centred per mode on its events' weighted mean (what the joint fit is, near enough).
        centre = np.sum(fe[ok] / ve[ok]) / np.sum(1.0 / ve[ok])
        rel = (fe - centre) / f0
        w = f0**2 / ve
        num[ok] += (w * rel)[ok]
        den[ok] += w[ok]
    seen = den > 0
    if np.sum(seen) < 2:
        return 0.0
    return _dersimonian_laird(num[seen] / den[seen], 1.0 / den[seen], level)


def with_common_wander(std: float, frequency: float, event_variances: np.ndarray, tau2: float) -> float:
    """1σ of a mode's mean frequency when the events scatter by the relative τ² of :func:`common_wander` (never smaller)."""
    v = np.asarray(event_variances, float)
    v = v[np.isfinite(v) & (v > 0)]
    if tau2 <= 0 or v.size < 2:
        return std
    return float(np.sqrt(max(std**2, random_effects_variance(v, tau2 * frequency**2))))


def _aligned(frequencies, variances) -> tuple[np.ndarray, np.ndarray]:
    f, v = np.asarray(frequencies, float), np.asarray(variances, float)
    bad = ~(np.isfinite(f) & np.isfinite(v) & (v > 0))
    return np.where(bad, np.nan, f), np.where(bad, np.nan, v)


def _usable(frequencies, variances) -> tuple[np.ndarray, np.ndarray]:
    f, v = _aligned(frequencies, variances)
    ok = np.isfinite(f)
    return f[ok], v[ok]
