"""One pole or two in a band: the likelihood-ratio test of a second resonance under a fitted mode.

A structural resonance (a deck's or a pylon's mode moving the anchorage) a few per mil from a cable mode, or a
turned sensor's leak of the other plane's mode, is rarely a peak of its own: one pole is fitted where two are,
its frequency between theirs, and its 1σ knows nothing of the other. The band's periodogram (the one
:func:`.ambient_fit.fit_ambient` fitted, the same mode-filtered bins and background) is fitted again with two
poles, each with its own (f, σ) and powers ≥ 0, by the same Fisher scoring, the second started from a scan of
the band (every few bins × a few damping ratios, the first pole held at its fit) and both then freed together.

The statistic is 2 (ℓ₁ − ℓ₂), the fall of the Whittle -log-likelihood with the second pole. Under one pole its
distribution is not χ² (the second pole's frequency is not identified where its power is zero: a maximum over
the band's positions), and it grows slowly with the record's length (the median over single-mode bands of 30,
60, 120, 600 and 3600 s: 5.7, 6.4, 7.2, 8.3, 8.7): its threshold :data:`THRESHOLD` was set above all of 2985
such bands of 30-600 s (benchmarks/two_poles.py null: 99.9th percentile 26.3, largest 28.4, at 600 s; 300 of
3600 s: largest 23.8); tests/test_two_poles.py measures the false alarms on seeds it was not set on. Where the
two poles are closer than the record resolves (:data:`RESOLVED_CELLS` resolution cells, 1/T) they are not told
apart: the test says one pole.

The test is made only where the one-pole fit misfits its band (:data:`MISFIT_GATE`): its cost is 3 % of the
picking of the 16-channel, 10-minute record of benchmarks/spectra.py --throughput (33 ms of 1.0 s, measured with
the test on and off in turns) and 13 % of a bridge record's analysis where deck modes merge with cable modes (32
tests in 12 records, about 40 ms each); it misses a weak second mode that does not move the misfit (two modes 8
half-power half-widths apart, the second at half the amplitude, 120 s: 77 of 100 found).

Each pole's covariance is the inverse Fisher information with every other parameter (the other pole's
included) marginalised, widened to the sandwich where larger, as the one-pole fit's. Only the second pole's is
used (:func:`second_resonance`, its 1σ at least its half-power half-width): where a deck's mode drives the cable
through its anchorage, the cable's peak is the product of the two resonances, which a sum of two poles of
powers ≥ 0 describes only roughly, and the cable's pole of the two-pole fit was off its truth by up to 11 of its
own σ on simulated bridge records, where the one-pole fit with its misfit widening stayed within 1.3σ
(benchmarks/README.md): the numbered mode keeps its one-pole fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .ambient_fit import AmbientFit, fisher_scoring, robust_covariance
from .decay_fit import pole_statistics
from .whittle import BandProblem, designs, fejer_lorentzian, linear_grid, neg_log_likelihood

__all__ = ["MISFIT_GATE", "RESOLVED_CELLS", "THRESHOLD", "TwoPoles", "second_resonance", "two_poles"]

#: 2 (ℓ₁ − ℓ₂) from which a band holds two poles (set on simulated single-mode bands: module docstring).
THRESHOLD = 30.0
#: Two poles closer than this many resolution cells (1/T) are one as far as the record can tell.
RESOLVED_CELLS = 1.0
#: The test is made on the bands whose one-pole fit misfits (:attr:`.ambient_fit.AmbientFit.misfit`, its sandwich 1σ
#: over its Fisher 1σ) by this factor or more: a band one pole describes is left alone (the test costs a few
#: one-pole fits' time).
MISFIT_GATE = 1.15
SCAN_BINS = 30  # frequencies of the second pole's scan across the band (every bin of a narrower band)
SCAN_DAMPING = (0.001, 0.004, 0.015, 0.05)  # and its damping ratios


@dataclass(frozen=True)
class TwoPoles:
    """Result of :func:`two_poles`: both poles as (f_d Hz, σ 1/s) with their (f_d, σ) covariances (every other
    parameter marginalised), each pole's power α (of the filtered periodogram), the statistic 2 (ℓ₁ − ℓ₂) and
    whether the scoring converged. ``poles[0]`` is the one nearer the one-pole fit."""

    poles: tuple[tuple[float, float], tuple[float, float]]
    covariances: tuple[np.ndarray, np.ndarray]
    powers: tuple[float, float]
    statistic: float
    converged: bool

    @property
    def two(self) -> bool:
        """Whether the band holds two poles: the statistic at :data:`THRESHOLD` or more, both poles with a power
        and a finite covariance, and resolved (:data:`RESOLVED_CELLS`)."""
        return bool(self.statistic >= THRESHOLD and self.converged and min(self.powers) > 0
                    and all(np.all(np.isfinite(c)) and c[0, 0] > 0 for c in self.covariances))


def _expected(theta: np.ndarray, problem: BandProblem):
    """Expected periodogram and its gradient in θ = (f₁, σ₁, f₂, σ₂, p₁, q₁, p₂, q₂, background...)."""
    dt, m = problem.dt, problem.phase.size
    basis = np.empty((m, 4 + problem.fixed.shape[1]))
    grad = np.empty((m, theta.size))
    for j in range(2):
        f, s = theta[2 * j], theta[2 * j + 1]
        h, dh = fejer_lorentzian(complex(-s * dt, 2 * np.pi * f * dt), problem.phase, problem.n_samples)
        basis[:, 2 * j] = h.real + h.imag
        basis[:, 2 * j + 1] = h.real - h.imag
        p, q = theta[4 + 2 * j], theta[5 + 2 * j]
        for i, d in enumerate((2j * np.pi * dt, -dt)):
            dd = dh * d
            grad[:, 2 * j + i] = p * (dd.real + dd.imag) + q * (dd.real - dd.imag)
    basis[:, 4:] = problem.fixed
    grad[:, 4:] = basis
    return basis @ theta[4:], grad


def two_poles(problem: BandProblem, theta: np.ndarray, limits, max_iterations: int = 60) -> TwoPoles | None:
    """One pole or two in the band of a one-pole fit (module docstring).

    Parameters
    ----------
    problem : BandProblem
        The one-pole fit's band (periodogram, bins, fixed columns: neighbours and background).
    theta : ndarray
        Its fit: (f_d, σ, p, q, fixed coefficients...).
    limits : ((f_lo, f_hi), (σ_lo, σ_hi))
        Its limits; both poles stay inside them.

    Returns
    -------
    TwoPoles or None
        None where the band is too narrow to scan or no second pole could be started.
    """
    periodogram = problem.periodogram
    cells = problem.n_samples * problem.dt
    one = neg_log_likelihood(_one_mean(theta, problem), periodogram)
    # The second pole's start: a scan with the first held at its fit (its two columns beside the fixed ones).
    basis_one = designs(theta[None, :2], problem)[0, :, :2]
    held = BandProblem(periodogram, problem.phase, problem.n_samples, problem.dt,
                       np.column_stack([basis_one, problem.fixed]),
                       np.concatenate([[True, True], problem.nonnegative]))
    freq = problem.phase / (2 * np.pi * problem.dt)
    inside = freq[(freq > limits[0][0]) & (freq < limits[0][1])]
    if inside.size < 4:
        return None
    scan = inside[np.unique(np.linspace(0, inside.size - 1, min(SCAN_BINS, inside.size)).round().astype(int))]
    scan = scan[np.abs(scan - theta[0]) >= RESOLVED_CELLS / cells]
    grid = np.array([(f, z * 2 * np.pi * f) for f in scan for z in SCAN_DAMPING
                     if limits[1][0] < z * 2 * np.pi * f < limits[1][1]])
    if grid.size == 0:
        return None
    lin, nll = linear_grid(grid, held, iterations=3)
    best = int(np.argmin(np.where(np.isfinite(nll), nll, np.inf)))
    if not np.isfinite(nll[best]):
        return None
    start = np.concatenate([theta[:2], grid[best], lin[best][2:4], lin[best][:2], lin[best][4:]])
    pair = BandProblem(periodogram, problem.phase, problem.n_samples, problem.dt, problem.fixed,
                       np.concatenate([[True, True], problem.nonnegative]))
    fitted, ok, mean, grad = fisher_scoring(start, pair, (*limits, *limits), max_iterations, expected=_expected)
    two = neg_log_likelihood(mean, periodogram)
    if not np.isfinite(two):
        return None
    if abs(fitted[2] - theta[0]) < abs(fitted[0] - theta[0]):  # the pole nearer the one-pole fit first
        order = [2, 3, 0, 1, 6, 7, 4, 5]
        fitted = np.concatenate([fitted[order], fitted[8:]])
        grad = np.column_stack([grad[:, order], grad[:, 8:]])
    free = np.concatenate([np.ones(4, bool), ~(pair.nonnegative & (fitted[4:] <= 0))])
    try:
        covariances = [robust_covariance(grad[:, free], mean, periodogram, keep=(2 * j, 2 * j + 1))[0]
                       for j in range(2)]
    except np.linalg.LinAlgError:
        covariances = [np.full((2, 2), np.nan)] * 2
    resolved = abs(fitted[2] - fitted[0]) >= RESOLVED_CELLS / cells
    powers = (float(fitted[4] + fitted[5]), float(fitted[6] + fitted[7]))
    statistic = max(2.0 * (one - two), 0.0) if resolved else 0.0
    return TwoPoles(((float(fitted[0]), float(fitted[1])), (float(fitted[2]), float(fitted[3]))),
                    tuple(covariances), powers, float(statistic), bool(ok))


def _one_mean(theta: np.ndarray, problem: BandProblem) -> np.ndarray:
    return designs(theta[None, :2], problem)[0] @ theta[2:]


def second_resonance(fit: AmbientFit) -> tuple[float, float, float] | None:
    """The second resonance in the band of a one-pole fit made with ``spread=False`` (its band kept), where the
    fit misfits its band (:data:`MISFIT_GATE`) and :func:`two_poles` says two: (undamped frequency Hz, 1σ Hz,
    statistic), the pole farther from the one-pole fit's frequency. Its 1σ is at least its half-power
    half-width ζ f: a resonance seen only as the second pole beside a mode is located to no better than its
    width (a deck's mode moving a cable's anchorage shapes the cable's peak as a product of the two
    resonances, which a sum of two poles describes only roughly). None otherwise."""
    if fit.band is None or not fit.misfit >= MISFIT_GATE:
        return None
    problem, theta, limits, _ = fit.band
    result = two_poles(problem, theta, limits)
    if result is None or not result.two:
        return None
    (f_d, sigma), cov = result.poles[1], result.covariances[1]
    f_n, f_std, zeta, _ = pole_statistics(f_d, sigma, cov)
    return f_n, max(f_std, zeta * f_n), result.statistic
