"""The anchorages' motion (deck and pylon modes, traffic) and the cable's answer to it.

Motion of the anchorages
------------------------
Each :class:`~stcs_ident.simulate.bridge.StructuralMode` is a narrow-band Gaussian acceleration: white noise
through the band-pass 2iζω_sω / (ω_s² − ω² + 2iζω_sω), scaled to its expected rms; its harmonics follow its
analytic signal. Crossing vehicles (:class:`~stcs_ident.simulate.bridge.Traffic`) multiply the deck motion by
1 + a Σ e_i(t) and add white acceleration of rms b Σ e_i(t). Everything is synthesised over the record by
FFT, as one period of a periodic process: it is stationary from the first sample (no start-up transient) and
a crossing near the end of the record rings on into its start.

The cable's answer
------------------
Let end B (x = l) move transversely by u_B(t) (end A: the same with 1 − x/l for x/l). Write the cable's
transverse displacement as the chord line's motion plus a relative part,

    w(x, t) = (x/l) u_B(t) + Σ_k φ_k(x) q_k(t),

φ_k the mass-normalised modes of the cable with fixed ends. The chord line is a static solution of the
taut string (w'' = 0), so m ẅ − H w'' = 0 leaves for the relative part the inertia load −m (x/l) ü_B, and by
the modes' orthogonality

    q̈_k + 2ζ_k ω_k q̇_k + ω_k² q_k = −Γ_k ü_B(t),   Γ_k = ∫ m φ_k (x/l) dx + Σ_a M_a φ_k(x_a) x_a/l

(the attachments' masses M_a ride on the chord line too). A sensor at x reads the absolute acceleration

    ẅ(x) = (x/l) ü_B + Σ_k φ_k(x) q̈_k,   so   Ẅ(x, ω) = [x/l + Σ_k φ_k(x) Γ_k ω² / (ω_k² − ω² + 2iζ_kω_kω)] Ü_B(ω),

which is applied per frequency bin (exact for the periodic motion). A structural mode near a cable mode
resonates in that mode's shape; far above every mode the cable's interior stays put (the bracket → 0, as
Σ φ_k Γ_k is the chord line's modal expansion); far below, the cable follows the chord line. Neglected: the
bending stiffness's boundary layers at clamped ends (the chord line is not a static solution there), springs
to ground and dampers acting on the chord line's motion, and the tension change that an axial anchorage
motion makes (through the sag it loads the symmetric in-plane modes: second order in the sag for a taut
cable). Each transverse plane answers to its own component of the motion with its own modes.

Axially the cable is stiff (its axial waves are far faster than its transverse ones), so it moves with the
chord line: an axial channel at x reads (x/l) ü_B,axial + (1 − x/l) ü_A,axial. The cable's transverse modes
give no axial acceleration to first order (their axial motion is quadratic in the amplitudes), so an axial
channel sees only the anchorages' axial motion (and, misaligned, some transverse motion).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.signal import hilbert

from ..core.model import Attachment
from ..forward.shapes import ModeShapes
from .bridge import ENDS, BridgeConditions, StructuralMode, Traffic
from .damped_modes import DampedModes

__all__ = ["AnchorageMotion", "anchorage_motion", "axial_response", "chord_weight", "transverse_response"]

#: Components of a motion, in the order of StructuralMode.direction.
COMPONENTS = ("in", "out", "axial")
_FREQUENCY_BLOCK = 2048  # frequency bins per block of the modal gains (bounds memory to BLOCK × n_modes)


@dataclass(frozen=True, eq=False)
class AnchorageMotion:
    """The anchorages' accelerations over a record.

    Attributes
    ----------
    acceleration : dict end → ndarray (n_samples, 3)
        m/s², components (in, out, axial), of the ends that move.
    crossings : ndarray
        s, start times of the vehicles' crossings (some may be negative: before the record).
    """

    acceleration: dict
    crossings: np.ndarray

    def component(self, end: str, component: str) -> np.ndarray | None:
        """The samples of one end's component, None if that end does not move."""
        acc = self.acceleration.get(end)
        return None if acc is None else acc[:, COMPONENTS.index(component)]


