"""Near-maximum-likelihood fit of one mode to an ambient record: debiased Whittle likelihood.

Modal coordinate
    Around the peak, the channels' DFTs (whole record, normalised by 1/√N)
    are whitened by each channel's noise floor and projected on the first
    eigenvector u of their cross-spectral matrix summed over the peak's
    bins (the FDD mode shape): y[k] = Σ_c conj(u_c) X_c[k] / s_c. This
    matched spatial filter gives the mode the best signal-to-noise ratio a
    linear combination can, and makes one scalar series, so the mode's
    random excitation (common to all channels) is counted once.

Expected periodogram
    A mode is a pole pair r = exp((−σ + i 2π f_d) Δt); whatever the
    excitation and the measured quantity, its autocovariance is
    c(τ) = Re(C r^|τ|) with a complex C. Near +f_d, the expected (not the
    true) periodogram of N samples is exactly

        E I(ω) = α Re H(u) + β Im H(u),   u = r e^{−iω},   |β| ≤ α,
        H(u) = 2 G(u) − 1,   G(u) = Σ_{τ=0}^{N−1} (1 − τ/N) u^τ
             = 1/(1 − u) − u (1 − u^N) / (N (1 − u)²),

    the SDOF spectrum convolved with the Fejér kernel in closed form: the
    leakage of a peak only a few bins wide is modelled, not suffered
    ("debiased Whittle", Sykulski et al. 2019, Biometrika 106(2)). The
    dispersive part β (of order ζ α for one mode; leaving it out biases
    the frequency by up to one σ in long records) is bounded by α, so a
    mode is always a peak, never a mere wiggle. Other modes add
    α_j Re H(u_j) with fixed poles and α_j ≥ 0, and noise and far tails a
    line that is ≥ 0 across the band (two ramps, each ≥ 0, from either
    edge). A line of free slope could go to zero inside the band, where the
    mode's dispersive part (negative beyond its half-power point on one
    side) cancels the rest: the model's mean then dips to nothing at one
    bin whose periodogram happens to be tiny, and log E_k rewards it by
    several units (a 60-s record of a stay: mode 16 at 14.57 Hz fitted at
    14.43 ± 0.012 Hz, −12σ, its mean 1e-3 at a bin of 6e-4 among bins of
    about 10). Nothing else: with a curvature term, a
    dispersive part of a neighbour or a neighbour of either sign, the
    background alone could carve a bump between two neighbours and mimic
    (and weaken the test of) the mode. The periodogram bins are then
    independent exponential variables with these means (asymptotically),
    and the Whittle likelihood Σ [log E_k + I_k / E_k] is maximised by
    Fisher scoring over (f_d, σ) and the linear coefficients, the bounded
    ones held at their bound while the step would cross it; the start is
    the best of a few frequencies × a grid of ζ.

Uncertainty
    The inverse Fisher information of the Whittle likelihood,
    F = Σ ∂E ∂Eᵀ / E², with the linear coefficients marginalised, each
    variance widened to the sandwich (misfit-robust) estimate where that
    is larger: in crowded bands of broad resonances the fixed shapes of
    the neighbours are only approximate. On a peak fewer than about 50
    bins wide the likelihood need not be Gaussian (second maxima on
    clusters of noise bins; below about 25 bins a skewed decay rate): the
    1σ is then widened to the spread of the profile likelihood where that
    is larger and, for the frequency, irregular (:mod:`.profile`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .decay_fit import one_blas_thread, pole_statistics
from .options import FitOptions
from .profile import spreads
from .whittle import (
    TINY,
    BandProblem,
    band_design,
    compiled_scoring,
    fejer_lorentzian,
    grid_start,
    neg_log_likelihood,
    null_neg_log_likelihood,
)

__all__ = ["AmbientFit", "fejer_lorentzian", "fisher_scoring", "fit_ambient", "marginal_covariance",
           "robust_covariance", "widen_to_spread"]

# The iterations and the start's ζ grid are :class:`.options.FitOptions`.
# A pole fitted narrower than this share of a resolution cell (2σ/2π below UNRESOLVED_BINS / T) has its decay rate at
# its bound: the record does not resolve its width, and the information of its frequency is degenerate there (the
# frequency confounded with the line's dispersive part: a 30-s stay's mode 1 at 0.83 Hz fitted with ζ 3e-14 had a
# 1σ of 35 kHz). Its 1σ is then that of the resolution cell (:func:`_unresolved_covariance`): measured on
# benchmarks/short_records.py's 30-s stays (seed 36000), 8 such modes off by 0.02-0.53 bins.
UNRESOLVED_BINS = 0.01
SERIAL_BLAS_SIZE = 2048  # elements: OpenBLAS runs a complex matrix-vector product this small on one thread


@dataclass(frozen=True)
class AmbientFit:
    """Result of :func:`fit_ambient`.

    Parameters
    ----------
    frequency, frequency_std : float
        Undamped natural frequency f_n and its 1σ, Hz.
    decay_rate, decay_rate_std : float
        σ, 1/s.
    damping, damping_std : float
        ζ = σ / (2π f_n); NaN where the fitted peak is narrower than the record resolves
        (:data:`UNRESOLVED_BINS`).
    amplitude : ndarray (n_channels,)
        Root-mean-square modal acceleration in each channel, signed by the
        phase of the mode shape relative to its largest entry, m/s².
    mode_shape : ndarray (n_channels,) complex
        Unit-norm mode shape (not whitened).
    misfit : float
        The sandwich (misfit-robust) 1σ of the frequency over the Fisher information's, at least 1: about 1
        where one mode over the background describes the band, larger where it does not (a second
        resonance under the mode, an excitation far from white across the band).
    significance : float
        Root of the likelihood-ratio statistic, sqrt(2 (ℓ₀ − ℓ)), of the
        mode against the background and neighbours alone: a z-like score,
        about 0–3 where no mode is present.
    converged : bool
    """

    frequency: float
    frequency_std: float
    decay_rate: float
    decay_rate_std: float
    damping: float
    damping_std: float
    amplitude: np.ndarray
    mode_shape: np.ndarray
    significance: float
    converged: bool
    misfit: float = 1.0
    # What :func:`widen_to_spread` needs (the band, the fit, its limits and covariance), kept by a fit made with
    # ``spread=False``.
    band: tuple | None = field(default=None, repr=False, compare=False)


def _expected(theta: np.ndarray, problem: BandProblem):
    basis, deriv = band_design(theta[:2], problem)
    lin = theta[2:]
    mean = basis @ lin
    grad = np.empty((basis.shape[0], 2 + basis.shape[1]))
    grad[:, 0] = deriv[:, :, 0] @ lin[:2]
    grad[:, 1] = deriv[:, :, 1] @ lin[:2]
    grad[:, 2:] = basis
    return mean, grad


def _fisher(grad: np.ndarray, mean: np.ndarray) -> np.ndarray:
    g = grad / mean[:, None]
    return g.T @ g


def _scoring_step(theta, score, fisher, nonnegative) -> np.ndarray:
    """Fisher-scoring step with power coefficients at zero held there where the likelihood wants them lower.

    The step minimises the local quadratic model −scoreᵀd + ½ dᵀ F d with the powers at zero kept ≥ 0, by an
    active set: a power at zero that the unconstrained step takes negative is held, and released again when the
    model's gradient at the held step says the likelihood would rise with it (its multiplier's sign). Holding
    without the release left a mode's symmetric part at zero whenever the joint step, through its correlation
    with the background, went negative while its own score was positive: the line shape then kept its largest
    dispersive part and its peak off the pole (a hanger's modes 14-20 at ζ 1.5 %, 60 s, all about 1 % low).
    """
    bounded = np.concatenate([np.zeros(theta.size - nonnegative.size, bool), nonnegative])  # after the poles
    at_zero = bounded & (theta <= 1e-12 * np.abs(theta).max())
    held = np.zeros(theta.size, dtype=bool)
    step = np.zeros(theta.size)
    for _ in range(2 * theta.size):
        free = ~held
        sub = fisher[np.ix_(free, free)]
        scale = np.sqrt(np.maximum(sub.diagonal(), TINY))
        step = np.zeros(theta.size)
        step[free] = np.linalg.lstsq(sub / (scale[:, None] * scale), score[free] / scale, rcond=1e-12)[0] / scale
        blocked = np.flatnonzero(free & at_zero & (step < 0))
        if blocked.size:
            held[blocked] = True
            continue
        gradient = fisher @ step - score  # of the quadratic model at the step: < 0 where moving up would lower it
        release = np.flatnonzero(held & (gradient < 0))
        if release.size == 0:
            break
        held[release[np.argmin(gradient[release])]] = False
    return step


def fisher_scoring(theta: np.ndarray, problem: BandProblem, limits, max_iterations: int,
                   expected=_expected) -> tuple[np.ndarray, bool, np.ndarray, np.ndarray]:
    """Fisher scoring with step halving (mean positive, likelihood not falling, powers ≥ 0, inside the limits).

    ``limits`` holds (low, high) of each nonlinear parameter, the first ``len(limits)`` of θ (f and σ of each
    pole); ``expected(θ, problem)`` gives the expected periodogram and its gradient (one pole: :func:`_expected`;
    several: :mod:`.two_poles`). Returns θ, whether it converged, and the expected periodogram and its gradient
    at θ. One pole is scored by the compiled kernel where it is built (``_whittle_kernel.c``: these steps, its
    least squares from the eigen-decomposition of the symmetric system), else by the steps below, its reference.
    """
    if expected is _expected and len(limits) == 2:  # one pole: its (f, σ) limits
        compiled = compiled_scoring(theta, problem, limits, max_iterations)
        if compiled is not None:
            return compiled
    return _fisher_scoring_numpy(theta, problem, limits, max_iterations, expected)


def _fisher_scoring_numpy(theta: np.ndarray, problem: BandProblem, limits, max_iterations: int,
                          expected=_expected) -> tuple[np.ndarray, bool, np.ndarray, np.ndarray]:
    """:func:`fisher_scoring` in numpy (the kernel's reference)."""
    poles = len(limits)
    mean, grad = expected(theta, problem)
    nll = neg_log_likelihood(mean, problem.periodogram)
    for _ in range(max_iterations):
        score = grad.T @ ((problem.periodogram - mean) / mean**2)
        fisher = _fisher(grad, mean)
        if not (np.all(np.isfinite(fisher)) and np.all(np.isfinite(score))):
            return theta, False, mean, grad
        try:
            step = _scoring_step(theta, score, fisher, problem.nonnegative)
        except np.linalg.LinAlgError:  # an information matrix LAPACK cannot solve (a band of Nyquist-alternating
            return theta, False, mean, grad  # samples): not converged, and the caller's checks reject the fit
        if not np.all(np.isfinite(step)):
            return theta, False, mean, grad
        if np.all(np.abs(step[:poles]) * np.sqrt(np.maximum(np.diag(fisher)[:poles], TINY)) < 1e-4):
            return theta, True, mean, grad
        for _ in range(30):
            trial = theta + step
            trial[poles:] = np.where(problem.nonnegative, np.maximum(trial[poles:], 0.0), trial[poles:])
            if all(low < value < high for value, (low, high) in zip(trial, limits)):
                new_mean, new_grad = expected(trial, problem)
                new_nll = neg_log_likelihood(new_mean, problem.periodogram)
                if new_nll <= nll:
                    theta, mean, grad, nll = trial, new_mean, new_grad, new_nll
                    break
            step = step / 2
        else:
            return theta, True, mean, grad  # no decrease along the scoring direction: at the optimum within rounding
    return theta, False, mean, grad


def robust_covariance(grad: np.ndarray, mean: np.ndarray, periodogram: np.ndarray,
                      keep=(0, 1)) -> tuple[np.ndarray, float]:
    """Covariance of the parameters ``keep`` (a pole's (f, σ): the first two of a one-pole fit), the others
    marginalised: the inverse Fisher information, widened to the sandwich estimate where larger; and the first
    one's widening factor (:attr:`AmbientFit.misfit`).

    The sandwich F⁻¹ J F⁻¹, J = Σ_k s_k s_kᵀ with the per-bin scores
    s_k = ∂E_k (I_k − E_k) / E_k², equals F⁻¹ when the model is right and
    grows when it is not (wrong neighbour shapes, a second mode in the
    band): each variance is the larger of the two, the correlation F's.
    """
    keep = list(keep)
    fisher = _fisher(grad, mean)
    cov = marginal_covariance(fisher, keep)
    scores = grad * ((periodogram - mean) / mean**2)[:, None]
    inverse = np.linalg.pinv(fisher, rcond=1e-12)
    sandwich = (inverse @ (scores.T @ scores) @ inverse)[np.ix_(keep, keep)]
    widen = np.sqrt(np.maximum(np.diag(sandwich) / np.diag(cov), 1.0))
    return cov * np.outer(widen, widen), float(widen[0])


def marginal_covariance(fisher: np.ndarray, keep=(0, 1)) -> np.ndarray:
    """Covariance of the parameters ``keep`` with the others marginalised (Schur complement)."""
    keep = list(keep)
    rest = [j for j in range(fisher.shape[0]) if j not in keep]
    a = fisher[np.ix_(keep, keep)]
    b = fisher[np.ix_(keep, rest)]
    d = fisher[np.ix_(rest, rest)]
    return np.linalg.inv(a - b @ np.linalg.pinv(d, rcond=1e-12) @ b.T)


def _serial_product(matrix: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """matrix @ vector, in blocks of rows small enough for one BLAS thread (the same values).

    OpenBLAS splits a complex matrix-vector product of 4096 elements or more over its threads; on a
    busy machine each such call then waits for a core (measured, 1200 × 16: 20 µs on one thread,
    200–600 µs threaded under load).
    """
    rows = max(1, SERIAL_BLAS_SIZE // max(1, matrix.shape[1]))
    out = np.empty(matrix.shape[0], dtype=np.result_type(matrix, vector))
    for start in range(0, matrix.shape[0], rows):
        np.matmul(matrix[start : start + rows], vector, out=out[start : start + rows])
    return out


@one_blas_thread
def mode_shape(dft_white: np.ndarray) -> np.ndarray:
    """First eigenvector of Σ_k X_k X_k^H (unit norm, largest entry real positive)."""
    m = dft_white.T @ dft_white.conj()
    _, vectors = np.linalg.eigh(m)
    u = vectors[:, -1]
    k = int(np.argmax(np.abs(u)))
    return u * np.exp(-1j * np.angle(u[k]))


@one_blas_thread
def fit_ambient(
    dft: np.ndarray,
    n_samples: int,
    sampling_rate: float,
    f_initial: float,
    half_width: float,
    noise_scale: np.ndarray,
    neighbours: list[tuple[float, float]] = (),
    peak_width: float = 0.0,
    max_damping: float = 0.2,
    options: FitOptions | None = None,
    spread: bool = True,
) -> AmbientFit | None:
    """Fit one mode to the band [f_initial ± half_width] of an ambient record.

    Parameters
    ----------
    dft : ndarray (n_rfft, n_channels) complex
        rfft of the whole record divided by √N.
    n_samples : int
        N.
    sampling_rate : float
        Hz.
    f_initial : float
        Overview peak, Hz.
    half_width : float
        Half-width of the band used, Hz.
    noise_scale : ndarray (n_channels,)
        Noise standard deviation per DFT bin of each channel near the peak
        (for whitening), m/s².
    neighbours : list of (frequency, decay rate)
        Nearby modes whose tails cross the band (fixed poles).
    peak_width : float
        Approximate -3 dB width of the peak, Hz (bins used for the mode shape).
    max_damping : float
        Upper bound on ζ during the search.
    options : FitOptions, optional
        Iterations and the start's ζ grid (default: the calibrated values).
    spread : bool
        Widen the frequency's 1σ to the spread of the profile likelihood where that is larger
        (:mod:`.profile`; a peak fewer than :data:`.profile.GAUSSIAN_BINS` bins wide). False gives the
        curvature's 1σ alone and keeps what :func:`widen_to_spread` needs: for a caller that fits many
        bands and keeps few (the profile costs several fits' time).

    Returns
    -------
    AmbientFit or None
        None when the fit leaves the band.
    """
    options = FitOptions() if options is None else options
    dt = 1.0 / sampling_rate
    df = sampling_rate / n_samples
    k = np.arange(max(1, int(np.ceil((f_initial - half_width) / df))), int(np.floor((f_initial + half_width) / df)) + 1)
    k = k[k < dft.shape[0]]
    if k.size < 12:
        return None
    white = dft[k] / noise_scale[None, :]
    near = np.abs(k * df - f_initial) <= max(peak_width, 3 * df)
    u = mode_shape(white[near])
    y = _serial_product(white, u.conj())
    fixed = _fixed_basis(k * df, f_initial, half_width, neighbours, k, n_samples, dt)
    # Linear coefficients: mode (p, q), neighbours, the background's two ramps; all are powers, ≥ 0.
    nonnegative = np.ones(2 + len(neighbours) + 2, dtype=bool)
    problem = BandProblem(np.abs(y) ** 2, 2 * np.pi * k / n_samples, n_samples, dt, fixed, nonnegative)
    # Starting frequencies: the overview's, and the band's maximum after smoothing over 3 bins (a narrow
    # peak) and over a quarter of the overview's width (a broad one, whose bins scatter).
    starts = [f_initial]
    for width in (3 * df, 0.25 * peak_width):
        f_max = _smoothed_peak(problem.periodogram, k * df, width)
        if all(abs(f_max - f) > 2 * df for f in starts):
            starts.append(f_max)
    limits = (
        (f_initial - half_width, f_initial + half_width),
        (0.0, min(2 * np.pi * half_width, max_damping * 2 * np.pi * f_initial)),
    )
    theta = grid_start(starts, problem, limits, options.ambient_start_damping)
    theta, ok, mean, grad = fisher_scoring(theta, problem, limits, options.ambient_max_iterations)
    # Power coefficients held at zero by their bound are not free: leave them out of the information.
    free = np.concatenate([[True, True], ~(problem.nonnegative & (theta[2:] <= 0))])
    try:
        cov, misfit = robust_covariance(grad[:, free], mean, problem.periodogram)
    except np.linalg.LinAlgError:
        cov, misfit = None, 1.0
    duration = n_samples * dt
    unresolved = theta[1] * duration / np.pi < UNRESOLVED_BINS
    if unresolved:  # its information is degenerate (a singular or negative covariance is then no reason to refuse)
        cov = _unresolved_covariance(duration)
    elif cov is None or not np.all(np.isfinite(cov)) or cov[0, 0] <= 0 or cov[1, 1] <= 0:
        return None
    band = None if unresolved else (problem, theta, limits, cov)
    if spread and not unresolved:
        cov = _spread_covariance(*band)
    null = null_neg_log_likelihood(problem)
    significance = np.sqrt(max(2.0 * (null - neg_log_likelihood(mean, problem.periodogram)), 0.0))
    variance_y = 2.0 * (theta[2] + theta[3])  # c(0) = 2α of the modal term in y, α = p + q
    shape = u * noise_scale
    shape = shape / np.linalg.norm(shape)
    amplitude = np.sqrt(max(variance_y, 0.0)) * np.abs(u) * noise_scale * np.sign(np.cos(np.angle(u)))
    fit = _result(theta[:2], cov, amplitude, shape, significance, ok, misfit)
    if unresolved:  # its width, and so its damping ratio, is below what the record resolves: not estimated
        fit = replace(fit, damping=float("nan"), damping_std=float("nan"))
    return fit if spread else replace(fit, band=band)


def _unresolved_covariance(duration: float) -> np.ndarray:
    """The covariance of (f_d, σ) of a pole fitted narrower than the record resolves (:data:`UNRESOLVED_BINS`):
    each uniform over what one resolution cell allows, the frequency over its bin (1/T) and the decay rate
    over [0, π/T] (a half-power width of one bin)."""
    return np.diag([1.0 / (12.0 * duration**2), (np.pi / duration) ** 2 / 12.0])


def widen_to_spread(fit: AmbientFit) -> AmbientFit:
    """A fit made with ``spread=False``, its 1σ widened as ``spread=True`` would have (the same pole)."""
    if fit.band is None:
        return fit
    theta = fit.band[1]
    cov = _spread_covariance(*fit.band)
    _, f_std, _, zeta_std = pole_statistics(theta[0], theta[1], cov)
    return replace(fit, frequency_std=max(fit.frequency_std, f_std), damping_std=max(fit.damping_std, zeta_std),
                   decay_rate_std=max(fit.decay_rate_std, float(np.sqrt(cov[1, 1]))), band=None)


def _spread_covariance(problem: BandProblem, theta: np.ndarray, limits, cov: np.ndarray) -> np.ndarray:
    """The covariance of (f_d, σ), each variance widened to the profile likelihood's spread where that is
    larger (:mod:`.profile`); the correlation kept."""
    std = np.sqrt(np.diag(cov))
    reach = max(8.0 * std[0], 6.0 * theta[1] / (2 * np.pi))
    spread = np.array(spreads(problem, theta, float(std[0]), reach, limits))
    widen = np.maximum(spread / std, 1.0)
    return cov * np.outer(widen, widen)


def _fixed_basis(freq, f_centre, half_width, neighbours, k, n, dt) -> np.ndarray:
    columns = []
    phase = 2 * np.pi * k / n
    for fj, sj in neighbours:
        h, _ = fejer_lorentzian(complex(-sj * dt, 2 * np.pi * fj * dt), phase, n, derivative=False)
        columns.append(h.real)
    x = (freq - f_centre) / half_width
    columns += [(1 - x) / 2, (1 + x) / 2]  # the background: a line ≥ 0 across the band, as two ramps ≥ 0
    return np.column_stack(columns)


def _smoothed_peak(periodogram: np.ndarray, freq: np.ndarray, width: float) -> float:
    n = max(1, round(width / (freq[1] - freq[0])))
    smooth = np.convolve(periodogram, np.ones(n) / n, mode="same")
    return float(freq[int(np.argmax(smooth))])


def _result(theta, cov, amplitude, shape, significance, ok, misfit=1.0) -> AmbientFit:
    f_d, sigma = theta
    f_n, f_std, zeta, zeta_std = pole_statistics(f_d, sigma, cov)
    return AmbientFit(
        frequency=f_n,
        frequency_std=f_std,
        decay_rate=float(sigma),
        decay_rate_std=float(np.sqrt(cov[1, 1])),
        damping=zeta,
        damping_std=zeta_std,
        amplitude=amplitude,
        mode_shape=shape,
        significance=float(significance),
        converged=bool(ok),
        misfit=misfit if np.isfinite(misfit) else 1.0,
    )
