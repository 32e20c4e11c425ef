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
    (:func:`_forced_response_covariance`); it reduces to the bound when
    M = 0. White-noise Fisher σ under light wind was up to 6 times too
    small (benchmarks/calibrate_spectra.py).

Reported frequency
    The undamped natural frequency f_n = |s| / 2π of the pole s = −σ + i2πf_d,
    with ζ = σ / (2π f_n).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, stats

__all__ = ["DecayFit", "EventSpectrum", "event_spectra", "fit_decay", "pole_statistics"]

MAX_ITERATIONS = 40
HETEROGENEITY_LEVEL = 0.05  # Cochran's Q test of the events' agreement before a between-event variance is added
DAMPING_GRID = np.concatenate([[0.0], np.logspace(-4.5, -1.0, 15)])


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
        of its free decay, both in noise units (:func:`_noise_model`): about
        0 for a clean decay, above 1 where ambient loading rather than the
        blows makes the peak.
    significance : float
        The mode's amplitudes against their noise, Λ = Σ |b|² / var(b) over
        channels and events, as the equivalent one-sided Gaussian z (about
        0–3 where no mode is present; capped at 40). Channels count only
        as far as their residuals are independent (a random response
        common to all channels is one observation, not C).
    converged : bool
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


def _levenberg_marquardt(theta, bands, dt, weights, limits) -> tuple[np.ndarray, _State, bool]:
    state = _evaluate(theta, bands, dt, weights, with_jacobian=True)
    n_data = sum(b.dft.size for b in bands)
    mu = 1e-3
    for _ in range(MAX_ITERATIONS):
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


def _initial_decay_rate(f0, bands, dt, weights, sigma_limits) -> float:
    best, best_cost = 0.0, np.inf
    for zeta in DAMPING_GRID:
        sigma = zeta * 2 * np.pi * f0
        if not sigma_limits[0] < sigma < sigma_limits[1]:
            continue
        cost = _evaluate(np.array([f0, sigma]), bands, dt, weights, with_jacobian=False).cost
        if cost < best_cost:
            best, best_cost = sigma, cost
    return best


