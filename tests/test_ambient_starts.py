"""The ambient fit's start grid, evaluated for all its (f, ζ) at once (spectra.whittle.grid_start), must
be the candidate-by-candidate evaluation it replaced: same coefficients, same likelihoods, same start; and the
compiled kernel of the linear terms (spectra/_whittle_kernel.c) the numpy reference's."""

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
        # numpy, one by one: the reference of the batched numpy path and of the compiled kernel
        one_lin, one_nll = A._whittle_linear_numpy(basis, problem.periodogram, problem.nonnegative, iterations=3)
        # 1e-12 and 1e-8 of the largest coefficient: the same arithmetic in another order (batched matrix
        # products or the kernel's loops, the normal matrix formed once and masked instead of rebuilt from the
        # free columns)
        assert nll[i] == pytest.approx(one_nll, rel=1e-12)
        assert np.max(np.abs(lin[i] - one_lin)) <= 1e-8 * np.max(np.abs(one_lin))
    limits = ((f0 - 0.2, f0 + 0.2), (0.0, 0.2 * 2 * np.pi * f0))
    start = A.grid_start([f0, f0 + 0.01], problem, limits, tuple(np.logspace(-4, -1, 7)))
    best = np.argmin(nll)
    assert np.allclose(start[:2], grid[best], rtol=1e-15) and np.allclose(start[2:], lin[best], rtol=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_the_compiled_kernel_gives_the_numpy_reference_s_fits(seed):
    """Profile-like grids (frequencies across the band × decay rates 0.25-4 times the truth's), with and without
    neighbours, 3 and 6 iterations, the null fit (no mode column: 12 iterations), and candidates the flat start
    cannot evaluate (a NaN basis, a mode column that makes the mean negative): the same coefficients and
    likelihoods, whichever path."""
    if A._whittle_kernel is None:
        pytest.skip("the compiled kernel is not built in this install (no C compiler)")
    for neighbours in (0, 2):
        problem, f0 = _problem(seed, neighbours)
        sigma = 0.01 * 2 * np.pi * f0
        grid = np.array([[f, s] for f in np.linspace(f0 - 0.1, f0 + 0.1, 15) for s in sigma * np.logspace(-0.6, 0.6, 7)])
        bases = A.designs(grid, problem)
        bases[3, 10, 0] = np.nan
        bases[5, :, 1] = -bases[5, :, 1] - 10.0  # a start the background cannot make positive everywhere
        for iterations in (3, 6):
            lin, nll = A.whittle_linear_many(bases, problem.periodogram, problem.nonnegative, iterations)
            ref_lin, ref_nll = A.whittle_linear_many_numpy(bases, problem.periodogram, problem.nonnegative, iterations)
            assert np.array_equal(np.isfinite(nll), np.isfinite(ref_nll))
            assert np.isnan(nll[3]) or np.isinf(nll[3])
            finite = np.isfinite(ref_nll)
            # rounding: sums in another order (1e-12 of the likelihood; a coefficient to 1e-6 of the largest,
            # measured 8e-7 on the throughput record's 78 calls, where a flat direction leaves it loose)
            assert np.allclose(nll[finite], ref_nll[finite], rtol=1e-12, atol=0)
            scale = np.max(np.abs(ref_lin[finite]), axis=1, keepdims=True)
            assert np.max(np.abs(lin[finite] - ref_lin[finite]) / scale) <= 1e-6
        null = A._whittle_linear(problem.fixed, problem.periodogram, problem.nonnegative[2:], iterations=12)
        ref = A._whittle_linear_numpy(problem.fixed, problem.periodogram, problem.nonnegative[2:], iterations=12)
        assert null[1] == pytest.approx(ref[1], rel=1e-12)
        assert np.max(np.abs(null[0] - ref[0])) <= 1e-8 * np.max(np.abs(ref[0]))


@pytest.mark.parametrize("seed", range(3))
def test_the_kernel_s_grid_forms_the_bases_designs_forms(seed):
    """linear_grid (the kernel forms each row's Fejér columns as it fits them) against the numpy reference of
    designs + whittle_linear_many, on rows in frequency-major order (the rotations reused) and in a shuffled one."""
    if A._whittle_kernel is None:
        pytest.skip("the compiled kernel is not built in this install (no C compiler)")
    problem, f0 = _problem(seed, 2)
    sigma = 0.01 * 2 * np.pi * f0
    grid = np.array([[f, s] for f in np.linspace(f0 - 0.1, f0 + 0.1, 9) for s in sigma * np.logspace(-0.6, 0.6, 5)])
    for rows in (grid, grid[np.random.default_rng(seed).permutation(len(grid))]):
        lin, nll = A.linear_grid(rows, problem, 4)
        ref_lin, ref_nll = A.whittle_linear_many_numpy(A.designs(rows, problem), problem.periodogram,
                                                        problem.nonnegative, 4)
        assert np.allclose(nll, ref_nll, rtol=1e-12, atol=0)  # rounding (sums and the Fejér sums in another order)
        assert np.max(np.abs(lin - ref_lin) / np.max(np.abs(ref_lin), axis=1, keepdims=True)) <= 1e-6


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("neighbours", [0, 2])
def test_the_kernel_s_fisher_scoring_is_the_numpy_reference_s(seed, neighbours):
    """The one-pole fit by the compiled kernel (its expected periodogram, gradient, scoring step with the held
    powers and its least squares from an eigen-decomposition) and by ambient_fit's numpy steps, from the start
    grid's best: the same pole, the same convergence, the same mean and gradient where it ended."""
    from stcs_ident.spectra import ambient_fit as F

    if A._whittle_kernel is None:
        pytest.skip("the compiled kernel is not built in this install (no C compiler)")
    problem, f0 = _problem(seed, neighbours)
    limits = ((f0 - 0.2, f0 + 0.2), (0.0, 0.2 * 2 * np.pi * f0))
    start = A.grid_start([f0, f0 + 0.01], problem, limits, tuple(np.logspace(-4, -1, 7)))
    theta, ok, mean, grad = F.fisher_scoring(start, problem, limits, 60)
    ref_theta, ref_ok, ref_mean, ref_grad = F._fisher_scoring_numpy(start, problem, limits, 60)
    assert ok == ref_ok
    # the converged pole to 1e-9 of its frequency and decay rate (the scoring stops within 1e-4 of a Fisher
    # σ, which the two paths' rounding moves by far less)
    assert theta[0] == pytest.approx(ref_theta[0], rel=1e-9)
    assert theta[1] == pytest.approx(ref_theta[1], rel=1e-6)
    assert np.allclose(mean, ref_mean, rtol=1e-8, atol=0)
    assert np.allclose(grad, ref_grad, rtol=1e-6, atol=1e-9 * np.max(np.abs(ref_grad), axis=0))
    # at θ itself the kernel's mean and gradient are the reference's formulas (rounding only)
    same_mean, same_grad = F._expected(theta, problem)
    assert np.allclose(mean, same_mean, rtol=1e-12, atol=0)
    assert np.allclose(grad, same_grad, rtol=1e-9, atol=1e-12 * np.max(np.abs(same_grad), axis=0))


def test_the_kernel_s_threads_give_each_row_its_own_result():
    """A grid's rows split over threads: the same bits as on one thread (each row's arithmetic its own)."""
    if A._whittle_kernel is None:
        pytest.skip("the compiled kernel is not built in this install (no C compiler)")
    problem, f0 = _problem(7, 2)
    sigma = 0.01 * 2 * np.pi * f0
    grid = np.array([[f, s] for f in np.linspace(f0 - 0.1, f0 + 0.1, 13) for s in sigma * np.logspace(-0.6, 0.6, 5)])
    args = (grid, problem.phase, problem.n_samples, problem.dt, np.ascontiguousarray(problem.fixed),
            problem.periodogram, problem.nonnegative.astype(np.uint8), 6)
    one = A._whittle_kernel.grid(*args, 1)
    for threads in (2, 3, 7):
        assert A._whittle_kernel.grid(*args, threads) == one
