"""The Whittle likelihood of one band's periodogram, as :mod:`.ambient_fit` fits it: the expected
periodogram of a mode (the Fejér-convolved SDOF spectrum, :func:`fejer_lorentzian`) on a fixed background,
its linear coefficients by damped Fisher scoring with powers held ≥ 0, and the start grid of (f, ζ), every
candidate of which is evaluated at once (:func:`grid_start`). The model and its references are in
:mod:`.ambient_fit`'s docstring.

The many small fits (start grids, profile grids, null fits, the one-pole scoring) run in the optional compiled
kernel ``_whittle_kernel.c`` where the install built it: the numpy functions here are its reference (the tests
compare the two; ``STCS_IDENT_NUMPY=1`` runs them), a candidate's result is its own arithmetic's, whatever the
batch or the threads.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..forward.roots import FORCE_NUMPY

try:  # the optional compiled kernel of whittle_linear_many (setup.py); the same numerics, no per-call overhead
    from . import _whittle_kernel
except ImportError:  # pragma: no cover - depends on the install
    _whittle_kernel = None

__all__ = [
    "TINY",
    "BandProblem",
    "band_design",
    "compiled_scoring",
    "designs",
    "fejer_lorentzian",
    "grid_start",
    "kernel_threads",
    "linear_grid",
    "neg_log_likelihood",
    "null_neg_log_likelihood",
    "whittle_linear_many",
    "whittle_linear_many_numpy",
]

TINY = np.finfo(float).tiny


def fejer_lorentzian(
    z: complex, phase: np.ndarray, n: int, derivative: bool = True
) -> tuple[np.ndarray, np.ndarray | None]:
    """H(u) = 2G(u) − 1 and dH/dz at u = exp(z − iφ), for the pole z = sΔt (see the module docstring).

    With ``derivative=False`` only H (and None): the start grid and the
    fixed neighbours need no derivative.
    """
    z = np.asarray(z)
    return _fejer(z.real, _turns(z.imag - phase, n), n, derivative)


def _turns(y: np.ndarray, n: int) -> tuple[tuple, tuple]:
    """The rotations of u = exp(z − iφ) and of uᴺ: (cos, sin, 2 sin²(·/2)) of y = Im z − φ and of N y.

    The transcendental part of :func:`fejer_lorentzian`, which depends on the frequency of the pole only:
    the start grid's poles of one frequency and several damping ratios share it (:func:`designs`).
    """
    return _rotation(y), _rotation(n * y)


def _rotation(y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    half = np.sin(0.5 * y)
    return np.cos(y), np.sin(y), 2.0 * half * half


def _complex(real: np.ndarray, imag: np.ndarray) -> np.ndarray:
    out = np.empty(np.broadcast_shapes(np.shape(real), np.shape(imag)), dtype=complex)
    out.real = real
    out.imag = imag
    return out


def _fejer(a, turns: tuple, n: int, derivative: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`fejer_lorentzian` from Re z (`a`, broadcasting against the rotations) and :func:`_turns`.

    exp and expm1 of x + iy written out as numpy's complex functions do (expm1: expm1(x) cos y − 2 sin²(y/2)
    + i eˣ sin y, free of cancellation near u = 1), with the sines and cosines computed once for u, 1 − u,
    uᴺ and 1 − uᴺ (twelve transcendental functions of each bin's complex argument before, of which eight
    were sines and cosines of the same two angles): the same values to rounding, in a third of the time.
    """
    (cos, sin, half), (cos_n, sin_n, half_n) = turns
    grow, grow_n = np.exp(a), np.exp(n * a)
    one_minus = _complex(half - np.expm1(a) * cos, -grow * sin)  # 1 − u = −expm1(log u)
    u = _complex(grow * cos, grow * sin)
    trunc = _complex(half_n - np.expm1(n * a) * cos_n, -grow_n * sin_n)  # 1 − u^N
    g = 1.0 / one_minus - u * trunc / (n * one_minus**2)
    if not derivative:
        return 2.0 * g - 1.0, None
    # dG/du, then du/dz = u.
    u_n = _complex(grow_n * cos_n, grow_n * sin_n)
    dg_du = (
        1.0 / one_minus**2 - (trunc - n * u_n) / (n * one_minus**2) - 2 * u * trunc / (n * one_minus**3)
    )
    return 2.0 * g - 1.0, 2.0 * dg_du * u


