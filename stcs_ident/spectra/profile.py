"""How far the Whittle likelihood of one band lets a mode's frequency and decay rate go: the spreads of its
profile likelihood.

The 1σ of :mod:`.ambient_fit` is the curvature of the likelihood at its
maximum (the inverse Fisher information, widened to the sandwich). On a
short record that is not the whole story: a randomly excited mode's
periodogram is a few dozen exponential bins, and the likelihood can have a
second maximum (a cluster of noise bins a few half-power widths off the
pole, or a neighbour's skirt, which another damping ratio fits as well):
the fit then lies off the truth by more curvature σ than a Gaussian allows.
The likelihood is computed on a grid of frequencies × decay rates around
the maximum (the linear terms fitted at each), each parameter's profile
taken (the other profiled out) and weighted as exp(−Δ nll) (the posterior
under a flat prior); the root-mean-square distance of that weight from the
fitted value is the 1σ where it exceeds the curvature's:

- for the frequency, only where its profile is irregular: the rms is
  :data:`IRREGULAR` curvature σ or more, or the profile has a second
  maximum within Δ nll 4.5 and beyond two curvature σ. On a single, regular
  maximum the rms is wider than the estimator's scatter, most on peaks a
  few bins wide (measured, 150 records of one mode, 1.7 / 3.4 / 6.7 /
  12.6 bins wide: within 1σ 71 / 75 / 69 / 74 % with the curvature,
  87 / 83 / 76 / 75 % with the rms everywhere); and the bridge records of
  the planes' coverage sets went from 72 to 76-80 % within 1σ with it;
- for the decay rate, always on a peak fewer than
  :data:`DECAY_GAUSSIAN_BINS` wide: its likelihood is skewed (a lightly
  damped mode on a short record may be far more damped than its peak
  shows).

The scanned range starts at 8 curvature σ (or 6 half-power widths) and
decay rates a quarter to 4 times the fitted one, and grows where the
profile has not risen by :data:`EDGE` at its edge: a lightly damped fit to
a cluster of noise bins on a broad, weak mode's top has a likelihood that
reaches the broad mode, far beyond the narrow fit's σ (a 60-s stay's mode
14 bins wide fitted 2 bins wide, −4.7σ off with the fixed range, −2.3σ
with the grown one: tests/test_short_record_fits.py).

Measured (benchmarks/short_records.py --cases 6 --seed 36000, the stays,
30-120 s, ζ 0.2-2 %): frequencies of mode 5 and up within 1σ / 3σ 61 / 94 %
with the curvature alone, 66 / 97 % with the spread where irregular
(69 / 98 % with the rms everywhere, at the cost above; 63 / 96 % at second
maxima only); numbered modes off by more than max(3σ, 0.5 %) 28 -> 16;
damping ratios 58 / 91 % -> 65 / 95 % (seed 52000).
"""

from __future__ import annotations

import numpy as np

from .whittle import BandProblem, band_design, linear_grid

__all__ = ["spreads"]

# The profile over the decay rate: its grid, as factors of the fitted one (log-spaced, the fitted one among them).
DECAY_FACTORS = np.exp(np.linspace(np.log(0.25), np.log(4.0), 11))
GRID_POINTS = 25  # frequencies of the coarse grid across the scanned range
FINE_POINTS = 9  # and of the fine one, ±4 curvature σ around the maximum
LINEAR_ITERATIONS = 6  # Fisher-scoring steps of the linear terms per (f, σ): a profile to within ~0.05 in nll


# A peak this many bins wide (2σ/2π over the resolution 1/T) or wider is described by enough bins that its
# likelihood is Gaussian in frequency: the curvature's 1σ is the spread (measured: 600-s records of a mode
# of 14.9 Hz at ζ 1.5 %, about 270 bins, rms z 0.84 with the curvature alone; 60 s, 27 bins, 2.0) -- unless a
# probe at ±PROBE_SIGMAS curvature σ finds the profile risen by less than PROBE_RISE on a side (a Gaussian's
# rises by 2), probed on peaks less than PROBE_CONTRAST times their background high: a weak broad mode's
# likelihood can be flat across its top (a 60-s hanger's mode 20, 170 bins
# wide, 5 dB above the floor: the profile rose by 1.2 at 3 curvature σ), and is then profiled as a narrower one.
GAUSSIAN_BINS = 50.0
PROBE_SIGMAS = 2.0
PROBE_RISE = 1.0
PROBE_CONTRAST = 10.0
# From this many bins wide the decay rate's likelihood is Gaussian enough: its spread is its curvature's σ
# (measured on benchmarks/short_records.py's cases, seeds 36000-36001, 30-600 s: the decay rate's spread over
# its curvature σ, median (90th percentile) 1.16 (1.52) at 0-3 bins, 1.05 (1.17) at 12-25, 0.94 (1.10) at
# 25-50). Its profile is then not computed, and the frequency's only where a screen of a few decay rates
# (:data:`SCREEN_DECAYS`) is irregular: those peaks cost the most (the bins scored grow with the width).
DECAY_GAUSSIAN_BINS = 25.0
SCREEN_DECAYS = 3  # the decay rates of the screen: the fitted one and its two neighbours on the grid
# The frequency's profile is irregular (not the single Gaussian-like maximum the curvature describes) where the rms
# of its weight is this many curvature σ or more: on a regular maximum the ratio is 1.04-1.3 (12 records of a
# mode 13 bins wide, tests/test_short_record_fits.py), and the rms there widens the 1σ beyond the estimator's
# scatter (the module docstring).
IRREGULAR = 1.5
# The scanned range grows (by GROWTH in frequency, DECAY_GROWTH in the decay rate's top, at most EXTENSIONS times)
# where the profile at its edge is within EDGE of its least (the weight e^-EDGE = 1 % there: not yet died out).
EDGE = 6.0
GROWTH = 3.0
DECAY_GROWTH = 4.0
EXTENSIONS = 2
MAX_ELEMENTS = 1_000_000  # of a block of design matrices (8 MB): the grid is evaluated in blocks this size


