"""Acceleration records from the forward model, by modal superposition.

The modes are the exact dynamic-stiffness model's natural frequencies and
mass-normalised shapes (:func:`~stcs_ident.forward.shapes.mode_shapes`).
Each modal coordinate obeys q̈ + 2ζω q̇ + ω² q = φᵀF(t) and a sensor at x
reads Σ_k φ_k(x) q̈_k(t). Nothing is time-stepped approximately:

- an impulse J at x₀ and t₀ starts each mode with q̇_k = φ_k(x₀) J, and its
  damped-sinusoid response is evaluated in closed form at the samples;
- ambient pressure is held constant over each sampling interval
  (zero-order hold, white up to the Nyquist frequency), and each mode is
  advanced by its exact state-transition matrix. The record starts from a
  state drawn from the stationary distribution, so it has no start-up
  transient (the kernels are in :mod:`~stcs_ident.simulate.modal_response`).

All modes below 0.45 × the sampling rate are kept (or a given number), so
a record has the realistic content of a band-limited sensor. Hidden
effects (:class:`~stcs_ident.simulate.effects.Effects`) act on the true
model only. :func:`~stcs_ident.simulate.simulate_campaign.simulate_campaign`
writes a whole campaign directory from them, for tests and benchmarks.

A cable with a :class:`~stcs_ident.core.model.Damper` among its true attachments
has non-proportional damping and complex modes: its records are made by
complex modal superposition of a finite-element model that carries the
dashpots exactly (:mod:`~stcs_ident.simulate.damped_response`), with the
same excitations and disturbances; ``damping`` is then the cable's own
(intrinsic) part. Without a damper nothing of that runs.

Field-like disturbances (coloured loading, a drifting tension, pink noise,
mains hum, offsets, float32 samples) are off by default and given as one
:class:`~stcs_ident.simulate.disturbances.FieldConditions`; without them a
record is exactly what it was before they existed.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..core.errors import ModelError
from ..core.model import Attachment, Cable, has_dampers, real_number
from ..core.record import Record
from ..core.record import sampling_rate as record_sampling_rate
from ..forward.dsm import count_below
from ..forward.shapes import ModeShapes, mode_shapes
from .conditions import FieldConditions, RecordTruth
from .damped_response import damped_record
from .disturbances import (
    apply_sensor_disturbances,
    check_field,
    field_rng,
    lowpass_force_filter,
    relative_tension,
    tension_sensitivities,
)
from .effects import Effects, true_model
from .field_response import superpose_field
from .modal_response import matrix_sqrt, modal_force_covariance, superpose

__all__ = [
    "NYQUIST_FRACTION", "UNCORRELATED_LENGTH", "Ambient", "Effects", "FieldConditions", "Impulse", "RecordTruth",
    "modal_basis", "modal_damping", "simulate_record", "simulate_record_with_truth", "true_model",
]

#: Modes are kept up to this fraction of the sampling rate (just below Nyquist).
NYQUIST_FRACTION = 0.45
#: Uncorrelated pressure: ``rms_pressure`` is the rms of its mean over this length (m).
UNCORRELATED_LENGTH = 1.0
#: Most samples of one simulated record (23 h at 200 Hz; 400 MB for 3 channels as float64, and several
#: times that while the modal responses are summed): a longer record is refused before anything is allocated.
MAX_SAMPLES = 2**24
#: Most hand blows in one record: each adds its free decay to every sample after it.
MAX_IMPULSES = 1000

Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class Impulse:
    """A hand or hammer blow: an impulse at one point of the cable.

    Parameters
    ----------
    time : float
        s from the start of the record (may be negative: a blow before it).
    position : float
        m from end A.
    magnitude : float
        N s, positive in the direction of sag.
    """

    time: float
    position: float
    magnitude: float

    def __post_init__(self):
        for name in ("time", "position", "magnitude"):
            object.__setattr__(self, name, real_number(getattr(self, name), f"impulse.{name}"))


@dataclass(frozen=True)
class Ambient:
    """Random pressure along the cable: Gaussian, white in time up to Nyquist.

    Parameters
    ----------
    rms_pressure : float
        N/m. With a correlation length, the pointwise rms; without one, the
        rms of the pressure averaged over each metre of cable
        (:data:`UNCORRELATED_LENGTH`), since a spatially white pressure has
        no pointwise value.
    correlation_length : float or None
        m; spatial correlation exp(−|x − x'| / L). None: uncorrelated along
        the cable, which loads every mode alike (∝ ∫φ_k²); a long L loads
        mainly the symmetric modes (∝ (∫φ_k)²).
    """

    rms_pressure: float
    correlation_length: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "rms_pressure", real_number(self.rms_pressure, "ambient.rms_pressure", positive=True))
        if self.correlation_length is not None:
            L = real_number(self.correlation_length, "ambient.correlation_length", positive=True)
            object.__setattr__(self, "correlation_length", L)


def simulate_record(cable: Cable, attachments: Sequence[Attachment], tension: float, positions: Sequence[float], *,
                    duration: float, sampling_rate: float, damping: float | Sequence[float] = 0.005,
                    impulses: Sequence[Impulse] = (), ambient: Ambient | None = None, snr_db: float | None = None,
                    effects: Effects | None = None, n_modes: int | None = None,
                    seed: int | np.random.SeedSequence | None = 0, channel_names: Sequence[str] | None = None,
                    field: FieldConditions | None = None, progress: Progress | None = None) -> Record:
    """Simulate a multi-channel acceleration record of one configuration.

    Parameters
    ----------
    cable, attachments, tension :
        The nominal configuration (tension in N); ``effects`` turn it into
        the true one that vibrates.
    positions : sequence of float
        Sensor positions, m from end A, strictly inside the true span.
    duration : float
        s; the record has ``round(duration * sampling_rate)`` samples.
    sampling_rate : float
        Hz.
    damping : float or sequence of float
        Modal damping ratio(s), 0 < ζ < 1: one for all modes, or one per
        mode from mode 1 (at least as many as modes simulated; extra
        entries are ignored). With dampers, the cable's own (intrinsic)
        damping of its undamped modes; the dashpots add theirs.
    impulses : sequence of Impulse
        Blows, evaluated exactly.
    ambient : Ambient or None
        Distributed random pressure. At least one excitation is needed;
        with both, the blows' decays ride on the continuing ambient
        response (they add: the model is linear).
    snr_db : float or None
        Sensor noise: white Gaussian, per channel with rms = the channel's
        signal rms × 10^(−snr_db/20). None: noise-free.
    effects : Effects or None
        Hidden differences of the true model from the nominal one.
    n_modes : int or None
        Number of modes; default all below 0.45 × sampling rate. Every
        mode must lie below the Nyquist frequency.
    seed : int, SeedSequence or None
        For ``np.random.default_rng``; the same seed gives the same record,
        and the same signal with or without noise (noise is drawn last).
    channel_names : sequence of str or None
        Default ``"A1"``, ``"A2"``, ...
    field : FieldConditions or None
        Field-like disturbances (:mod:`~stcs_ident.simulate.disturbances`):
        low-pass ambient loading, tension drift, pink noise, mains hum, DC
        offsets, float32 samples. None (or ``FieldConditions()``): none,
        and the record is bit for bit the one without this argument. Their
        random draws use a stream of their own: turning on pink noise, hum,
        offsets or float32 leaves the signal and the white noise as they
        were; a coloured loading or a drift makes another signal.
    progress : callable(done, total), optional
        Called after each block of samples.

    Returns
    -------
    Record
        Acceleration in m/s² at the sensors.

    Raises
    ------
    ModelError
        For an invalid option; the field names it.

    See Also
    --------
    simulate_record_with_truth : the same record and what it truly holds
        (the time-averaged frequencies under a drift).
    """
    return simulate_record_with_truth(cable, attachments, tension, positions, duration=duration,
                                      sampling_rate=sampling_rate, damping=damping, impulses=impulses,
                                      ambient=ambient, snr_db=snr_db, effects=effects, n_modes=n_modes, seed=seed,
                                      channel_names=channel_names, field=field, progress=progress)[0]


def simulate_record_with_truth(cable: Cable, attachments: Sequence[Attachment], tension: float,
                               positions: Sequence[float], *, duration: float, sampling_rate: float,
                               damping: float | Sequence[float] = 0.005, impulses: Sequence[Impulse] = (),
                               ambient: Ambient | None = None, snr_db: float | None = None,
                               effects: Effects | None = None, n_modes: int | None = None,
                               seed: int | np.random.SeedSequence | None = 0,
                               channel_names: Sequence[str] | None = None, field: FieldConditions | None = None,
                               progress: Progress | None = None) -> tuple[Record, RecordTruth]:
    """:func:`simulate_record`'s record and what it truly holds.

    The parameters are :func:`simulate_record`'s. The
    :class:`~stcs_ident.simulate.disturbances.RecordTruth` gives the true
    model's frequencies and damping ratios (with dampers, the complex
    modes' |s|/2π and −Re(s)/|s|) and, under a tension drift, the relative tension at
    every sample, each mode's sensitivity to it, the instantaneous and the
    time-averaged frequencies.
    """
    fs, n_samples = check_timing(duration, sampling_rate)
    impulses = check_impulses(impulses)
    if snr_db is not None:
        snr_db = real_number(snr_db, "snr_db")
    if not impulses and ambient is None:
        raise ModelError("no excitation: give impulses and/or ambient", field="excitation")
    if ambient is not None and not isinstance(ambient, Ambient):
        raise ModelError(f"must be an Ambient or None, got {type(ambient).__name__}", field="ambient")
    cable, atts, tension = true_model(cable, attachments, tension, effects)
    x = _check_positions(positions, cable.length, "positions")
    for imp in impulses:
        _check_positions([imp.position], cable.length, "impulse.position")
    names = _channel_names(channel_names, len(x))
    if field is not None:
        check_field(field, len(x), fs, ambient is not None)
    if has_dampers(atts):
        return _damped(cable, atts, tension, x, fs, n_samples, names, damping, impulses, ambient, snr_db, n_modes,
                       seed, field, progress)
    shapes = modal_basis(cable, atts, tension, fs, n_modes)
    zeta = modal_damping(damping, len(shapes.frequencies))
    rng = np.random.default_rng(seed)
    own_rng = field_rng(rng) if field is not None else None
    force_sqrt = None
    if ambient is not None:
        cov = modal_force_covariance(shapes, ambient.rms_pressure, ambient.correlation_length, length=cable.length,
                                     wave_speed=math.sqrt(tension / cable.mass_per_length),
                                     uncorrelated_length=UNCORRELATED_LENGTH)
        force_sqrt = matrix_sqrt(cov)
    kicks = [(imp.time, shapes([imp.position])[0] * imp.magnitude) for imp in impulses]
    truth = RecordTruth(np.asarray(shapes.frequencies, dtype=float), tension, fs, n_samples, damping=zeta)
    lowpass = field.ambient_lowpass if field is not None else None
    drift = field.drift if field is not None else None
    if lowpass is None and drift is None:
        clean = superpose(shapes, zeta, fs, n_samples, x, kicks, force_sqrt, rng, progress)
    else:
        if drift is not None:
            d = relative_tension(drift, n_samples, fs, own_rng)
            s = tension_sensitivities(cable, atts, tension, len(shapes.frequencies))
            truth = RecordTruth(truth.frequencies, tension, fs, n_samples, d, s, damping=zeta)
        clean = superpose_field(shapes, zeta, fs, n_samples, x, kicks, force_sqrt, rng,
                                force_filter=None if lowpass is None else lowpass_force_filter(lowpass, fs),
                                relative_tension=truth.relative_tension, sensitivities=truth.sensitivities,
                                progress=progress)
    signal = _with_noise(clean, snr_db, rng)
    if field is not None:
        signal = apply_sensor_disturbances(signal, clean, fs, field, own_rng)
    return Record(signal, fs, names, x), truth


def _damped(cable, atts, tension, x, fs, n_samples, names, damping, impulses, ambient, snr_db, n_modes, seed, field,
            progress) -> tuple[Record, RecordTruth]:
    """simulate_record_with_truth for a cable with dampers: complex modes (:mod:`.damped_response`)."""
    if n_modes is not None and (isinstance(n_modes, bool) or not isinstance(n_modes, int | np.integer)
                                or n_modes < 1):
        raise ModelError(f"must be an integer >= 1, got {n_modes!r}", field="n_modes")
    modal_damping(damping, 1)  # its checks before any work
    rng = np.random.default_rng(seed)
    own_rng = field_rng(rng) if field is not None else None
    load = None if ambient is None else (ambient.rms_pressure, ambient.correlation_length, UNCORRELATED_LENGTH)
    clean, truth = damped_record(cable, atts, tension, x, fs, n_samples, damping=lambda n: modal_damping(damping, n),
                                 n_modes=n_modes, band_fraction=NYQUIST_FRACTION, impulses=impulses,
                                 ambient_load=load, field=field, rng=rng, field_rng=own_rng, progress=progress)
    signal = _with_noise(clean, snr_db, rng)
    if field is not None:
        signal = apply_sensor_disturbances(signal, clean, fs, field, own_rng)
    return Record(signal, fs, names, x), truth


def modal_basis(cable: Cable, attachments: Sequence[Attachment], tension: float, sampling_rate: float,
                n_modes: int | None = None) -> ModeShapes:
    """The modes a record at ``sampling_rate`` contains.

    Parameters
    ----------
    cable, attachments, tension :
        The configuration that vibrates (the true one).
    sampling_rate : float
        Hz.
    n_modes : int or None
        Default: all modes below ``NYQUIST_FRACTION × sampling_rate``.
        Given, every one of them must lie below the Nyquist frequency.

    Returns
    -------
    ModeShapes
        Frequencies (Hz) and mass-normalised shapes.

    Notes
    -----
    A massless, springless node is added at an irrational fraction of the
    span, away from the attachments: the shapes come from the nodal values
    of the dynamic stiffness, and without it a bare clamped cable has no
    nodal unknowns, and a mode with a node at every attachment has none
    that move. It changes no frequency or shape.
    """
    fs = float(sampling_rate)
    if n_modes is None:
        n = count_below(cable, attachments, tension, NYQUIST_FRACTION * fs)
        if n == 0:
            raise ModelError(f"no mode below {NYQUIST_FRACTION} x sampling rate ({fs:g} Hz): raise it",
                             field="sampling_rate")
    else:
        if isinstance(n_modes, bool) or not isinstance(n_modes, int | np.integer) or n_modes < 1:
            raise ModelError(f"must be an integer >= 1, got {n_modes!r}", field="n_modes")
        n = int(n_modes)
    shapes = mode_shapes(cable, attachments, tension, n)
    if shapes.frequencies[-1] >= fs / 2:
        raise ModelError(f"mode {n} at {shapes.frequencies[-1]:.4g} Hz is at or above the Nyquist frequency "
                         f"({fs / 2:g} Hz) and would alias", field="n_modes")
    return shapes


def modal_damping(damping: float | Sequence[float], n_modes: int) -> np.ndarray:
    """Damping ratios of the first ``n_modes`` modes, checked: 0 < ζ < 1."""
    try:
        values = np.atleast_1d(np.asarray(damping, dtype=float))
    except (TypeError, ValueError):
        raise ModelError(f"must be a number or a sequence of numbers, got {damping!r}", field="damping") from None
    if values.ndim != 1:
        raise ModelError("must be a number or a sequence of numbers", field="damping")
    if values.size == 1 and np.ndim(damping) == 0:
        values = np.full(n_modes, values[0])
    if values.size < n_modes:
        raise ModelError(f"gives {values.size} ratios for {n_modes} modes", field="damping")
    values = values[:n_modes]
    if not np.all(np.isfinite(values) & (values > 0) & (values < 1)):
        raise ModelError("ratios must satisfy 0 < damping < 1", field="damping")
    return values


def _with_noise(clean: np.ndarray, snr_db: float | None, rng: np.random.Generator) -> np.ndarray:
    if snr_db is None:
        return clean
    noise_rms = np.sqrt(np.mean(clean**2, axis=0)) * 10 ** (-snr_db / 20)
    return clean + rng.standard_normal(clean.shape) * noise_rms


def check_timing(duration, sampling_rate) -> tuple[float, int]:
    duration = real_number(duration, "duration", positive=True)
    fs = record_sampling_rate(sampling_rate)
    n = duration * fs
    if n > MAX_SAMPLES:
        raise ModelError(f"gives {n:.3g} samples at {fs:g} Hz; a simulated record has at most {MAX_SAMPLES} "
                         f"({MAX_SAMPLES / fs:.4g} s at this rate: memory grows with the samples)", field="duration")
    n = round(n)
    if n < 2:
        raise ModelError(f"gives {n} samples at {fs:g} Hz: at least 2 needed", field="duration")
    return fs, n


def check_impulses(impulses) -> tuple[Impulse, ...]:
    """The impulses (any iterable, read no further than one past the limit) as a checked tuple."""
    out = tuple(itertools.islice(impulses, MAX_IMPULSES + 1))
    if len(out) > MAX_IMPULSES:
        raise ModelError(f"more than {MAX_IMPULSES} hand blows; at most {MAX_IMPULSES} per record (each adds its "
                         "decay to every sample after it)", field="impulses")
    for imp in out:
        if not isinstance(imp, Impulse):
            raise ModelError(f"must hold Impulse objects, got {type(imp).__name__}", field="impulses")
    return out


def _check_positions(positions, length: float, name: str) -> np.ndarray:
    try:
        x = np.atleast_1d(np.asarray(positions, dtype=float))
    except (TypeError, ValueError):
        raise ModelError(f"must be numbers (m), got {positions!r}", field=name) from None
    if x.ndim != 1 or x.size == 0:
        raise ModelError("must be a non-empty sequence of positions (m)", field=name)
    bad = ~(np.isfinite(x) & (x > 0) & (x < length))
    if bad.any():
        raise ModelError(f"{x[bad][0]!r} m is outside the (true) span (0, {length:g}) m", field=name)
    return x


def _channel_names(names, n: int) -> tuple[str, ...]:
    if names is None:
        return tuple(f"A{i + 1}" for i in range(n))
    names = tuple(str(s) for s in names)
    if len(names) != n:
        raise ModelError(f"gives {len(names)} names for {n} positions", field="channel_names")
    return names
