"""Records of cables with dampers: complex modal superposition, exact in time.

The kernel behind :func:`~stcs_ident.simulate.simulate.simulate_record`
when the true attachments hold a :class:`~stcs_ident.core.model.Damper` (the
records of a cable without one are made by
:mod:`~stcs_ident.simulate.modal_response` and
:mod:`~stcs_ident.simulate.field_response`, unchanged). The complex modes
come from :func:`~stcs_ident.simulate.damped_modes.damped_modes`; each
modal coordinate obeys η̇_j = s_j η_j + u_j(t), u_j = q_jᵀ f the modal
force, and a sensor at x reads

    a(x, t) = Re Σ_j w_j φ_j(x) (s_j² η_j + s_j u_j)

(w_j = 2 for an oscillating mode, standing for its conjugate pair; 1 for
an overdamped one). As for the undamped records nothing is time-stepped
approximately:

- an impulse J at x₀ and t₀ adds φ_j(x₀) J e^{s_j (t − t₀)} to η_j after
  t₀, evaluated in closed form at the samples (and carried in the state);
- ambient pressure is held over each sampling interval (zero-order hold):
  η_j[n+1] = e^{s_j Δt} η_j[n] + (e^{s_j Δt} − 1)/s_j · u_j[n], exact; the
  Ritz forces (∫ b_i p dx on the real Ritz basis) are drawn with the
  pressure's spatial covariance, then coloured in time by the loading's
  low-pass if any; the record starts from the stationary distribution of
  modes and filter together (a discrete Lyapunov equation on the real and
  imaginary parts of η), so it has no start-up transient;
- under a tension drift each pole is held over segments of
  :data:`~stcs_ident.simulate.field_response.DRIFT_SEGMENT` s at its mean
  s_j (1 + d)^κ_j over the segment's samples (κ_j = d ln s_j / d ln H,
  :func:`~stcs_ident.simulate.damped_modes.pole_sensitivities`), the state
  carried across, the shapes fixed, as for the undamped records.

The random draws are in the undamped kernels' order: the start state, then
the white forces block by block (one column per Ritz function, not per mode).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from scipy.linalg import solve_discrete_lyapunov
from scipy.signal import lfilter

from ..core.model import Attachment, Cable
from .conditions import FieldConditions, RecordTruth
from .damped_modes import DampedModes, damped_modes, pole_sensitivities
from .disturbances import filter_state_space, lowpass_force_filter, relative_tension
from .field_response import DRIFT_SEGMENT
from .modal_response import matrix_sqrt, modal_force_covariance

__all__ = ["damped_record", "modal_kicks", "stationary_state_covariance", "superpose_damped"]

_BLOCK = 16384  # samples per segment without drift (bounds memory, as in modal_response)


def damped_record(cable: Cable, attachments: Sequence[Attachment], tension: float, positions: np.ndarray,
                  sampling_rate: float, n_samples: int, *, damping: Callable[[int], np.ndarray],
                  n_modes: int | None, band_fraction: float, impulses: Sequence, ambient_load: tuple | None,
                  field: FieldConditions | None, rng: np.random.Generator, field_rng: np.random.Generator | None,
                  progress: Callable[[int, int], None] | None = None,
                  modes: DampedModes | None = None) -> tuple[np.ndarray, RecordTruth]:
    """The noise-free record of a cable with dampers and what it truly holds.

    Parameters
    ----------
    cable, attachments, tension :
        The true configuration (the attachments hold the dampers).
    positions, sampling_rate, n_samples :
        Sensors (m, checked), Hz, samples.
    damping : callable(n) -> ndarray
        The intrinsic damping ratios of the first n undamped modes (checked).
    n_modes, band_fraction :
        As :func:`~stcs_ident.simulate.damped_modes.damped_modes`.
    impulses : sequence of Impulse
    ambient_load : (rms_pressure, correlation_length, uncorrelated_length) or None
        The ambient pressure (:class:`~stcs_ident.simulate.simulate.Ambient`).
    field : FieldConditions or None
        Only its coloured loading and drift act here (the sensor side is the caller's).
    rng, field_rng :
        The signal's stream and the disturbances' own (for a drift's random walk).
    modes : DampedModes or None
        The complex modes, if the caller has them already
        (:func:`~stcs_ident.simulate.damped_modes.damped_modes` of the same
        arguments); None: computed here.

    Returns
    -------
    clean : ndarray (n_samples, n_positions)
    truth : RecordTruth
        The oscillating modes' frequencies |s|/2π and damping ratios −Re s/|s| (the overdamped modes
        are simulated, not listed: a spectrum shows no peak of them); under a drift, each mode's
        sensitivity Re κ (its frequency's, as for the undamped records).
    """
    fs = float(sampling_rate)
    if modes is None:
        modes = damped_modes(cable, attachments, tension, fs, n_modes, damping, band_fraction)
    truth = RecordTruth(modes.frequencies, tension, fs, n_samples, damping=modes.damping)
    force_sqrt = None
    if ambient_load is not None:
        rms, length, uncorrelated = ambient_load
        cov = modal_force_covariance(modes.basis, rms, length, length=cable.length,
                                     wave_speed=math.sqrt(tension / cable.mass_per_length),
                                     uncorrelated_length=uncorrelated)
        force_sqrt = matrix_sqrt(cov)
    lowpass = field.ambient_lowpass if field is not None else None
    drift = field.drift if field is not None else None
    kappa = None
    if drift is not None:
        d = relative_tension(drift, n_samples, fs, field_rng)
        kappa = pole_sensitivities(cable, attachments, tension, modes, damping)
        truth = RecordTruth(truth.frequencies, tension, fs, n_samples, d, kappa[: modes.oscillating].real,
                            damping=truth.damping)
    clean = superpose_damped(modes, fs, n_samples, positions, modal_kicks(modes, impulses), force_sqrt, rng,
                             force_filter=None if lowpass is None else lowpass_force_filter(lowpass, fs),
                             relative_tension=truth.relative_tension, sensitivities=kappa, progress=progress)
    return clean, truth


def modal_kicks(modes: DampedModes, impulses) -> list[tuple[float, np.ndarray]]:
    """(time, jump of η) of each impulse: φ_j(x₀) J."""
    return [(imp.time, modes.shapes([imp.position])[0] * imp.magnitude) for imp in impulses]


def superpose_damped(modes: DampedModes, sampling_rate: float, n_samples: int, positions: np.ndarray,
                     kicks: Sequence[tuple[float, np.ndarray]], force_sqrt: np.ndarray | None,
                     rng: np.random.Generator, *, force_filter: tuple[np.ndarray, np.ndarray] | None = None,
                     relative_tension: np.ndarray | None = None, sensitivities: np.ndarray | None = None,
                     progress: Callable[[int, int], None] | None = None) -> np.ndarray:
    """Noise-free acceleration (n_samples, n_positions) of a cable with dampers.

    Parameters
    ----------
    modes : DampedModes
        The complex modes kept.
    sampling_rate, n_samples :
        Hz; samples at t = n / sampling_rate.
    positions : ndarray
        Sensor positions, m.
    kicks : sequence of (time, ndarray (p,) complex)
        Impulses as the jumps of the modal coordinates (:func:`modal_kicks`).
    force_sqrt : ndarray (r, r) or None
        R with R Rᵀ = E[f fᵀ], the covariance of the held Ritz forces; None
        for no random force (``rng`` is then not used).
    force_filter : (b, a) or None
        IIR applied in time to every Ritz force (a[0] = 1); None: white.
    relative_tension : ndarray (n_samples,) or None
        d[n]: the tension is H (1 + d[n]) at sample n; None: constant.
    sensitivities : ndarray (p,) complex
        κ_j = d ln s_j / d ln H (with ``relative_tension``).
    progress : callable(done, total), optional
        Called after each segment.
    """
    s0 = np.asarray(modes.poles, dtype=complex)
    p = s0.size
    dt = 1.0 / sampling_rate
    read = (modes.shapes(positions) * modes.weights[None, :]).T  # (p, n_channels): a = Re(modal @ read)
    # (r, 2p): the real and imaginary parts side by side. A real force times a complex matrix is not a BLAS
    # product in numpy (it ran 0.02-0.25 s a block, erratically); two real ones are.
    to_modal = np.hstack([modes.to_modal.real, modes.to_modal.imag])
    drifting = relative_tension is not None
    seg = max(1, min(round(DRIFT_SEGMENT * sampling_rate), _BLOCK)) if drifting else _BLOCK
    log1p_d = np.log1p(relative_tension) if drifting else None

    def poles_over(start, stop):
        if not drifting:
            return s0
        return s0 * np.mean(np.exp(np.outer(log1p_d[start:stop], sensitivities)), axis=0)

    eta = np.zeros(p, dtype=complex)  # η at the segment's first sample
    filt_state = None
    if force_sqrt is not None:
        eta, filt_state = _stationary_start(poles_over(0, min(seg, n_samples)), dt, modes.to_modal,
                                            force_sqrt @ force_sqrt.T, force_filter, rng)

    order = sorted(range(len(kicks)), key=lambda i: kicks[i][0])
    next_kick = 0
    out = np.empty((n_samples, len(positions)))
    if force_sqrt is not None:  # buffers reused block after block: fresh large arrays cost page faults each time
        r = force_sqrt.shape[0]
        white, force, parts = np.empty((seg, r)), np.empty((seg, r)), np.empty((2 * p, seg))
        u, path = np.empty((p, seg), dtype=complex), np.empty((p, seg), dtype=complex)
    for start in range(0, n_samples, seg):
        stop = min(start + seg, n_samples)
        n = stop - start
        s = poles_over(start, stop)
        lam = np.exp(s * dt)
        if force_sqrt is not None:
            rng.standard_normal(out=white[:n])
            np.matmul(white[:n], force_sqrt.T, out=force[:n])
            held = force[:n]
            if force_filter is not None:
                held, filt_state = lfilter(force_filter[0], force_filter[1], held, axis=0, zi=filt_state)
            np.matmul(to_modal.T, held.T, out=parts[:, :n])  # modes along rows: each one's path is contiguous
            u[:, :n].real, u[:, :n].imag = parts[:p, :n], parts[p:, :n]
            beta = _hold_gain(s, lam)
            for j in range(p):
                nxt, _ = lfilter([beta[j]], [1.0, -lam[j]], u[j, :n], zi=[lam[j] * eta[j]])
                path[j, 0] = eta[j]
                path[j, 1:n] = nxt[:-1]
                eta[j] = nxt[-1]
            modal = path[:, :n]
            modal *= s[:, None]
            modal += u[:, :n]
            modal *= s[:, None]  # s (s η + u): the acceleration of each modal coordinate
            modal = modal.T
        else:
            steps = np.arange(n)[:, None]
            modal = s * s * (eta[None, :] * np.exp(s[None, :] * steps * dt))
            eta = eta * np.exp(s * n * dt)
        t = np.arange(start, stop) * dt
        t_next = stop * dt
        while next_kick < len(order) and kicks[order[next_kick]][0] <= t_next:
            t0, jump = kicks[order[next_kick]]
            after = t >= t0
            modal[after] += s * s * jump * np.exp(np.outer(t[after] - t0, s))
            eta += jump * np.exp(s * (t_next - t0))
            next_kick += 1
        out[start:stop] = modal.real @ read.real - modal.imag @ read.imag
        if progress is not None:
            progress(stop, n_samples)
    return out


def _hold_gain(s: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """(e^{sΔt} − 1)/s: a force held over one step moves η by this times the force."""
    return (lam - 1.0) / s


def stationary_state_covariance(poles: np.ndarray, dt: float, to_modal: np.ndarray, force_cov: np.ndarray,
                                force_filter: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """Stationary covariance of (Re η, Im η[, filter states]) under held Ritz forces of covariance ``force_cov``.

    The real state is ξ = (Re η, Im η) (2p), ξ' = A ξ + B f with A the
    rotation-scaling blocks of λ = e^{sΔt} and B = (Re, Im) of diag(β) qᵀ.
    With a force filter (lfilter's transposed direct form II, state z of m
    per Ritz force, f = z₀ + b₀ w for white w), the state is (ξ, z) and the
    input w; z is ordered force by force.
    """
    lam = np.exp(poles * dt)
    beta = _hold_gain(poles, lam)
    p = poles.size
    A = np.block([[np.diag(lam.real), -np.diag(lam.imag)], [np.diag(lam.imag), np.diag(lam.real)]])
    gain = beta[:, None] * to_modal.T  # (p, r)
    B = np.vstack([gain.real, gain.imag])
    if force_filter is None:
        P = solve_discrete_lyapunov(A, B @ force_cov @ B.T)
        return 0.5 * (P + P.T)
    b, a = (np.asarray(v, float) for v in force_filter)
    Af, Bf = filter_state_space(b, a)
    m, r = len(Bf), force_cov.shape[0]
    eye = np.eye(r)
    first = np.zeros((1, m))
    first[0, 0] = 1.0
    big_a = np.block([[A, B @ np.kron(eye, first)], [np.zeros((m * r, 2 * p)), np.kron(eye, Af)]])
    big_b = np.vstack([B * b[0], np.kron(eye, Bf[:, None])])
    P = solve_discrete_lyapunov(big_a, big_b @ force_cov @ big_b.T)
    return 0.5 * (P + P.T)


def _stationary_start(poles, dt, to_modal, force_cov, force_filter, rng) -> tuple[np.ndarray, np.ndarray | None]:
    """η and the filter's lfilter state (m, r) drawn from the stationary distribution."""
    P = stationary_state_covariance(poles, dt, to_modal, force_cov, force_filter)
    x = matrix_sqrt(P) @ rng.standard_normal(P.shape[0])
    p = poles.size
    eta = x[:p] + 1j * x[p:2 * p]
    if force_filter is None:
        return eta, None
    m = len(force_filter[1]) - 1
    return eta, x[2 * p:].reshape(-1, m).T.copy()
