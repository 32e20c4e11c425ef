"""Cramér–Rao lower bounds for the frequency of damped sinusoids in noise.

The signal of one channel c and one event e is a real exponentially damped
sinusoid in real white Gaussian noise,

    x[n] = A_ce · exp(-σ t_n) · cos(ω t_n + φ_ce) + w[n],   t_n = n Δt,
    n = 0 … N_e − 1,   w[n] ~ N(0, s_c²),

with the angular frequency ω and the decay rate σ common to all channels
and events, and an amplitude and a phase of their own per channel and
event. Write the decay-weighted time moments of event e as

    S_k,e = Σ_n t_n^k · exp(-2 σ t_n),   k = 0, 1, 2.

For one channel and one event the Fisher information of (ω, φ) is
(A² / 2s²) [[S_2, S_1], [S_1, S_0]] and that of (σ, A) has the same
structure; the two blocks decouple because the cross terms carry
sin·cos products that average out when ω is well away from 0 and from
the Nyquist frequency and many periods are recorded (for ω near 0 or
π/Δt the real-signal bound is larger). Eliminating the phase (a nuisance)
leaves, for ω, the information A²/(2 s²) · (S_2 − S_1²/S_0). Information
from independent channels and events adds, so

    var(ω) ≥ 1 / Σ_{c,e} [A_ce² / (2 s_c²) · (S_2,e − S_1,e² / S_0,e)],
    var(σ) has the same bound, and σ_f = sqrt(var(ω)) / (2π).

This is the bound of Yao & Pandit (1995), "Cramér–Rao lower bounds for a
damped sinusoidal process", IEEE Trans. Signal Process. 43(4), 878–885,
written for the real signal: their complex model b·exp((−σ + iω) t) in
complex noise of variance s_v² gives var(ω) ≥ s_v² / (2|b|²) · S_0 /
(S_0 S_2 − S_1²), and a real sinusoid of amplitude A in real noise s² is
the complex case with |b| = A and s_v² = 4 s² (Fisher information
(1/s²) Σ (∂x)² = (1/2s²) Re Σ |∂μ|², μ the complex exponential).

Undamped limit (σ = 0): S_2 − S_1²/S_0 = Δt² N (N² − 1) / 12, hence

    var(f) ≥ 6 s² / (π² A² Δt² N (N² − 1))  ≈  6 s² / (π² A² N³ Δt²),

the classical bound of Rife & Boorstyn (1974), 12 / ((2π)² η N (N² − 1))
with η = A² / (2 s²), expressed in Hz with the sample spacing Δt.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..core.errors import InputError

__all__ = ["crb_decay_rate", "crb_frequency", "decay_information"]


def _as_event_lengths(n_samples: ArrayLike) -> np.ndarray:
    lengths = np.atleast_1d(np.asarray(n_samples))
    if lengths.ndim != 1 or lengths.size == 0 or np.any(lengths < 2) or np.any(lengths != np.round(lengths)):
        raise InputError(f"must be integers >= 2, one per event, got {n_samples!r}", field="n_samples")
    return lengths.astype(int)


def _moment_term(n: int, decay_rate: float, dt: float) -> float:
    """S_2 − S_1²/S_0 for one event, evaluated stably (times relative to the weighted mean)."""
    t = np.arange(n) * dt
    w = np.exp(-2.0 * decay_rate * t)
    s0 = w.sum()
    t_mean = (w * t).sum() / s0
    return float((w * (t - t_mean) ** 2).sum())


def decay_information(
    amplitude: ArrayLike,
    noise_std: ArrayLike,
    n_samples: ArrayLike,
    sampling_rate: float,
    decay_rate: float = 0.0,
) -> float:
    """Fisher information on ω (rad/s)⁻² for a common damped sinusoid; see the module docstring.

    Parameters are those of :func:`crb_frequency`. The same number is the
    information on the decay rate σ.
    """
    lengths = _as_event_lengths(n_samples)
    amp = np.asarray(amplitude, dtype=float)
    if amp.ndim == 1:
        amp = amp[None, :]
    if amp.ndim != 2 or amp.shape[0] != lengths.size:
        raise InputError(
            f"must have shape (n_channels,) or (n_events={lengths.size}, n_channels), got {np.shape(amplitude)}",
            field="amplitude",
        )
    noise = np.broadcast_to(np.asarray(noise_std, dtype=float), amp.shape[1:])
    if np.any(noise <= 0):
        raise InputError("must be > 0", field="noise_std")
    if not sampling_rate > 0:
        raise InputError(f"must be > 0, got {sampling_rate!r}", field="sampling_rate")
    dt = 1.0 / float(sampling_rate)
    moments = np.array([_moment_term(int(n), float(decay_rate), dt) for n in lengths])
    snr_weight = amp**2 / (2.0 * noise**2)  # (n_events, n_channels)
    return float((snr_weight * moments[:, None]).sum())


def crb_frequency(
    amplitude: ArrayLike,
    noise_std: ArrayLike,
    n_samples: ArrayLike,
    sampling_rate: float,
    decay_rate: float = 0.0,
) -> float:
    """Cramér–Rao bound (1σ, Hz) on the common frequency of damped sinusoids in white noise.

    Parameters
    ----------
    amplitude : array_like, shape (n_channels,) or (n_events, n_channels)
        Amplitude A of the real sinusoid at the start of each event in each
        channel (any unit, the same as ``noise_std``).
    noise_std : float or array_like (n_channels,)
        Standard deviation s of the white noise per sample, per channel.
    n_samples : int or array_like (n_events,)
        Samples per event.
    sampling_rate : float
        Hz.
    decay_rate : float
        σ = ζ ω_n in 1/s (0 for an undamped sinusoid).

    Returns
    -------
    float
        sqrt(var(f)) in Hz, with var(ω) = 1 / Σ A²/(2 s²) (S_2 − S_1²/S_0)
        as derived in the module docstring (Yao & Pandit 1995 for the real
        signal; channels and events add their Fisher information).
    """
    info = decay_information(amplitude, noise_std, n_samples, sampling_rate, decay_rate)
    if info <= 0:
        return float("inf")
    return float(1.0 / np.sqrt(info) / (2.0 * np.pi))


def crb_decay_rate(
    amplitude: ArrayLike,
    noise_std: ArrayLike,
    n_samples: ArrayLike,
    sampling_rate: float,
    decay_rate: float = 0.0,
) -> float:
    """Cramér–Rao bound (1σ, 1/s) on the common decay rate σ; same parameters as :func:`crb_frequency`.

    The damping ratio's bound follows as σ_ζ ≈ σ_σ / ω_n.
    """
    info = decay_information(amplitude, noise_std, n_samples, sampling_rate, decay_rate)
    return float(1.0 / np.sqrt(info)) if info > 0 else float("inf")
