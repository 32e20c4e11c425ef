"""Near-maximum-likelihood fit of one mode to free decays: a common pole, per channel/event amplitudes.

Model
    In segment e (N_e samples from the start of a free decay), channel c
    holds x[n] = b_ce r^n + conj(b_ce r^n) + other modes + noise, with the
    pole r = exp((−σ + i 2π f_d) Δt) common to all. Its DFT, normalised by
    1/√N_e so that white noise of variance s² gives every bin the variance
    s², is exactly

        X[k] = b_ce · g_e(k),   g_e(k) = (1 − r^N_e) / (1 − r e^{−2πik/N_e}) / √N_e

    near the positive-frequency peak, whether or not the decay has ended
    within the segment. Only the DFT bins within a band around the peak are
    used ("mixing down and decimating" done exactly: DFT bins of white noise
    are independent, so least squares on a band is maximum likelihood on
    that band). Other modes leave a smooth background in the band: the
    nearest detected mode on each side enters as its own fixed-pole term
    g(r_j), and a complex constant and slope take up the rest (the image
    at −f, far tails). All of these are linear, so they are eliminated by
    variable projection; only (f_d, σ) are iterated, by Levenberg–Marquardt
    with the Kaufman Jacobian −(I − P)(∂g/∂θ) b.

Noise and uncertainty
    Each channel's noise variance is estimated from its residual in the
    band (pooled over events); a second fit weights the channels by it.
    With white sensor noise the covariance is the inverse Fisher
    information 2 Re(J^H W J) of the projected problem, the Cramér–Rao
    bound at the estimate with the nuisance amplitudes marginalised. Wind
    that goes on under the decays adds the mode's own random response: a
    Lorentzian of the same pole, largest exactly where the frequency is
    decided and common to all channels. The band noise is therefore
    modelled as diag(n) + L_k M (sensor floor n per channel, forced
    response L_k M), both estimated from the residuals, and the
    covariance is the sandwich of the fit under that noise
    (:func:`.decay_covariance.forced_response_covariance`); it reduces to the bound when
    M = 0. White-noise Fisher σ under light wind was up to 6 times too
    small (benchmarks/calibrate_spectra.py).

Reported frequency
    The undamped natural frequency f_n = |s| / 2π of the pole s = −σ + i2πf_d,
    with ζ = σ / (2π f_n).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import wraps

import numpy as np
from scipy import stats

from .decay_covariance import forced_response_covariance
from .options import FitOptions
from .wander import between_events_addition

__all__ = ["DecayFit", "EventSpectrum", "event_spectra", "fit_decay", "one_blas_thread", "pole_statistics"]

# The iterations, the start's ζ grid and the events' agreement test are :class:`.options.FitOptions`.



class _OneBlasThread:
    """BLAS limited to one thread while any decorated function runs (:func:`one_blas_thread`).

    The limit is the process's (OpenBLAS keeps one thread count), so it is counted: set by the first call
    to enter, restored by the last to leave, whichever Python threads they run in. The controller is
    made at the first call, when numpy's and scipy's BLAS are loaded (about 1 ms; each limit then about
    7 µs).
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._depth = 0
        self._controller = None
        self._limiter = None

    def __enter__(self) -> None:
        with self._lock:
            if self._depth == 0:
                if self._controller is None:
                    from threadpoolctl import ThreadpoolController

                    self._controller = ThreadpoolController()
                self._limiter = self._controller.limit(limits=1, user_api="blas")
            self._depth += 1

    def __exit__(self, *exc) -> None:
        with self._lock:
            self._depth -= 1
            if self._depth == 0:
                self._limiter.restore_original_limits()
                self._limiter = None


_ONE_BLAS_THREAD = _OneBlasThread()


def one_blas_thread(function: Callable) -> Callable:
    """Run `function` with BLAS on one thread.

    A band's fit (:func:`fit_decay`, :func:`.ambient_fit.fit_ambient`) is hundreds of small products and
    solves (bins × a few parameters, channels × channels). OpenBLAS splits the larger of them over its
    threads (a matrix product from 65536 multiply-adds, a matrix-vector product from 9216 elements), where
    splitting gains nothing, and on a busy machine each such call waits for a core. Measured on two cores
    at load 3: the 16-channel, 10-minute ambient record of benchmarks/spectra.py --throughput spent 1.7 s
    of its 66 Whittle fits in the mode shape's 16 × 16 products alone (2 ms on one thread), find_peaks
    3.4–4.2 s instead of 0.7; the same record with ten blows (66 decay fits), at load 4–6, 10–15 s instead
    of 4–5.5.
    """

    @wraps(function)
    def on_one_thread(*args, **kwargs):
        with _ONE_BLAS_THREAD:
            return function(*args, **kwargs)

    return on_one_thread


