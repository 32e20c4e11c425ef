"""Exact response of modal coordinates to impulses and to held random forces.

The kernels behind :func:`~stcs_ident.simulate.simulate.simulate_record`.
Each mode is an SDOF q̈ + 2ζω q̇ + ω² q = f(t) with unit modal mass; the
response is computed without time-stepping error:

- after an impulse, q is a damped sinusoid evaluated in closed form;
- a force held constant over each sampling interval (zero-order hold) is
  propagated by the exact state-transition matrix of each SDOF, written as
  a second-order IIR filter from f[n] to the sampled acceleration q̈[n];
- the start state is drawn from the recursion's stationary covariance
  (discrete Lyapunov equation), so a record has no start-up transient.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from scipy.linalg import expm, solve_discrete_lyapunov
from scipy.signal import lfilter

from ..forward.shapes import ModeShapes

__all__ = [
    "acceleration_filters", "impulse_acceleration", "matrix_sqrt", "modal_force_covariance",
    "stationary_covariance", "superpose", "zoh_transition",
]

_BLOCK = 16384  # samples per block: bounds memory to BLOCK × n_modes
_GRID_CHUNK = 8192
_DECAYED = 40.0  # ζωτ beyond which an impulse response is below double rounding (e^-40 = 4e-18)


def modal_force_covariance(shapes: ModeShapes, rms_pressure: float, correlation_length: float | None, *,
                           length: float, wave_speed: float, uncorrelated_length: float) -> np.ndarray:
    """E[f fᵀ] (N²) of the generalised forces f_k = ∫ φ_k p dx of one held sample.

    Parameters
    ----------
    shapes : ModeShapes
        Mass-normalised modes.
    rms_pressure : float
        σ, N/m (see ``correlation_length``).
    correlation_length : float or None
        L, m. None: uncorrelated, E[p(x) p(x')] = σ² ℓ δ(x − x') with
        ℓ = ``uncorrelated_length``, giving σ² ℓ ∫φ_k φ_j dx. Otherwise
        σ² ∫∫ φ_k(x) e^{−|x−x'|/L} φ_j(x') dx dx', on a grid that resolves
        both L and the shortest wavelength; an L below 1/200 of the
        shortest wavelength is taken in its white limit (2L σ² δ), exact to
        about (2π/200)² = 0.1 %.
    length : float
        Span, m.
    wave_speed : float
        √(H/m), m/s: the shortest wavelength is the string's at the highest
        frequency (bending only lengthens it).
    uncorrelated_length : float
        ℓ, m.
    """
    sigma2 = rms_pressure**2
    L = correlation_length
    if L is None:
        return sigma2 * uncorrelated_length * _gram(shapes)
    wavelength = wave_speed / shapes.frequencies[-1]
    if L < wavelength / 200:
        return sigma2 * 2 * L * _gram(shapes)
    return sigma2 * exponential_gram(shapes, length, L, min(L / 8, wavelength / 40))


def _gram(shapes: ModeShapes) -> np.ndarray:
    x, w = shapes.quadrature()
    phi = shapes(x)
    return (phi * w[:, None]).T @ phi


def exponential_gram(shapes: ModeShapes, length: float, L: float, spacing: float) -> np.ndarray:
    """Σ_ij v_i v_jᵀ e^{−|x_i−x_j|/L} on a uniform trapezoid grid, v_i = w_i φ(x_i).

    On a uniform grid the lower-triangular sum S_i = Σ_{j≤i} e^{−(x_i−x_j)/L} v_j
    is a first-order recursion (a one-pole filter), so the double sum costs
    O(n) instead of O(n²); the full sum is F + Fᵀ − diagonal.
    """
    n = max(math.ceil(length / spacing), 2) + 1
    x = np.linspace(0.0, length, n)
    h = x[1] - x[0]
    w = np.full(n, h)
    w[[0, -1]] = h / 2
    decay = math.exp(-h / L)
    N = len(shapes.frequencies)
    F = np.zeros((N, N))
    D = np.zeros((N, N))
    zi = np.zeros((1, N))
    for start in range(0, n, _GRID_CHUNK):
        sel = slice(start, min(start + _GRID_CHUNK, n))
        v = shapes(x[sel]) * w[sel, None]
        S, zi = lfilter([1.0], [1.0, -decay], v, axis=0, zi=zi)
        F += v.T @ S
        D += v.T @ v
    return F + F.T - D


def matrix_sqrt(C: np.ndarray) -> np.ndarray:
    """The principal square root R = V √Λ Vᵀ of a symmetric positive semi-definite C (R Rᵀ = C).

    Of all the factors with R Rᵀ = C this one is unique, so a seeded record is the same on every machine.
    The factor V √Λ alone is not: the sign of each eigenvector (and the basis of a repeated eigenvalue) is
    LAPACK's choice, which changes with the BLAS kernel the CPU selects, and the same seeded white noise
    then made another wind (a record differed by 0.013 m/s² in 8 when OpenBLAS ran its Haswell kernel).
    """
    lam, V = np.linalg.eigh(0.5 * (C + C.T))
    return (V * np.sqrt(np.clip(lam, 0.0, None))) @ V.T


def zoh_transition(omega: np.ndarray, zeta: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact one-step matrices of each SDOF under a force held over the step.

    State (q, q̇): s[n+1] = Ad s[n] + Bd f[n], from the exponential of the
    augmented matrix [[A, B], [0, 0]] dt. Returns Ad (N, 2, 2), Bd (N, 2).
    """
    M = np.zeros((len(omega), 3, 3))
    M[:, 0, 1] = 1.0
    M[:, 1, 0] = -(omega**2)
    M[:, 1, 1] = -2 * zeta * omega
    M[:, 1, 2] = 1.0
    E = expm(M * dt)
    return E[:, :2, :2], E[:, :2, 2]


def acceleration_filters(Ad: np.ndarray, Bd: np.ndarray, omega: np.ndarray,
                         zeta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """IIR coefficients (b, a) from a held force to the sampled modal acceleration.

    q̈[n] = C s[n] + f[n] with C = (−ω², −2ζω); the transfer function is
    C (zI − Ad)⁻¹ Bd + 1, written out for 2 × 2 blocks. Returns b (N, 3),
    a (N, 3) and the (N, 2, 2) map from a state s to lfilter's ``zi``.
    """
    C = np.stack([-(omega**2), -2 * zeta * omega], axis=1)
    tr = Ad[:, 0, 0] + Ad[:, 1, 1]
    det = Ad[:, 0, 0] * Ad[:, 1, 1] - Ad[:, 0, 1] * Ad[:, 1, 0]
    adj = np.stack([np.stack([-Ad[:, 1, 1], Ad[:, 0, 1]], 1), np.stack([Ad[:, 1, 0], -Ad[:, 0, 0]], 1)], 1)
    cb = np.einsum("ni,ni->n", C, Bd)
    cmb = np.einsum("ni,nij,nj->n", C, adj, Bd)
    b = np.stack([np.ones_like(tr), cb - tr, cmb + det], axis=1)
    a = np.stack([np.ones_like(tr), -tr, det], axis=1)
    # lfilter's (transposed direct form II) state that reproduces state s: zi = (C s, C (Ad − tr I) s)
    to_zi = np.stack([C, np.einsum("ni,nij->nj", C, Ad) - tr[:, None] * C], axis=1)
    return b, a, to_zi


def stationary_covariance(Ad: np.ndarray, Bd: np.ndarray, force_cov: np.ndarray) -> np.ndarray:
    """Stationary covariance (2N × 2N, states ordered q1, q̇1, q2, ...) of the held-force recursion."""
    N = len(Ad)
    A = np.zeros((2 * N, 2 * N))
    B = np.zeros((2 * N, N))
    for k in range(N):
        A[2 * k:2 * k + 2, 2 * k:2 * k + 2] = Ad[k]
        B[2 * k:2 * k + 2, k] = Bd[k]
    P = solve_discrete_lyapunov(A, B @ force_cov @ B.T)
    return 0.5 * (P + P.T)


def superpose(shapes: ModeShapes, zeta: np.ndarray, sampling_rate: float, n_samples: int, positions: np.ndarray,
              kicks: Sequence[tuple[float, np.ndarray]], force_sqrt: np.ndarray | None, rng: np.random.Generator,
              progress: Callable[[int, int], None] | None = None) -> np.ndarray:
    """Noise-free acceleration (n_samples, n_positions) by modal superposition.

    Parameters
    ----------
    shapes, zeta :
        Modes and their damping ratios.
    sampling_rate, n_samples :
        Hz; samples at t = n / sampling_rate.
    positions : ndarray
        Sensor positions, m.
    kicks : sequence of (time, modal velocity)
        Impulses as the modal velocities φ_k(x₀) J they start at ``time``.
    force_sqrt : ndarray (N, N) or None
        R with R Rᵀ = E[f fᵀ], the held modal forces' covariance; None for
        no random force (``rng`` is then not used).
    progress : callable(done, total), optional
        Called after each block of samples.
    """
    omega = 2 * math.pi * np.asarray(shapes.frequencies)
    dt = 1.0 / sampling_rate
    phi_sensors = shapes(positions)  # (n_channels, N)
    N = len(omega)
    if force_sqrt is not None:
        Ad, Bd = zoh_transition(omega, zeta, dt)
        b, a, to_zi = acceleration_filters(Ad, Bd, omega, zeta)
        P = stationary_covariance(Ad, Bd, force_sqrt @ force_sqrt.T)
        s0 = (matrix_sqrt(P) @ rng.standard_normal(2 * N)).reshape(N, 2)
        zi = np.einsum("nij,nj->ni", to_zi, s0)
    out = np.empty((n_samples, len(positions)))
    for start in range(0, n_samples, _BLOCK):
        stop = min(start + _BLOCK, n_samples)
        t = np.arange(start, stop) * dt
        modal = np.zeros((stop - start, N))
        if force_sqrt is not None:
            force = rng.standard_normal((stop - start, N)) @ force_sqrt.T
            for k in range(N):
                modal[:, k], zi[k] = lfilter(b[k], a[k], force[:, k], zi=zi[k])
        for t0, velocity in kicks:
            modal += impulse_acceleration(t - t0, omega, zeta, velocity)
        out[start:stop] = modal @ phi_sensors.T
        if progress is not None:
            progress(stop, n_samples)
    return out


def impulse_acceleration(tau: np.ndarray, omega: np.ndarray, zeta: np.ndarray, amplitude: np.ndarray) -> np.ndarray:
    """Modal accelerations (len(tau), N) at times ``tau`` after an impulse.

    Unit modal mass, q̇(0⁺) = A = ``amplitude`` (= φ_k(x₀) J): q = (A/ω_d) e^{−ζωτ} sin ω_d τ, so
    q̈ = (A/ω_d) e^{−ζωτ} [(ζ²ω² − ω_d²) sin ω_d τ − 2ζω ω_d cos ω_d τ] for τ ≥ 0
    (the Dirac at τ = 0 is not sampled), zero before.
    """
    out = np.zeros((len(tau), len(omega)))
    after = tau >= 0
    sigma = zeta * omega
    live = np.flatnonzero(sigma * max(float(np.min(tau, initial=np.inf)), 0.0) < _DECAYED)
    if not after.any() or live.size == 0:
        return out
    T = tau[after, None]
    sigma, omega, amplitude = sigma[live], omega[live], amplitude[live]
    wd = omega * np.sqrt(1 - zeta[live] ** 2)
    env = np.exp(-sigma * T) * (amplitude / wd)
    out[np.ix_(after, live)] = env * ((sigma**2 - wd**2) * np.sin(wd * T) - 2 * sigma * wd * np.cos(wd * T))
    return out

