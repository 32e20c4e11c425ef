"""The ambient fit's start grid, evaluated for all its (f, ζ) at once (spectra.whittle.grid_start), must
be the candidate-by-candidate evaluation it replaced: same coefficients, same likelihoods, same start."""

from __future__ import annotations

import numpy as np
import pytest

from stcs_ident.spectra import whittle as A


def _problem(seed: int, neighbours: int):
    rng = np.random.default_rng(seed)
    n, fs = 60_000, 100.0
    dt, df = 1 / fs, fs / n
    k = np.arange(int(4.8 / df), int(5.2 / df))
    phase = 2 * np.pi * k / n
    f0, zeta = 5.0 + rng.uniform(-0.02, 0.02), rng.uniform(0.002, 0.02)
    h, _ = A.fejer_lorentzian(complex(-zeta * 2 * np.pi * f0 * dt, 2 * np.pi * f0 * dt), phase, n, derivative=False)
    columns = []
    for j in range(neighbours):  # tails of modes outside the band, some with no power (their bound is active)
        fj = 5.0 + (0.5 + j) * (1 if j % 2 else -1)
        hj, _ = A.fejer_lorentzian(complex(-0.01 * 2 * np.pi * fj * dt, 2 * np.pi * fj * dt), phase, n, derivative=False)
        columns.append(hj.real)
    fixed = np.column_stack(columns + [np.ones(k.size), np.linspace(-1, 1, k.size)])
    mean = 50 * h.real + 1.0 + (0.3 * columns[0] if columns else 0)
    periodogram = mean * rng.exponential(size=k.size)
    nonnegative = np.array([True, True] + [True] * neighbours + [True, False])
    return A.BandProblem(periodogram, phase, n, dt, fixed, nonnegative), f0


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("neighbours", [0, 2])
def test_all_starts_at_once_equal_one_by_one(seed, neighbours):
    problem, f0 = _problem(seed, neighbours)
    grid = np.array([[f, z * 2 * np.pi * f] for f in (f0, f0 + 0.01) for z in np.logspace(-4, -1, 7)])
    lin, nll = A.whittle_linear_many(A.designs(grid, problem), problem.periodogram, problem.nonnegative, 3)
    for i, theta in enumerate(grid):
        basis, _ = A.band_design(theta, problem, derivative=False)
        assert np.allclose(A.designs(theta[None], problem)[0], basis, rtol=1e-14, atol=0)
        one_lin, one_nll = A._whittle_linear(basis, problem.periodogram, problem.nonnegative, iterations=3)
        # 1e-12 and 1e-8 of the largest coefficient: the same arithmetic in another order (batched matrix
        # products, the normal matrix formed once and masked instead of rebuilt from the free columns)
        assert nll[i] == pytest.approx(one_nll, rel=1e-12)
        assert np.max(np.abs(lin[i] - one_lin)) <= 1e-8 * np.max(np.abs(one_lin))
    limits = ((f0 - 0.2, f0 + 0.2), (0.0, 0.2 * 2 * np.pi * f0))
    start = A.grid_start([f0, f0 + 0.01], problem, limits, tuple(np.logspace(-4, -1, 7)))
    best = np.argmin(nll)
    assert np.allclose(start[:2], grid[best], rtol=1e-15) and np.allclose(start[2:], lin[best], rtol=1e-12)