@dataclass(frozen=True)
class EventSpectrum:
    """Normalised DFT of one free-decay segment: X = rfft(x) / √N, bins k ↔ k / (N Δt)."""

    dft: np.ndarray  # (n_bins, n_channels) complex
    n_samples: int


@dataclass(frozen=True)
class DecayFit:
    """Result of :func:`fit_decay`.

    Parameters
    ----------
    frequency, frequency_std : float
        Undamped natural frequency f_n and its 1σ, Hz.
    decay_rate, decay_rate_std : float
        σ, 1/s.
    damping, damping_std : float
        ζ = σ / (2π f_n).
    amplitude : ndarray (n_events, n_channels) complex
        Complex amplitude of the real sinusoid at the start of each segment
        (x = Re(amplitude · e^{(−σ+iω_d)t})), m/s².
    noise_std : ndarray (n_channels,)
        Noise standard deviation per sample in the band, m/s².
    channel_snr_db : ndarray (n_channels,)
        Peak power of the fitted mode over the noise power per bin, plus
        one (peak-to-floor ratio), best event, dB.
    residual_excess : float
        Mean residual power (in noise units) in the inner third of the band
        over that in the outer two thirds: about 1 when the decay model
        explains the peak, large when a random response (ambient loading
        continuing through the decay) or another misfit sits under it.
    forced_ratio : float
        Power of the mode's random (forced) response in the band over that
        of its free decay, both in noise units (:func:`.decay_covariance.noise_model`): about
        0 for a clean decay, above 1 where ambient loading rather than the
        blows makes the peak.
    significance : float
        The mode's amplitudes against their noise, Λ = Σ |b|² / var(b) over
        channels and events, as the equivalent one-sided Gaussian z (about
        0–3 where no mode is present; capped at 40). Channels count only
        as far as their residuals are independent (a random response
        common to all channels is one observation, not C).
    converged : bool
    event_frequencies, event_variances : ndarray (n_events,)
        Each event's own fit of the mode (f_d, Hz, and its variance, Hz²;
        NaN where the event is too short for the band or its fit failed),
        in the order of the spectra; empty with one event. The 1σ above
        already allows for their disagreement (:mod:`.wander`).
    """

    frequency: float
    frequency_std: float
    decay_rate: float
    decay_rate_std: float
    damping: float
    damping_std: float
    amplitude: np.ndarray
    noise_std: np.ndarray
    channel_snr_db: np.ndarray
    residual_excess: float
    significance: float
    converged: bool
    forced_ratio: float = 0.0
    event_frequencies: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    event_variances: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)


def event_spectra(x: np.ndarray, starts_stops: list[tuple[int, int]]) -> list[EventSpectrum]:
    """Normalised DFT of each free-decay segment of `x` (n_samples, n_channels)."""
    out = []
    for start, stop in starts_stops:
        n = stop - start
        out.append(EventSpectrum(np.fft.rfft(x[start:stop], axis=0) / np.sqrt(n), n))
    return out


@dataclass
class _Band:
    """The bins of one event inside the band, with what the model needs about them."""

    dft: np.ndarray  # (m, C)
    phase: np.ndarray  # 2πk/N of the bins
    n_samples: int
    background: np.ndarray  # (m, q): fixed columns (neighbours, constant, slope)
    offset: np.ndarray  # (f − centre) / half-width of the bins


def _bands(spectra, f_centre, half_width, dt, neighbours) -> list[_Band]:
    bands = []
    for spec in spectra:
        n = spec.n_samples
        df = 1.0 / (n * dt)
        k = np.arange(
            max(1, int(np.ceil((f_centre - half_width) / df))), int(np.floor((f_centre + half_width) / df)) + 1
        )
        k = k[k < spec.dft.shape[0]]
        phase = 2 * np.pi * k / n
        offset = (k * df - f_centre) / half_width
        columns = [_pole_column(_pole(fj, sj, dt), phase, n) for fj, sj in neighbours]
        columns += [np.ones(k.size, complex), offset.astype(complex)]
        bands.append(_Band(spec.dft[k], phase, n, np.column_stack(columns), offset))
    return bands


def _pole(frequency: float, decay_rate: float, dt: float) -> complex:
    """z = s Δt for the pole s = −σ + i 2π f."""
    return complex(-decay_rate * dt, 2 * np.pi * frequency * dt)


def _pole_column(z: complex, phase: np.ndarray, n: int) -> np.ndarray:
    den = np.expm1(z - 1j * phase)
    den = np.where(np.abs(den) < 1e-300, 1e-300, den)
    return np.expm1(n * z) / den / np.sqrt(n)