def fit_decay(
    spectra: list[EventSpectrum],
    sampling_rate: float,
    f_initial: float,
    half_width: float,
    neighbours: list[tuple[float, float]] = (),
    max_damping: float = 0.2,
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

    Returns
    -------
    DecayFit or None
        None when the fit leaves the band or the information matrix is singular.
    """
    dt = 1.0 / sampling_rate
    bands = [
        b for b in _bands(spectra, f_initial, half_width, dt, neighbours) if b.dft.shape[0] > b.background.shape[1] + 2
    ]
    if not bands:
        return None
    n_channels = bands[0].dft.shape[1]
    n_params = bands[0].background.shape[1] + 1
    sigma_max = min(2 * np.pi * half_width, max_damping * 2 * np.pi * f_initial)
    limits = ((f_initial - half_width, f_initial + half_width), (-0.05 * sigma_max, sigma_max))
    weights = np.ones(n_channels)
    theta = np.array([f_initial, _initial_decay_rate(f_initial, bands, dt, weights, limits[1])])
    theta, state, ok = _levenberg_marquardt(theta, bands, dt, weights, limits)
    noise_var = _noise_variance(state, n_params)
    weights = 1.0 / noise_var
    theta, state, ok = _levenberg_marquardt(theta, bands, dt, weights, limits)
    noise_var = _noise_variance(state, n_params)
    weights = 1.0 / noise_var
    state = _evaluate(theta, bands, dt, weights, with_jacobian=True)
    jtj, _ = _normal_equations(state, weights)
    try:
        cov, forced_ratio = _forced_response_covariance(theta, state, bands, dt, weights, jtj)
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(cov)) or cov[0, 0] <= 0 or cov[1, 1] <= 0:
        return None
    cov[0, 0] += _between_events_variance(theta, bands, dt, weights, limits, cov[0, 0])
    return _result(theta, cov, state, bands, dt, noise_var, ok, forced_ratio)


def _between_events_variance(theta, bands: list[_Band], dt: float, weights: np.ndarray, limits,
                             joint_variance: float) -> float:
    """What to add to the joint fit's frequency variance for the events' disagreement (0 with one event).

    The tension, and with it every frequency, wanders within a record
    (temperature, traffic): blows minutes apart ring at frequencies that
    differ by more than their noise, and the record's mean frequency is
    known only as well as their scatter allows. Each event is fitted on
    its own (its sandwich 1σ v_i); the between-event variance τ² is the
    DerSimonian–Laird moment estimate from their weighted scatter, taken
    only where Cochran's Q shows the events disagree (level
    HETEROGENEITY_LEVEL: without the test, chance scatter of two or three
    clean events made their σ too large, 78–88 % within 1σ), and the
    joint estimate is given the random-effects variance of the mean,
    1 / Σ 1/(v_i + τ²), where that exceeds its own.
    """
    if len(bands) < 2:
        return 0.0
    f, v = [], []
    for band in bands:
        try:
            t, st, ok = _levenberg_marquardt(theta.copy(), [band], dt, weights, limits)
            if not ok:
                continue
            st = _evaluate(t, [band], dt, weights, with_jacobian=True)
            jtj, _ = _normal_equations(st, weights)
            c, _ = _forced_response_covariance(t, st, [band], dt, weights, jtj)
        except np.linalg.LinAlgError:
            continue
        if np.isfinite(c[0, 0]) and c[0, 0] > 0:
            f.append(t[0])
            v.append(c[0, 0])
    if len(f) < 2:
        return 0.0
    f, w = np.array(f), 1.0 / np.array(v)
    mean = np.sum(w * f) / np.sum(w)
    q = float(np.sum(w * (f - mean) ** 2))
    if q <= stats.chi2.isf(HETEROGENEITY_LEVEL, len(f) - 1):
        return 0.0  # the events agree within their noise (DerSimonian–Laird alone inflates clean records)
    tau2 = (q - (len(f) - 1)) / (np.sum(w) - np.sum(w**2) / np.sum(w))
    return max(0.0, 1.0 / float(np.sum(1.0 / (np.array(v) + tau2))) - joint_variance)


def _stationary_shape(z: complex, phase: np.ndarray, n: int) -> np.ndarray:
    """Expected |X[k]|² (up to scale) of the mode's stationary random response in an N-sample segment.

    Re(2G(u) − 1), u = exp(z − iφ), G(u) = Σ_{τ<N} (1 − τ/N) u^τ: the
    Lorentzian of the pole convolved with the segment's Fejér kernel (the
    debiased Whittle mean of :mod:`.ambient_fit`, its dispersive part left out).
    """
    log_u = z - 1j * phase
    u = np.exp(log_u)
    one_minus = -np.expm1(log_u)
    g = 1.0 / one_minus - u * (-np.expm1(n * log_u)) / (n * one_minus**2)
    return np.maximum(np.real(2.0 * g - 1.0), 0.0)


def _noise_model(theta, state: _State, bands: list[_Band], dt: float) -> tuple[np.ndarray, np.ndarray, list]:
    """White floor n_c and forced-response matrix M (C × C) of the band noise Σ_k = diag(n) + L_k M.

    Ambient loading that goes on under a decay leaves, besides the sensor
    noise, the mode's own random response: a Lorentzian L_k of the fitted
    pole in every channel, common to all (M is the cross-spectral matrix
    of that response, rank one for one mode). Both are estimated from the
    residuals by moments that allow for what the fit removed: the
    residual of bin k has E|r_kc|² = n_c (1 − h_k) + M_cc Σ_j |(I − P)_kj|² L_j
    (P the projection on the model's linear columns), and its
    cross-products between channels only the second term. M is then
    projected on the positive semi-definite matrices.
    """
    z = _pole(theta[0], theta[1], dt)
    lev, lor, res_all, shapes = [], [], [], []
    for band, res in zip(bands, state.residuals):
        basis = np.column_stack([_pole_column(z, band.phase, band.n_samples), band.background])
        q, _ = np.linalg.qr(basis)
        complement = np.eye(q.shape[0]) - q @ q.conj().T
        shape = _stationary_shape(z, band.phase, band.n_samples)
        lev.append(np.real(np.diag(complement)))
        lor.append((np.abs(complement) ** 2) @ shape)
        res_all.append(res)
        shapes.append(shape)
    a, b, r = np.concatenate(lev), np.concatenate(lor), np.concatenate(res_all)
    n_channels = r.shape[1]
    power = np.abs(r) ** 2
    floor, forced = np.zeros(n_channels), np.zeros(n_channels)
    design = np.column_stack([a, b])
    for c in range(n_channels):
        # Moments weighted by the inverse expected power (|r|² scatters in proportion to its mean).
        weight = np.ones(a.size)
        for _ in range(3):
            coef, _ = optimize.nnls(design * weight[:, None], power[:, c] * weight)
            expected = design @ coef
            weight = 1.0 / np.maximum(expected, 1e-12 * max(expected.max(), np.finfo(float).tiny))
        floor[c], forced[c] = coef
    matrix = np.diag(forced).astype(complex)
    if n_channels > 1 and np.any(forced > 0):
        weight = b / np.maximum(a * floor.mean() + b * forced.mean(), np.finfo(float).tiny) ** 2
        cross = (r * (weight * b)[:, None]).T @ r.conj() / max(float(np.sum(weight * b * b)), np.finfo(float).tiny)
        matrix = cross.copy()
        matrix[np.diag_indices(n_channels)] = forced
        values, vectors = np.linalg.eigh(0.5 * (matrix + matrix.conj().T))
        matrix = (vectors * np.maximum(values, 0.0)) @ vectors.conj().T
    # A floor the forced term explains away entirely is still not zero (the ratios below divide by it).
    floor = np.maximum(floor, 1e-9 * power.mean(axis=0) + np.finfo(float).tiny)
    return floor, matrix, shapes


def _forced_response_covariance(theta, state: _State, bands: list[_Band], dt: float, weights: np.ndarray,
                                jtj: np.ndarray) -> tuple[np.ndarray, float]:
    """Covariance of (f_d, σ) under the band noise diag(n) + L_k M (:func:`_noise_model`), and the forced ratio.

    The estimate solves Re Σ_k J_kᴴ W r_k = 0, so to first order its
    covariance is the sandwich F⁻¹ (½ Re Σ_k J_kᴴ W Σ_k W J_k) F⁻¹ with
    F = Re Σ J^H W J: (2F)⁻¹, the Fisher information's bound, when the
    noise is white and independent between channels (M = 0), larger when
    a random response of the mode sits under the decay (it is coloured,
    concentrated where the frequency is decided, and common to all
    channels). The forced ratio is Σ L_k tr(M N⁻¹) over Σ |g_k|² bᴴ N⁻¹ b
    (N = diag(n)): the random response's power in the band over the decay's.
    """
    floor, matrix, shapes = _noise_model(theta, state, bands, dt)
    z = _pole(theta[0], theta[1], dt)
    forced_power = sum(float(shape.sum()) for shape in shapes) * float(np.sum(np.real(np.diag(matrix)) / floor))
    decay_power = sum(float(np.sum(np.abs(_pole_column(z, band.phase, band.n_samples)) ** 2))
                      * float(np.sum(np.abs(coef[0]) ** 2 / floor)) for band, coef in zip(bands, state.coefficients))
    meat = np.zeros((2, 2))
    for jac, shape in zip(state.jacobian, shapes):
        wj = jac * weights[None, :, None]  # (m, C, 2)
        white = np.einsum("mci,c,mcj->ij", wj.conj(), floor, wj)
        forced = np.einsum("m,mci,cd,mdj->ij", shape, wj.conj(), matrix, wj)
        meat += 0.5 * np.real(white + forced)
    inverse = np.linalg.inv(jtj)
    return inverse @ meat @ inverse, forced_power / max(decay_power, np.finfo(float).tiny)


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