@dataclass
class BandProblem:
    periodogram: np.ndarray  # I_k
    phase: np.ndarray  # 2πk/N
    n_samples: int
    dt: float
    fixed: np.ndarray  # (m, q) fixed real basis columns: neighbours, then the background (see _whittle_linear)
    nonnegative: np.ndarray  # (2 + q,) bool: linear coefficients that are powers (mode, neighbours, background)


def band_design(theta_nl: np.ndarray, problem: BandProblem, derivative: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """Real basis (m, 2 + q) of the expected periodogram and its derivative wrt (f, σ) for the mode term."""
    z = complex(-theta_nl[1] * problem.dt, 2 * np.pi * theta_nl[0] * problem.dt)
    h, dh = fejer_lorentzian(z, problem.phase, problem.n_samples, derivative)
    # α Re H + β Im H with |β| ≤ α, written as p (Re H + Im H) + q (Re H − Im H) with p, q ≥ 0.
    basis = np.empty((h.size, 2 + problem.fixed.shape[1]))
    np.add(h.real, h.imag, out=basis[:, 0])
    np.subtract(h.real, h.imag, out=basis[:, 1])
    basis[:, 2:] = problem.fixed
    if not derivative:
        return basis, None
    deriv = np.empty((h.size, 2, 2))
    for j, d in enumerate((2j * np.pi * problem.dt, -problem.dt)):
        dh_d = dh * d
        np.add(dh_d.real, dh_d.imag, out=deriv[:, 0, j])
        np.subtract(dh_d.real, dh_d.imag, out=deriv[:, 1, j])
    return basis, deriv


def neg_log_likelihood(mean: np.ndarray, periodogram: np.ndarray) -> float:
    lowest = mean.min()
    if lowest <= 0 or (np.isnan(lowest) and np.any(mean <= 0)):  # (min is nan if any entry is)
        return np.inf
    terms = np.log(mean)
    terms += periodogram / mean
    return float(terms.sum())


def _linear_start(theta_nl: np.ndarray, problem: BandProblem) -> tuple[np.ndarray, float]:
    """Linear coefficients for given (f, σ)."""
    basis, _ = band_design(theta_nl, problem, derivative=False)
    return _whittle_linear(basis, problem.periodogram, problem.nonnegative, iterations=3)  # a start only


def null_neg_log_likelihood(problem: BandProblem) -> float:
    """Whittle -log-likelihood of the background and neighbours alone (no mode)."""
    return _whittle_linear(problem.fixed, problem.periodogram, problem.nonnegative[2:], iterations=12)[1]


def _whittle_linear(
    basis: np.ndarray, periodogram: np.ndarray, nonnegative: np.ndarray, iterations: int = 8
) -> tuple[np.ndarray, float]:
    """Whittle fit of a mean linear in its coefficients, by damped Fisher scoring (iteratively reweighted LS).

    It starts from the flat mean (the last two columns are the background:
    a constant and a slope, or, where the last is a power, two ramps from
    the band's edges that sum to a constant) and halves each step until the mean stays positive
    and the likelihood does not fall, so it never ends worse than the flat
    background. Coefficients that are powers stay ≥ 0: a neighbour's tail
    taken negative would carve a bump out of a constant and mimic a mode. By the compiled kernel where it is
    built (:func:`whittle_linear_many` of one basis: the same steps), else :func:`_whittle_linear_numpy`.
    """
    if _whittle_kernel is None or FORCE_NUMPY:
        return _whittle_linear_numpy(basis, periodogram, nonnegative, iterations)
    lin, nll = whittle_linear_many(basis[None], periodogram, nonnegative, iterations)
    return lin[0], float(nll[0])


def _whittle_linear_numpy(
    basis: np.ndarray, periodogram: np.ndarray, nonnegative: np.ndarray, iterations: int = 8
) -> tuple[np.ndarray, float]:
    """:func:`_whittle_linear` in numpy (the reference of the compiled kernel)."""
    lin = np.zeros(basis.shape[1])
    lin[-2] = np.mean(periodogram)
    if nonnegative[-1]:  # the background as two nonnegative edge ramps: both at the mean make it flat
        lin[-1] = lin[-2]
    mean = basis @ lin
    nll = neg_log_likelihood(mean, periodogram)
    for _ in range(iterations):
        target = _weighted_least_squares(basis, periodogram, 1.0 / mean, nonnegative)
        step = target - lin
        for _ in range(20):
            trial = lin + step
            trial_mean = basis @ trial
            trial_nll = neg_log_likelihood(trial_mean, periodogram)
            if trial_nll <= nll:
                lin, mean, nll = trial, trial_mean, trial_nll
                break
            step = step / 2
        else:
            break
    return lin, nll


def _weighted_least_squares(basis, target, weight, nonnegative) -> np.ndarray:
    """min ||w (basis c − target)|| with c ≥ 0 where `nonnegative`, by dropping the most negative column in turn.

    A small active-set loop (the columns are few); the normal equations are
    solved with column scaling and a tiny ridge.
    """
    # Rows of a_t are the weighted columns (sub_t @ sub_t.T: the normal matrix of the free ones). Called
    # thousands of times per record: few numpy calls per pass, the same arithmetic as the plain form.
    a_t = np.multiply(basis.T, weight, order="C")
    b = target * weight
    n_columns = basis.shape[1]
    free = np.ones(n_columns, dtype=bool)
    bounded = nonnegative.copy()  # free columns that must stay >= 0
    sub_t = a_t
    for _ in range(n_columns):
        normal = sub_t @ sub_t.T
        scale = np.sqrt(np.maximum(normal.diagonal(), TINY))
        normal /= scale[:, None] * scale
        normal.flat[:: scale.size + 1] += 1e-12  # the ridge
        coef = np.zeros(n_columns)
        coef[free] = np.linalg.solve(normal, (sub_t @ b) / scale) / scale
        candidate = np.where(bounded, coef, 0.0)
        worst = int(np.argmin(candidate))
        if not candidate[worst] < 0:
            break
        free[worst] = bounded[worst] = False
        sub_t = a_t[free]
    return coef


def grid_start(starts: list[float], problem: BandProblem, limits, damping_grid) -> np.ndarray:
    """The best (least -log-likelihood) of the starting frequencies × `damping_grid` (ζ), linear terms fitted
    (all of them at once: :func:`linear_grid`; the first of equal ones)."""
    grid = [np.array([f_start, zeta * 2 * np.pi * f_start]) for f_start in starts for zeta in damping_grid]
    grid = [theta_nl for theta_nl in grid if limits[1][0] < theta_nl[1] < limits[1][1]]
    if grid:
        lin, nll = linear_grid(np.array(grid), problem, iterations=3)  # starts only
        best = int(np.argmin(np.where(np.isnan(nll), np.inf, nll)))
        if nll[best] < np.inf:
            return np.concatenate([grid[best], lin[best]])
    theta_nl = np.array([starts[0], limits[1][1] / 2])
    return np.concatenate([theta_nl, _linear_start(theta_nl, problem)[0]])


# A grid of this many rows × bins or more is split over the kernel's threads (:func:`kernel_threads`): a
# profile's grid (hundreds of rows of a few hundred bins), not a fit's start grid (15 rows of about 800 bins,
# a millisecond: threading those from 10 000 rows × bins on measured no faster on the throughput record).
THREADED_ROW_BINS = 50_000
MAX_KERNEL_THREADS = 4


def kernel_threads() -> int:
    """Threads for a large grid: the CPUs this process may use (at most :data:`MAX_KERNEL_THREADS`), or one in
    a worker process of a pool (track's, diagnose's, a Dask worker's), whose siblings use the others."""
    import multiprocessing

    if multiprocessing.parent_process() is not None:
        return 1
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        n = os.cpu_count() or 1
    return max(1, min(n, MAX_KERNEL_THREADS))


def linear_grid(thetas: np.ndarray, problem: BandProblem, iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`whittle_linear_many` of :func:`designs` (``thetas``, ``problem``): the linear terms fitted at each
    (f, σ) row, coefficients (c, 2 + q) and -log-likelihoods (c,). By the compiled kernel where it is built,
    which forms each row's basis as it fits it (the same formulas as :func:`_fejer`; the rotations once per
    distinct frequency, for consecutive rows): the grids never stacked in memory; a large grid's rows split
    over :func:`kernel_threads` threads (each row's result its own arithmetic's, whichever thread fits it)."""
    if _whittle_kernel is None or FORCE_NUMPY:
        return whittle_linear_many(designs(thetas, problem), problem.periodogram, problem.nonnegative, iterations)
    c, q = thetas.shape[0], 2 + problem.fixed.shape[1]
    threads = kernel_threads() if c * problem.phase.size >= THREADED_ROW_BINS else 1
    lin, nll = _whittle_kernel.grid(np.ascontiguousarray(thetas, dtype=np.float64),
                                    np.ascontiguousarray(problem.phase, dtype=np.float64), int(problem.n_samples),
                                    float(problem.dt), np.ascontiguousarray(problem.fixed, dtype=np.float64),
                                    np.ascontiguousarray(problem.periodogram, dtype=np.float64),
                                    np.ascontiguousarray(problem.nonnegative, dtype=np.uint8), int(iterations),
                                    threads)
    return np.frombuffer(lin, dtype=np.float64).reshape(c, q).copy(), np.frombuffer(nll, dtype=np.float64).copy()


def compiled_scoring(theta: np.ndarray, problem: BandProblem, limits, max_iterations: int):
    """The one-pole Fisher scoring (:func:`.ambient_fit.fisher_scoring` with its own expected periodogram) by the
    compiled kernel: θ, whether it converged, the expected periodogram and its gradient at θ; None where the
    kernel is not built (or STCS_IDENT_NUMPY=1): the caller then runs the numpy reference."""
    if _whittle_kernel is None or FORCE_NUMPY:
        return None
    m, p = problem.phase.size, theta.size
    out, ok, mean, grad = _whittle_kernel.fisher_scoring(
        np.ascontiguousarray(theta, dtype=np.float64), np.ascontiguousarray(problem.phase, dtype=np.float64),
        int(problem.n_samples), float(problem.dt), np.ascontiguousarray(problem.fixed, dtype=np.float64),
        np.ascontiguousarray(problem.periodogram, dtype=np.float64),
        np.ascontiguousarray(problem.nonnegative, dtype=np.uint8), np.array(limits, dtype=np.float64).ravel(),
        int(max_iterations))
    return (np.frombuffer(out, dtype=np.float64).copy(), bool(ok), np.frombuffer(mean, dtype=np.float64).copy(),
            np.frombuffer(grad, dtype=np.float64).reshape(m, p).copy())


def designs(thetas: np.ndarray, problem: BandProblem) -> np.ndarray:
    """:func:`band_design`'s basis (no derivative) of many (f, σ) rows at once, (c, m, 2 + q); the sines and
    cosines once per distinct frequency, for all its damping ratios (:func:`_turns`)."""
    omega = 2 * np.pi * thetas[:, 0] * problem.dt
    real = -thetas[:, 1] * problem.dt
    bases = np.empty((thetas.shape[0], problem.phase.size, 2 + problem.fixed.shape[1]))
    for value in np.unique(omega):
        rows = np.flatnonzero(omega == value)
        h, _ = _fejer(real[rows, None], _turns(value - problem.phase, problem.n_samples), problem.n_samples,
                      derivative=False)
        bases[rows, :, 0] = h.real + h.imag
        bases[rows, :, 1] = h.real - h.imag
    bases[:, :, 2:] = problem.fixed
    return bases


def whittle_linear_many(bases: np.ndarray, periodogram: np.ndarray, nonnegative: np.ndarray,
                         iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_whittle_linear` of many bases (c, m, q) at once: coefficients (c, q) and -log-likelihoods (c,).

    The same steps candidate by candidate (the flat start, the weighted least squares with the active set,
    the step halved until the likelihood does not fall, a candidate whose step cannot be made to stops). By
    the compiled kernel where it is built (``_whittle_kernel.c``: each candidate's arithmetic in a fixed
    order, whatever the batch), else in a few array operations for all (:func:`whittle_linear_many_numpy`,
    the reference): the start grids of the bands' fits and the profiles' grids were half of a bridge record's
    analysis, numpy's per-call overhead and temporaries on 6 × 6 systems."""
    if _whittle_kernel is None or FORCE_NUMPY:
        return whittle_linear_many_numpy(bases, periodogram, nonnegative, iterations)
    c, _, q = bases.shape
    lin, nll = _whittle_kernel.linear_many(np.ascontiguousarray(bases, dtype=np.float64),
                                           np.ascontiguousarray(periodogram, dtype=np.float64),
                                           np.ascontiguousarray(nonnegative, dtype=np.uint8), int(iterations))
    return np.frombuffer(lin, dtype=np.float64).reshape(c, q).copy(), np.frombuffer(nll, dtype=np.float64).copy()


def whittle_linear_many_numpy(bases: np.ndarray, periodogram: np.ndarray, nonnegative: np.ndarray,
                              iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`whittle_linear_many` in numpy, all candidates in a few array operations (the kernel's reference)."""
    c, _, q = bases.shape
    lin = np.zeros((c, q))
    lin[:, -2] = np.mean(periodogram)
    if nonnegative[-1]:  # the background as two nonnegative edge ramps (:func:`_whittle_linear`)
        lin[:, -1] = lin[:, -2]
    mean = np.einsum("cmq,cq->cm", bases, lin)
    nll = _neg_log_likelihood_many(mean, periodogram)
    active = np.ones(c, dtype=bool)
    for _ in range(iterations):
        if not active.any():
            break
        with np.errstate(divide="ignore", invalid="ignore"):
            target = _weighted_least_squares_many(bases, periodogram, 1.0 / mean, nonnegative)
        step = target - lin
        accepted = np.zeros(c, dtype=bool)
        for _ in range(20):
            todo = active & ~accepted
            if not todo.any():
                break
            trial = lin[todo] + step[todo]
            trial_mean = np.einsum("cmq,cq->cm", bases[todo], trial)
            trial_nll = _neg_log_likelihood_many(trial_mean, periodogram)
            with np.errstate(invalid="ignore"):
                ok = trial_nll <= nll[todo]
            rows = np.flatnonzero(todo)
            lin[rows[ok]], mean[rows[ok]], nll[rows[ok]] = trial[ok], trial_mean[ok], trial_nll[ok]
            accepted[rows[ok]] = True
            step[rows[~ok]] /= 2
        active &= accepted
    return lin, nll


def _neg_log_likelihood_many(mean: np.ndarray, periodogram: np.ndarray) -> np.ndarray:
    """:func:`neg_log_likelihood` of each row of ``mean``."""
    bad = np.any(mean <= 0, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.sum(np.log(mean) + periodogram / mean, axis=1)
    out[bad] = np.inf
    return out


def _weighted_least_squares_many(bases, target, weight, nonnegative) -> np.ndarray:
    """:func:`_weighted_least_squares` of many bases (c, m, q) and weights (c, m) at once. A dropped column is
    zeroed: its row and column of the normal matrix are then zero but for the ridge, and its coefficient 0."""
    c, _, q = bases.shape
    a_t = np.transpose(bases, (0, 2, 1)) * weight[:, None, :]  # (c, q, m)
    full = a_t @ np.transpose(a_t, (0, 2, 1))  # the normal matrix of all columns; a free set's is its sub-block
    full_rhs = np.einsum("cqm,cm->cq", a_t, target[None, :] * weight)
    free = np.ones((c, q), dtype=bool)
    bounded = np.broadcast_to(nonnegative, (c, q)).copy()
    running = np.ones(c, dtype=bool)
    coef = np.zeros((c, q))
    diagonal = np.arange(q)
    for _ in range(q):
        rows = np.flatnonzero(running)
        mask = free[rows]
        normal = full[rows] * (mask[:, :, None] & mask[:, None, :])
        scale = np.sqrt(np.maximum(normal[:, diagonal, diagonal], TINY))
        normal /= scale[:, :, None] * scale[:, None, :]
        normal[:, diagonal, diagonal] += 1e-12  # the ridge
        rhs = full_rhs[rows] * mask / scale
        coef[rows] = np.linalg.solve(normal, rhs[:, :, None])[:, :, 0] / scale * mask
        candidate = np.where(bounded[rows], coef[rows], 0.0)
        worst = np.argmin(candidate, axis=1)
        negative = candidate[np.arange(rows.size), worst] < 0
        running[rows[~negative]] = False
        drop = rows[negative]
        free[drop, worst[negative]] = bounded[drop, worst[negative]] = False
        if not running.any():
            break
    return coef
