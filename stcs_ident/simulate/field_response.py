"""Modal superposition under coloured loading and a drifting tension.

The kernel behind :func:`~stcs_ident.simulate.simulate.simulate_record`
when :class:`~stcs_ident.simulate.disturbances.FieldConditions` colour the
ambient loading or make the tension drift (otherwise
:func:`~stcs_ident.simulate.modal_response.superpose` is used, unchanged).
It works on the same exact pieces:

- the held modal forces are white, as there, then filtered in time by the
  loading's low-pass (lfilter, its state carried from sample to sample);
- each mode is advanced by its exact state-transition matrix over a
  segment of samples; the record starts from the stationary distribution
  of modes *and* filter together (one discrete Lyapunov equation);
- with a drift, each mode's frequency is held over segments of
  :data:`DRIFT_SEGMENT` s at its mean over the segment's samples, and the
  modal state (q, q̇) is carried across the steps: the record is the exact
  response of a cable whose stiffness changes in those steps, so the phase
  is continuous and advances by the integral of the instantaneous
  frequency: exactly over each segment (whose frequency is the mean of
  its samples' f_k[n], so the record's mean frequency is the mean of the
  f_k[n]), and within one by at most 2π ḟ T_s² / 8 rad, ḟ the frequency's
  rate of change (Hz/s): 2e-4 rad for a 20 Hz mode wandering by 1e-4 over
  a 60 s period;
- an impulse adds its closed-form damped sinusoid (at the segment's
  frequency) to the samples of its segment and its state (q, q̇) at the
  segment's end to the carried state; blows before the record start in the
  first segment.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from scipy.linalg import solve_discrete_lyapunov
from scipy.signal import lfilter

from ..forward.shapes import ModeShapes
from .disturbances import filter_state_space
from .modal_response import (
    acceleration_filters,
    impulse_acceleration,
    matrix_sqrt,
    stationary_covariance,
    zoh_transition,
)

__all__ = ["DRIFT_SEGMENT", "augmented_stationary_covariance", "impulse_state", "superpose_field"]

#: s: a drifting tension is held constant over segments this long.
DRIFT_SEGMENT = 1.0
_BLOCK = 16384  # samples per segment without drift (bounds memory, as in modal_response)


def superpose_field(shapes: ModeShapes, zeta: np.ndarray, sampling_rate: float, n_samples: int,
                    positions: np.ndarray, kicks: Sequence[tuple[float, np.ndarray]], force_sqrt: np.ndarray | None,
                    rng: np.random.Generator, *, force_filter: tuple[np.ndarray, np.ndarray] | None = None,
                    relative_tension: np.ndarray | None = None, sensitivities: np.ndarray | None = None,
                    progress: Callable[[int, int], None] | None = None) -> np.ndarray:
    """Noise-free acceleration (n_samples, n_positions) under coloured forces and/or a drifting tension.

    Parameters
    ----------
    shapes, zeta, sampling_rate, n_samples, positions, kicks, force_sqrt, rng, progress :
        As for :func:`~stcs_ident.simulate.modal_response.superpose`; the
        random draws are in the same order (start state, then the white
        forces sample by sample), so with neither a filter nor a drift the
        record is superpose's to round-off.
    force_filter : (b, a) or None
        IIR applied in time to every modal force (a[0] = 1); None: white.
    relative_tension : ndarray (n_samples,) or None
        d[n]: the tension is H (1 + d[n]) at sample n; None: constant.
    sensitivities : ndarray (N,)
        s_k = d ln f_k / d ln H (with ``relative_tension``): f_k(t) = f_k (1 + d)^s_k.
    """
    omega0 = 2 * math.pi * np.asarray(shapes.frequencies, dtype=float)
    zeta = np.asarray(zeta, dtype=float)
    dt = 1.0 / sampling_rate
    phi_sensors = shapes(positions)
    N = len(omega0)
    drifting = relative_tension is not None
    seg = max(1, min(round(DRIFT_SEGMENT * sampling_rate), _BLOCK)) if drifting else _BLOCK
    log1p_d = np.log1p(relative_tension) if drifting else None

    def omega_over(start, stop):
        if not drifting:
            return omega0
        return omega0 * np.mean(np.exp(np.outer(log1p_d[start:stop], sensitivities)), axis=0)

    state = np.zeros((N, 2))  # (q, q̇) of each mode at the segment's first sample
    filt_state = None
    omega = omega_over(0, min(seg, n_samples))
    if force_sqrt is not None:
        Ad, Bd = zoh_transition(omega, zeta, dt)
        C = force_sqrt @ force_sqrt.T
        if force_filter is None:
            P = stationary_covariance(Ad, Bd, C)
            state = (matrix_sqrt(P) @ rng.standard_normal(2 * N)).reshape(N, 2)
        else:
            b_f, a_f = force_filter
            m = len(a_f) - 1
            P = augmented_stationary_covariance(Ad, Bd, C, b_f, a_f)
            x = (matrix_sqrt(P) @ rng.standard_normal((2 + m) * N)).reshape(N, 2 + m)
            state, filt_state = x[:, :2].copy(), x[:, 2:].copy()

    order = sorted(range(len(kicks)), key=lambda i: kicks[i][0])
    next_kick = 0
    out = np.empty((n_samples, len(positions)))
    last_omega = None
    for start in range(0, n_samples, seg):
        stop = min(start + seg, n_samples)
        n = stop - start
        omega = omega_over(start, stop)
        if last_omega is None or not np.array_equal(omega, last_omega):
            Ad, Bd = zoh_transition(omega, zeta, dt)
            b, a, to_zi = acceleration_filters(Ad, Bd, omega, zeta)
            last_omega = omega
        if force_sqrt is not None:
            force = rng.standard_normal((n, N)) @ force_sqrt.T
            if force_filter is not None:
                for k in range(N):
                    force[:, k], filt_state[k] = lfilter(force_filter[0], force_filter[1], force[:, k],
                                                         zi=filt_state[k])
        else:
            force = np.zeros((n, N))
        modal = np.empty((n, N))
        zi = np.einsum("nij,nj->ni", to_zi, state)
        for k in range(N):
            modal[:, k], zi[k] = lfilter(b[k], a[k], force[:, k], zi=zi[k])
        state = np.linalg.solve(to_zi, zi[:, :, None])[:, :, 0]
        t = np.arange(start, stop) * dt
        t_next = stop * dt
        while next_kick < len(order) and kicks[order[next_kick]][0] <= t_next:
            t0, velocity = kicks[order[next_kick]]
            modal += impulse_acceleration(t - t0, omega, zeta, velocity)
            state += impulse_state(t_next - t0, omega, zeta, velocity)
            next_kick += 1
        out[start:stop] = modal @ phi_sensors.T
        if progress is not None:
            progress(stop, n_samples)
    return out


def impulse_state(tau: float, omega: np.ndarray, zeta: np.ndarray, amplitude: np.ndarray) -> np.ndarray:
    """(q, q̇) (N, 2) at ``tau`` >= 0 after an impulse giving q̇(0⁺) = ``amplitude`` (unit modal mass).

    q = (A/ω_d) e^{−στ} sin ω_d τ, q̇ = A e^{−στ} (cos ω_d τ − (σ/ω_d) sin ω_d τ).
    """
    sigma = zeta * omega
    wd = omega * np.sqrt(1 - zeta**2)
    env = amplitude * np.exp(-sigma * tau)
    s, c = np.sin(wd * tau), np.cos(wd * tau)
    return np.stack([env * s / wd, env * (c - sigma / wd * s)], axis=1)


def augmented_stationary_covariance(Ad: np.ndarray, Bd: np.ndarray, force_cov: np.ndarray, b: np.ndarray,
                                    a: np.ndarray) -> np.ndarray:
    """Stationary covariance of modes and force filters together, per mode (q, q̇, z₁..z_m), modes in turn.

    The white forces u (covariance ``force_cov``) pass each through the
    filter (b, a) in lfilter's transposed direct form II, state z:
    z' = A_f z + B_f u and f = z₁ + b₀ u, which drives the mode:
    s' = Ad s + Bd f = Ad s + Bd z₁ + Bd b₀ u.
    """
    N = len(Ad)
    Af, Bf = filter_state_space(np.asarray(b, float), np.asarray(a, float))
    m = len(Bf)
    w = 2 + m
    A = np.zeros((w * N, w * N))
    B = np.zeros((w * N, N))
    for k in range(N):
        i = w * k
        A[i:i + 2, i:i + 2] = Ad[k]
        A[i:i + 2, i + 2] = Bd[k]
        A[i + 2:i + w, i + 2:i + w] = Af
        B[i:i + 2, k] = Bd[k] * b[0]
        B[i + 2:i + w, k] = Bf
    P = solve_discrete_lyapunov(A, B @ force_cov @ B.T)
    return 0.5 * (P + P.T)