def _pole_derivative(z: complex, phase: np.ndarray, n: int) -> np.ndarray:
    """d g / d z for g = expm1(N z) / expm1(z − iφ) / √N."""
    num = np.expm1(n * z)
    den = np.expm1(z - 1j * phase)
    return (n * np.exp(n * z) * den - num * np.exp(z - 1j * phase)) / den**2 / np.sqrt(n)


@dataclass
class _State:
    cost: float
    residuals: list  # per band (m, C)
    coefficients: list  # per band (p, C)
    jacobian: list  # per band (m, C, 2) projected derivative columns


def _evaluate(theta: np.ndarray, bands: list[_Band], dt: float, weights: np.ndarray, with_jacobian: bool) -> _State:
    z = _pole(theta[0], theta[1], dt)
    dz = np.array([2j * np.pi * dt, -dt])  # dz/df, dz/dσ
    cost = 0.0
    residuals, coefficients, jacobian = [], [], []
    for band in bands:
        g = _pole_column(z, band.phase, band.n_samples)
        basis = np.column_stack([g, band.background])
        q, r = np.linalg.qr(basis)
        coef = np.linalg.solve(r, q.conj().T @ band.dft)
        res = band.dft - basis @ coef
        cost += float((np.abs(res) ** 2 * weights).sum())
        residuals.append(res)
        coefficients.append(coef)
        if with_jacobian:
            dg = _pole_derivative(z, band.phase, band.n_samples)
            cols = []
            for d in dz:
                v = (dg * d)[:, None] * coef[0][None, :]
                cols.append(v - q @ (q.conj().T @ v))
            jacobian.append(np.stack(cols, axis=-1))
    return _State(cost, residuals, coefficients, jacobian)