def _near(problem: BandProblem, lo: float, hi: float, margin: float) -> BandProblem:
    """The band's bins from ``lo − margin`` to ``hi + margin`` Hz, as a problem of their own."""
    freq = problem.phase / (2 * np.pi * problem.dt)
    rows = slice(int(np.searchsorted(freq, lo - margin)), int(np.searchsorted(freq, hi + margin, side="right")))
    return BandProblem(problem.periodogram[rows], problem.phase[rows], problem.n_samples, problem.dt,
                       problem.fixed[rows], problem.nonnegative)


def spreads(problem: BandProblem, theta: np.ndarray, std: float, reach: float, limits) -> tuple[float, float]:
    """Root-mean-square distances from θ[0] (the fitted damped frequency, Hz) and from θ[1] (the decay rate,
    1/s) of the profile-likelihood weight of each, the other profiled out (the frequency's only where its
    profile is irregular, else 0: the module docstring); (0, 0) for a peak wide enough to be Gaussian
    (:data:`GAUSSIAN_BINS`), and the decay rate's 0 from :data:`DECAY_GAUSSIAN_BINS` wide.

    Parameters
    ----------
    problem : BandProblem
    theta : ndarray
        The fit: (f_d, σ, linear terms...).
    std : float
        The curvature 1σ of f_d, Hz.
    reach : float
        Half-width of the scanned range, Hz (clipped to the frequency limits).
    limits : ((f_lo, f_hi), (σ_lo, σ_hi))
        The fit's limits; the profile stays inside them.
    """
    f_hat, s_hat = float(theta[0]), float(theta[1])
    bins = s_hat * problem.n_samples * problem.dt / np.pi
    lo, hi = max(limits[0][0], f_hat - reach), min(limits[0][1], f_hat + reach)
    if bins >= GAUSSIAN_BINS and (_contrast(problem, theta) >= PROBE_CONTRAST
                                  or not _flat(problem, f_hat, s_hat, std, limits)):
        return 0.0, 0.0
    wide = bins >= DECAY_GAUSSIAN_BINS
    top = DECAY_FACTORS[-1]
    for extension in range(EXTENSIONS + 1):
        points = int(np.ceil(GRID_POINTS * (hi - lo) / (2 * reach)))  # the coarse grid's spacing kept as it grows
        coarse = np.linspace(lo, hi, max(GRID_POINTS, points))
        fine = f_hat + np.linspace(-4.0, 4.0, FINE_POINTS) * std
        freqs = np.unique(np.concatenate([coarse, fine[(fine > lo) & (fine < hi)], [f_hat]]))
        step = np.log(DECAY_FACTORS[1] / DECAY_FACTORS[0])  # the log-spaced grid's step kept as it grows
        decays = s_hat * DECAY_FACTORS[0] * np.exp(step * np.arange(round(np.log(top / DECAY_FACTORS[0]) / step) + 1))
        decays = decays[(decays > limits[1][0]) & (decays < limits[1][1])]
        if freqs.size < 3 or decays.size < 3:
            return 0.0, 0.0
        # The bins that see the scanned poles: the range and ten of the fit's half-power widths beyond it (far
        # bins change the profile's differences by little and cost the most: each alternative is scored on these
        # alone).
        sub = _near(problem, lo, hi, 10.0 * s_hat / (2 * np.pi))
        if wide and extension == 0:  # the decay rate's spread is its curvature's; the frequency's profile only
            order = np.argsort(np.abs(np.log(decays / s_hat)))  # where a screen is irregular (its rates first)
            screen = _values(sub, freqs, decays[order[:SCREEN_DECAYS]])
            if not _irregular(freqs, screen.min(axis=1), f_hat, std):
                return 0.0, 0.0
            values = np.hstack([screen, _values(sub, freqs, decays[order[SCREEN_DECAYS:]])])  # columns in `order`
            decays = decays[order]
        else:
            values = _values(sub, freqs, decays)
        # Where the weight has not died out at the scanned range's edge (the profile within EDGE of its least
        # there), the range grows, up to the fit's limits: a broad mode's likelihood can reach far beyond a
        # narrow fit's curvature σ (a cluster of noise bins on its top fitted as a lightly damped mode).
        f_profile, s_profile = values.min(axis=1), values.min(axis=0)
        low = f_profile - f_profile.min() < EDGE
        grow_lo, grow_hi = low[0] and lo > limits[0][0], low[-1] and hi < limits[0][1]
        grow_decay = (not wide and s_profile[-1] - s_profile.min() < EDGE  # (ascending unless wide)
                      and decays[-1] * np.exp(step) < limits[1][1])
        if not (grow_lo or grow_hi or grow_decay):
            break
        if grow_lo:
            lo = max(limits[0][0], f_hat - GROWTH * (f_hat - lo))
        if grow_hi:
            hi = min(limits[0][1], f_hat + GROWTH * (hi - f_hat))
        if grow_decay:
            top *= DECAY_GROWTH
    f_spread = _rms(freqs, f_profile, f_hat) if _irregular(freqs, f_profile, f_hat, std) else 0.0
    return f_spread, 0.0 if wide else _rms(decays, s_profile, s_hat)