def anchorage_motion(bridge: BridgeConditions, n_samples: int, sampling_rate: float,
                     rng: np.random.Generator) -> AnchorageMotion:
    """The anchorages' accelerations of one record, drawn from ``rng`` (the crossings first, then each
    structural mode's noise in turn, then the broadband noise)."""
    fs = float(sampling_rate)
    t = np.arange(n_samples) / fs
    traffic = bridge.traffic
    crossings = np.zeros(0)
    envelope = None
    if traffic is not None:
        crossings, envelope = _crossings(traffic, t, rng)
    acc = {}
    for mode in bridge.anchorage_motion:
        series = _structural(mode, n_samples, fs, rng)
        if envelope is not None:
            series = series * (1.0 + traffic.amplitude * envelope)
        _add(acc, mode.end, mode.direction, series, n_samples)
    if traffic is not None and traffic.broadband > 0:
        _add(acc, traffic.end, traffic.direction, traffic.broadband * envelope * rng.standard_normal(n_samples),
             n_samples)
    return AnchorageMotion(acc, crossings)


def chord_weight(end: str, x: np.ndarray, length: float) -> np.ndarray:
    """How much of end ``end``'s motion the chord line carries at ``x``: x/l for B, 1 − x/l for A."""
    s = np.asarray(x, float) / length
    return s if end == "B" else 1.0 - s


def transverse_response(motion: AnchorageMotion, plane: str, shapes: ModeShapes | DampedModes,
                        damping: np.ndarray | None, masses: Sequence[Attachment], length: float,
                        mass_per_length: float, x: np.ndarray, sampling_rate: float, n_samples: int) -> np.ndarray:
    """The absolute acceleration (n_samples, len(x)) of the cable's ``plane`` motion under the anchorages'
    ``plane`` components (the module docstring derives it).

    ``shapes`` and ``damping`` are the plane's fixed-end modes and ratios, or ``shapes`` its complex modes
    (:class:`~stcs_ident.simulate.damped_modes.DampedModes`, ``damping`` None) for a cable with dampers;
    ``masses`` the attachments (their masses ride on the chord line).
    """
    out = np.zeros((n_samples, len(x)))
    omega = 2 * math.pi * np.fft.rfftfreq(n_samples, 1.0 / sampling_rate)
    for end in ENDS:
        u = motion.component(end, plane)
        if u is None or not np.any(u):
            continue
        if isinstance(shapes, DampedModes):
            modal = _complex_modal_gain(shapes, end, masses, length, mass_per_length, x, omega)
        else:
            modal = _modal_gain(shapes, damping, end, masses, length, mass_per_length, x, omega)
        tf = chord_weight(end, x, length)[None, :] + modal  # (n_f, n_ch)
        out += np.fft.irfft(np.fft.rfft(u)[:, None] * tf, n=n_samples, axis=0)
    return out