def _normal_equations(state: _State, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Fisher-type matrix Re Σ w J^H J and right-hand side Re Σ w J^H r (J = projected ∂(b g)/∂θ)."""
    jtj = np.zeros((2, 2))
    jtr = np.zeros(2)
    for jac, res in zip(state.jacobian, state.residuals):
        wj = jac * weights[None, :, None]
        jtj += np.real(np.einsum("mci,mcj->ij", wj.conj(), jac))
        jtr += np.real(np.einsum("mci,mc->i", wj.conj(), res))
    return jtj, jtr


def _levenberg_marquardt(theta, bands, dt, weights, limits, max_iterations: int) -> tuple[np.ndarray, _State, bool]:
    state = _evaluate(theta, bands, dt, weights, with_jacobian=True)
    n_data = sum(b.dft.size for b in bands)
    mu = 1e-3
    for _ in range(max_iterations):
        jtj, jtr = _normal_equations(state, weights)
        scale = np.sqrt(np.maximum(np.diag(jtj), np.finfo(float).tiny))
        step = np.linalg.solve(jtj / np.outer(scale, scale) + mu * np.eye(2), jtr / scale) / scale
        # Converged when the Gauss-Newton step is far below the statistical uncertainty.
        if mu <= 1e-3 and np.all(np.abs(step) * scale < 1e-4 * np.sqrt(state.cost / n_data)):
            return theta, state, True
        trial = theta + step
        inside = limits[0][0] < trial[0] < limits[0][1] and limits[1][0] < trial[1] < limits[1][1]
        new = _evaluate(trial, bands, dt, weights, with_jacobian=True) if inside else None
        if new is not None and new.cost <= state.cost:
            theta, state = trial, new
            mu = max(mu / 10.0, 1e-9)
        else:
            mu *= 10.0
            if mu > 1e8:
                # No step lowers the cost: a minimum, unless the steps were pushing out of the limits.
                return theta, state, inside
    return theta, state, False


def _noise_variance(state: _State, n_params: int) -> np.ndarray:
    """Per-channel complex noise variance per bin, pooled over events."""
    rss = sum((np.abs(res) ** 2).sum(axis=0) for res in state.residuals)
    dof = sum(max(res.shape[0] - n_params, 1) for res in state.residuals)
    return np.maximum(rss / dof, np.finfo(float).tiny)


def _initial_decay_rate(f0, bands, dt, weights, sigma_limits, damping_grid) -> float:
    best, best_cost = 0.0, np.inf
    for zeta in damping_grid:
        sigma = zeta * 2 * np.pi * f0
        if not sigma_limits[0] < sigma < sigma_limits[1]:
            continue
        cost = _evaluate(np.array([f0, sigma]), bands, dt, weights, with_jacobian=False).cost
        if cost < best_cost:
            best, best_cost = sigma, cost
    return best


@one_blas_thread
def fit_decay(
    spectra: list[EventSpectrum],
    sampling_rate: float,
    f_initial: float,
    half_width: float,
    neighbours: list[tuple[float, float]] = (),
    max_damping: float = 0.2,
    min_damping: float = 0.0,
    options: FitOptions | None = None,
) -> DecayFit | None:
    """Fit one mode (common f, σ) to the band [f_initial ± half_width] of the free-decay DFTs.

    Parameters
    ----------
    spectra : list of EventSpectrum
        One per event.
    sampling_rate : float
        Hz.
    f_initial : float
        Starting frequency (the overview peak), Hz.
    half_width : float
        Half-width of the band of bins used, Hz.
    neighbours : list of (frequency, decay rate)
        Nearby modes whose tails cross the band, modelled with fixed poles.
    max_damping : float
        Upper bound on ζ during the search.
    min_damping : float
        Lower bound on ζ (0: a slightly growing pole is allowed, so that an
        undamped line is fitted without a bound in the way).
    options : FitOptions, optional
        Iterations, the start's ζ grid and the events' agreement test
        (default: the calibrated values).

    Returns
    -------
    DecayFit or None
        None when the fit leaves the band or the information matrix is singular.
    """
    options = FitOptions() if options is None else options
    iterations = options.decay_max_iterations
    dt = 1.0 / sampling_rate
    all_bands = _bands(spectra, f_initial, half_width, dt, neighbours)
    used = [b.dft.shape[0] > b.background.shape[1] + 2 for b in all_bands]
    bands = [b for b, u in zip(all_bands, used) if u]
    if not bands:
        return None
    n_channels = bands[0].dft.shape[1]
    n_params = bands[0].background.shape[1] + 1
    sigma_max = min(2 * np.pi * half_width, max_damping * 2 * np.pi * f_initial)
    sigma_min = min_damping * 2 * np.pi * f_initial if min_damping > 0 else -0.05 * sigma_max
    limits = ((f_initial - half_width, f_initial + half_width), (sigma_min, sigma_max))
    weights = np.ones(n_channels)
    start = _initial_decay_rate(f_initial, bands, dt, weights, limits[1], options.decay_start_damping)
    theta = np.array([f_initial, start])
    theta, state, ok = _levenberg_marquardt(theta, bands, dt, weights, limits, iterations)
    noise_var = _noise_variance(state, n_params)
    weights = 1.0 / noise_var
    theta, state, ok = _levenberg_marquardt(theta, bands, dt, weights, limits, iterations)
    noise_var = _noise_variance(state, n_params)
    weights = 1.0 / noise_var
    try:
        cov, forced_ratio, state = _covariance(theta, bands, dt, weights)
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(cov)) or cov[0, 0] <= 0 or cov[1, 1] <= 0:
        return None
    event_f = np.full(len(all_bands), np.nan) if len(spectra) > 1 else np.zeros(0)
    event_v = event_f.copy()
    if len(bands) > 1:
        event_f[np.flatnonzero(used)], event_v[np.flatnonzero(used)] = _event_estimates(theta, bands, dt, weights,
                                                                                        limits, iterations)
        cov[0, 0] += between_events_addition(event_f, event_v, cov[0, 0], options.heterogeneity_level)
    fit = _result(theta, cov, state, bands, dt, noise_var, ok, forced_ratio)
    return replace(fit, event_frequencies=event_f, event_variances=event_v)


def _covariance(theta, bands: list[_Band], dt: float, weights: np.ndarray) -> tuple[np.ndarray, float, _State]:
    """Covariance of (f_d, σ) at ``theta`` under the band noise model, the forced ratio (:mod:`.decay_covariance`), the state."""
    state = _evaluate(theta, bands, dt, weights, with_jacobian=True)
    jtj, _ = _normal_equations(state, weights)
    z = _pole(theta[0], theta[1], dt)
    columns = [_pole_column(z, band.phase, band.n_samples) for band in bands]
    return (*forced_response_covariance(z, columns, state, bands, weights, jtj), state)


def _event_estimates(theta, bands: list[_Band], dt: float, weights: np.ndarray, limits,
                     max_iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """Each band's own fit of the mode from the joint one: f_d (Hz) and its variance (NaN where it fails)."""
    f, v = np.full(len(bands), np.nan), np.full(len(bands), np.nan)
    for i, band in enumerate(bands):
        try:
            t, _, ok = _levenberg_marquardt(theta.copy(), [band], dt, weights, limits, max_iterations)
            if not ok:
                continue
            c, _, _ = _covariance(t, [band], dt, weights)
        except np.linalg.LinAlgError:
            continue
        if np.isfinite(c[0, 0]) and c[0, 0] > 0:
            f[i], v[i] = t[0], c[0, 0]
    return f, v


def _independent_channels(state: _State, noise_var: np.ndarray) -> float:
    """(tr R)² / ||R||_F² of the whitened residual covariance R between channels: C for independent noise, 1 if common."""
    white = np.concatenate([res / np.sqrt(noise_var) for res in state.residuals])
    if white.shape[1] == 1:
        return 1.0
    cov = white.T @ white.conj() / white.shape[0]
    # Remove the sampling bias of ||R||² (complex Wishart with m bins): E||R̂||² = ||R||² + (tr R)² / m.
    frob = max(
        np.sum(np.abs(cov) ** 2) - np.real(np.trace(cov)) ** 2 / white.shape[0],
        np.real(np.trace(cov)) ** 2 / white.shape[1],
    )
    return float(np.clip(np.real(np.trace(cov)) ** 2 / frob, 1.0, white.shape[1]))


def _residual_excess(state: _State, bands: list[_Band], noise_var: np.ndarray) -> float:
    inner, outer = [], []
    for band, res in zip(bands, state.residuals):
        power = (np.abs(res) ** 2 / noise_var).sum(axis=1)
        offset = np.abs(band.offset)
        inner.append(power[offset < 1 / 3])
        outer.append(power[offset >= 1 / 3])
    inner, outer = np.concatenate(inner), np.concatenate(outer)
    if inner.size == 0 or outer.size == 0:
        return 1.0
    return float(inner.mean() / max(outer.mean(), np.finfo(float).tiny))


def pole_statistics(f_d: float, sigma: float, cov: np.ndarray) -> tuple[float, float, float, float]:
    """(f_n, 1σ, ζ, 1σ) of the pole s = −σ + i2πf_d from the covariance of (f_d, σ), by the delta method.

    f_n = |s| / 2π = sqrt(f_d² + (σ/2π)²) and ζ = σ / |s|.
    """
    omega_n = np.hypot(2 * np.pi * f_d, sigma)
    f_n = omega_n / (2 * np.pi)
    grad_f = np.array([f_d, sigma / (2 * np.pi) ** 2]) / f_n
    grad_zeta = np.array([-sigma * (2 * np.pi) ** 2 * f_d, (2 * np.pi * f_d) ** 2]) / omega_n**3
    return (
        float(f_n),
        float(np.sqrt(grad_f @ cov @ grad_f)),
        float(sigma / omega_n),
        float(np.sqrt(grad_zeta @ cov @ grad_zeta)),
    )


def _result(theta, cov, state, bands, dt, noise_var, ok, forced_ratio=0.0) -> DecayFit:
    f_d, sigma = theta
    f_n, f_std, zeta, zeta_std = pole_statistics(f_d, sigma, cov)
    z = _pole(f_d, sigma, dt)
    amplitude = np.array([2.0 * c[0] for c in state.coefficients])  # b → real amplitude A e^{iφ}
    peak_power = []
    chi2 = 0.0
    for band, coef in zip(bands, state.coefficients):
        g = _pole_column(z, band.phase, band.n_samples)
        k = int(np.argmax(np.abs(g)))
        peak_power.append(np.abs(coef[0] * g[k]) ** 2)
        r = np.linalg.qr(np.column_stack([g, band.background]), mode="r")
        unit_var = np.sum(np.abs(np.linalg.inv(r)[0]) ** 2)  # [(Φ^H Φ)^-1]_00
        chi2 += float(np.sum(np.abs(coef[0]) ** 2 / (unit_var * noise_var)))
    snr = 10 * np.log10(1.0 + np.max(peak_power, axis=0) / noise_var)
    # Channels count as independent only as far as their residuals are (a random response is common to all).
    independent = _independent_channels(state, noise_var)
    n_amplitudes = 2 * len(bands) * independent
    chi2 *= independent / noise_var.size
    significance = min(float(stats.norm.isf(max(stats.chi2.sf(2 * chi2, n_amplitudes), 1e-300))), 40.0)
    return DecayFit(
        frequency=f_n,
        frequency_std=f_std,
        decay_rate=float(sigma),
        decay_rate_std=float(np.sqrt(cov[1, 1])),
        damping=zeta,
        damping_std=zeta_std,
        amplitude=amplitude,
        noise_std=np.sqrt(noise_var),
        channel_snr_db=snr,
        residual_excess=_residual_excess(state, bands, noise_var),
        significance=significance,
        converged=bool(ok),
        forced_ratio=float(forced_ratio),
    )