def _contrast(problem: BandProblem, theta: np.ndarray) -> float:
    """The fitted mode's expected periodogram at its highest over the rest of the model (neighbours and background)
    at that bin."""
    basis, _ = band_design(theta[:2], problem, derivative=False)
    mode = basis[:, :2] @ theta[2:4]
    k = int(np.argmax(mode))
    rest = float(basis[k, 2:] @ theta[4:])
    return float(mode[k] / rest) if rest > 0 else np.inf


def _flat(problem: BandProblem, f_hat: float, s_hat: float, std: float, limits) -> bool:
    """Whether the frequency's profile at ±:data:`PROBE_SIGMAS` curvature σ has risen by less than
    :data:`PROBE_RISE` on either side (a Gaussian's rises by 2): a likelihood flatter than its curvature says."""
    freqs = f_hat + np.array([-PROBE_SIGMAS, 0.0, PROBE_SIGMAS]) * std
    decays = s_hat * DECAY_FACTORS[DECAY_FACTORS.size // 2 - 1: DECAY_FACTORS.size // 2 + 2]
    if freqs[0] <= limits[0][0] or freqs[-1] >= limits[0][1]:
        return True
    profile = _values(_near(problem, freqs[0], freqs[-1], 10.0 * s_hat / (2 * np.pi)), freqs, decays).min(axis=1)
    return bool(min(profile[0], profile[2]) - profile[1] < PROBE_RISE)


def _values(sub: BandProblem, freqs: np.ndarray, decays: np.ndarray) -> np.ndarray:
    """The band's -log-likelihood at each (frequency, decay rate) of the grid, the linear terms fitted at each,
    (freqs, decays); inf where the model is not valid."""
    grid = np.array([(f, s) for f in freqs for s in decays])
    block = max(decays.size, (MAX_ELEMENTS // max(1, sub.periodogram.size * (2 + sub.fixed.shape[1]))) // decays.size
                * decays.size)
    values = np.concatenate([
        linear_grid(grid[i:i + block], sub, iterations=LINEAR_ITERATIONS)[1]
        for i in range(0, grid.shape[0], block)])
    return np.where(np.isfinite(values), values, np.inf).reshape(freqs.size, decays.size)


def _irregular(freqs: np.ndarray, profile: np.ndarray, f_hat: float, std: float) -> bool:
    """Whether a frequency profile is irregular: its rms is :data:`IRREGULAR` curvature σ or more, or it has a
    second maximum (:func:`_second_maximum`)."""
    return _rms(freqs, profile, f_hat) >= IRREGULAR * std or _second_maximum(freqs, profile, f_hat, 2.0 * std)


def _second_maximum(x: np.ndarray, profile: np.ndarray, centre: float, away: float) -> bool:
    """Whether the profile has a local maximum of the likelihood other than the fit's: farther than `away`
    from `centre` and within 4.5 of the least -log-likelihood (where a Gaussian's 3σ ends)."""
    delta = profile - profile.min()
    inner = (delta[1:-1] <= delta[:-2]) & (delta[1:-1] <= delta[2:])
    candidates = np.flatnonzero(inner) + 1
    return bool(np.any((delta[candidates] <= 4.5) & (np.abs(x[candidates] - centre) > away)))


def _rms(x: np.ndarray, profile: np.ndarray, centre: float) -> float:
    """Root-mean-square distance from `centre` of the weight exp(−(profile − min)) on the uneven grid `x`
    (trapezoid weights: a flat prior on x)."""
    mass = np.exp(-(profile - profile.min())) * np.gradient(x)
    total = mass.sum()
    if not total > 0:
        return 0.0
    return float(np.sqrt(np.sum(mass * (x - centre) ** 2) / total))