def _modal_gain(shapes: ModeShapes, damping: np.ndarray, end: str, masses, length: float, mass_per_length: float,
                x: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Σ_k φ_k(x) Γ_k ω² / (ω_k² − ω² + 2iζ_kω_kω), (n_f, n_ch): in real arithmetic, a block of frequencies
    at a time (the (n_f, n_modes) complex gains of a long record at a high rate would be hundreds of MB)."""
    wk = 2 * math.pi * np.asarray(shapes.frequencies, float)
    read = _participation(shapes, end, masses, length, mass_per_length)[:, None] * shapes(x).T  # (N, n_ch)
    out = np.empty((len(omega), len(x)), dtype=complex)
    for start in range(0, len(omega), _FREQUENCY_BLOCK):
        w = omega[start:start + _FREQUENCY_BLOCK, None]
        real = wk**2 - w**2
        imag = 2 * damping * wk * w
        scale = w**2 / (real**2 + imag**2)
        out[start:start + len(w)].real = (scale * real) @ read
        out[start:start + len(w)].imag = -(scale * imag) @ read
    return out


def _complex_modal_gain(modes: DampedModes, end: str, masses, length: float, mass_per_length: float,
                        x: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """The complex modes' answer to the chord line's inertia load, (n_f, n_ch).

    The load −m s(x) ü gives the Ritz forces −g ü (g_i = ∫ m b_i s dx + Σ M_a b_i(x_a) s(x_a)) and the modal
    forces u_j = −c_j ü, c_j = q_jᵀ g. With η̇_j = s_j η_j + u_j the sensor reads Re z, z = Σ_j w_j φ_j(x)
    s_j (s_j η_j + u_j), whose transfer from ü is G(ω) = −Σ_j w_j φ_j(x) s_j c_j iω / (iω − s_j); a real
    signal's Re z has the transfer (G(ω) + conj G(−ω)) / 2. The dashpots act on the relative motion only
    (a damper riding on the moving anchorage's structure), as the intrinsic damping does.
    """
    c = modes.to_modal.T @ _participation(modes.basis, end, masses, length, mass_per_length)  # (p,)
    read = modes.shapes(x) * (modes.weights * modes.poles * c)[None, :]  # (n_ch, p)
    s = modes.poles

    def g(w):
        return -(1j * w[:, None] / (1j * w[:, None] - s[None, :])) @ read.T

    out = np.empty((len(omega), len(x)), dtype=complex)
    for start in range(0, len(omega), _FREQUENCY_BLOCK):
        w = omega[start:start + _FREQUENCY_BLOCK]
        out[start:start + len(w)] = 0.5 * (g(w) + np.conj(g(-w)))
    return out


def axial_response(motion: AnchorageMotion, x: np.ndarray, length: float, n_samples: int) -> np.ndarray:
    """The axial acceleration (n_samples, len(x)): the chord line's, from both ends' axial components."""
    out = np.zeros((n_samples, len(x)))
    for end in ENDS:
        u = motion.component(end, "axial")
        if u is not None:
            out += u[:, None] * chord_weight(end, x, length)[None, :]
    return out


def _participation(shapes, end: str, attachments: Sequence[Attachment], length: float,
                   mass_per_length: float) -> np.ndarray:
    """Γ_k = ∫ m φ_k s dx + Σ_a M_a φ_k(x_a) s(x_a), s the chord weight of ``end``."""
    xq, wq = shapes.quadrature()
    gamma = mass_per_length * ((shapes(xq) * (wq * chord_weight(end, xq, length))[:, None]).sum(axis=0))
    for a in attachments:
        if a.mass > 0:
            gamma += a.mass * shapes([a.position])[0] * chord_weight(end, np.array([a.position]), length)[0]
    return gamma


def _structural(mode: StructuralMode, n_samples: int, fs: float, rng: np.random.Generator) -> np.ndarray:
    """A structural mode's acceleration along its direction (with its harmonics), m/s²."""
    noise = rng.standard_normal(n_samples)
    if mode.amplitude == 0:
        return np.zeros(n_samples)
    omega = 2 * math.pi * np.fft.rfftfreq(n_samples, 1.0 / fs)
    ws = 2 * math.pi * mode.frequency
    band = 2j * mode.damping * ws * omega / (ws**2 - omega**2 + 2j * mode.damping * ws * omega)
    series = np.fft.irfft(np.fft.rfft(noise) * band, n=n_samples)
    series *= mode.amplitude / math.sqrt(_mean_square_gain(band, n_samples))
    if mode.harmonics:
        analytic = hilbert(series)
        envelope, phase = np.abs(analytic), np.angle(analytic)
        for h, ratio in enumerate(mode.harmonics, start=2):
            if ratio > 0 and h * mode.frequency < fs / 2:
                series = series + ratio * envelope * np.cos(h * phase)
    return series


def _mean_square_gain(gain: np.ndarray, n_samples: int) -> float:
    """E[y²] of y = irfft(rfft(w) · gain) for unit white w: the two-sided mean of |gain|²."""
    g2 = np.abs(gain) ** 2
    total = g2[0] + 2 * g2[1:].sum()
    if n_samples % 2 == 0:
        total -= g2[-1]  # the Nyquist bin counts once
    return float(total / n_samples)


def _crossings(traffic: Traffic, t: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Poisson start times over [−D, T) and the sum of their sin² envelopes at ``t``."""
    D = traffic.duration_s
    span = (t[-1] if t.size else 0.0) + D
    count = rng.poisson(traffic.rate_per_hour / 3600.0 * span)
    starts = np.sort(rng.uniform(-D, t[-1] if t.size else 0.0, count))
    envelope = np.zeros_like(t)
    for t0 in starts:
        lo, hi = np.searchsorted(t, [t0, t0 + D])
        envelope[lo:hi] += np.sin(math.pi * (t[lo:hi] - t0) / D) ** 2
    return starts, envelope


def _add(acc: dict, end: str, direction, series: np.ndarray, n_samples: int) -> None:
    if end not in acc:
        acc[end] = np.zeros((n_samples, 3))
    acc[end] += series[:, None] * np.asarray(direction, float)[None, :]
