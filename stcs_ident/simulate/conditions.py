"""Field-like conditions of a simulated record, as validated data (what to add; :mod:`.disturbances` adds it).

:class:`FieldConditions` groups the optional parts (:class:`LowPassLoading`,
:class:`TensionDrift`, :class:`PinkNoise`, :class:`MainsHum`,
:class:`DcOffsets`, float32 samples), each validated when built (a
:class:`~stcs_ident.core.errors.ModelError` names the field);
:class:`RecordTruth` is what a simulated record truly holds (under drift,
the time-averaged frequencies to score against);
:func:`random_field_conditions` draws field-like conditions from a seeded
generator.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

import numpy as np

from ..core.errors import ModelError
from ..core.model import real_number

__all__ = [
    "DRIFT_LIMIT", "DcOffsets", "FieldConditions", "LowPassLoading", "MainsHum", "PinkNoise", "RecordTruth",
    "TensionDrift", "random_field_conditions",
]

#: Largest relative tension excursion a drift may reach within a record: beyond it the fixed mode shapes
#: and the frequencies' power law in the tension (fitted at the true tension) would no longer hold.
DRIFT_LIMIT = 0.01

# --------------------------------------------------------------------------
# The conditions
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class LowPassLoading:
    """Ambient pressure coloured by a Butterworth low-pass instead of white.

    The white held pressure of :class:`~stcs_ident.simulate.simulate.Ambient`
    is filtered in time, the same filter at every point, so its spatial
    correlation is unchanged. The filter is scaled to keep the pressure's
    variance: ``Ambient.rms_pressure`` is still its rms. Its power spectrum
    is flat below the corner and falls as f^(−2·order) above it (the
    digital filter, by the bilinear transform, falls faster near Nyquist).

    Parameters
    ----------
    corner_frequency : float
        Hz, the −3 dB frequency; below the Nyquist frequency of the record.
    order : int
        1 or 2.
    """

    corner_frequency: float
    order: int = 2

    def __post_init__(self):
        object.__setattr__(self, "corner_frequency",
                           real_number(self.corner_frequency, "ambient_lowpass.corner_frequency", positive=True))
        if isinstance(self.order, bool) or self.order not in (1, 2):
            raise ModelError(f"must be 1 or 2, got {self.order!r}", field="ambient_lowpass.order")
        object.__setattr__(self, "order", int(self.order))


@dataclass(frozen=True)
class TensionDrift:
    """A slow drift of the tension within the record.

    The tension is H(t) = H (1 + d(t)), H the true tension (at t = 0) and

        d(t) = rate · t + amplitude · (sin(2πt/period + phase) − sin(phase)) + walk · W(t),

    W a standard Wiener process (W(0) = 0, drawn per sample), so d(0) = 0.
    Each modal frequency follows f_k(t) = f_k (1 + d(t))^s_k, with s_k =
    d ln f_k / d ln H of the true model (1/2 for a taut string, less with
    bending stiffness or attachments): a relative frequency wander of about
    half the tension's. The response is phase-continuous (the tension
    changes in steps of :data:`~stcs_ident.simulate.field_response.DRIFT_SEGMENT`
    s carrying the modal state across); see
    :func:`~stcs_ident.simulate.field_response.superpose_field`.

    Parameters
    ----------
    rate : float
        1/s, linear trend of d.
    amplitude : float
        >= 0, of the sinusoid (relative tension).
    period : float
        s, > 0, of the sinusoid.
    phase : float
        rad, of the sinusoid at t = 0.
    walk : float
        >= 0, 1/√s: the random walk's standard deviation after t s is
        walk · √t.

    The realised |d| must stay within :data:`DRIFT_LIMIT` over the record
    (checked when simulating, field ``drift``).
    """

    rate: float = 0.0
    amplitude: float = 0.0
    period: float = 300.0
    phase: float = 0.0
    walk: float = 0.0

    def __post_init__(self):
        for name in ("rate", "phase"):
            object.__setattr__(self, name, real_number(getattr(self, name), f"drift.{name}"))
        for name in ("amplitude", "walk"):
            object.__setattr__(self, name, real_number(getattr(self, name), f"drift.{name}", nonnegative=True))
        object.__setattr__(self, "period", real_number(self.period, "drift.period", positive=True))


@dataclass(frozen=True)
class PinkNoise:
    """1/f sensor noise: power spectral density ∝ 1/f from 1/duration to Nyquist.

    Gaussian, independent between channels, zero mean (no power at 0 Hz).

    Parameters
    ----------
    rms : float or sequence of float
        >= 0, the expected rms over the record's band: m/s², or, if
        ``relative``, a fraction of the channel's clean signal rms. One for
        all channels or one per channel.
    relative : bool
        Levels relative to each channel's clean signal rms (the rms before
        any noise, as ``snr_db`` is).
    """

    rms: float | tuple[float, ...]
    relative: bool = False

    def __post_init__(self):
        object.__setattr__(self, "rms", _levels(self.rms, "pink_noise.rms", nonnegative=True))
        object.__setattr__(self, "relative", _flag(self.relative, "pink_noise.relative"))


@dataclass(frozen=True)
class MainsHum:
    """A common-mode hum at the mains frequency and its harmonics.

    Channel c reads g_c Σ_h a_h cos(2π h f₀ t + θ_h + φ_c), h = 1, 2, ...
    (m/s², or fractions of the channel's clean signal rms if ``relative``).
    Harmonics at or above the Nyquist frequency are skipped, as after an
    ideal anti-alias filter: none is aliased.

    Parameters
    ----------
    frequency : float
        f₀, Hz (> 0): 50 or 60, or a mains frequency a little off it.
    amplitudes : sequence of float
        a_h >= 0 of the harmonics h = 1, 2, ... (peak amplitudes).
    phases : sequence of float or None
        θ_h, rad, one per harmonic; default 0.
    channel_gains : float, sequence of float or None
        g_c >= 0, one for all channels or one per channel; default 1.
    channel_phases : float, sequence of float or None
        φ_c, rad, one for all channels or one per channel; default 0.
    relative : bool
        Amplitudes relative to each channel's clean signal rms.
    """

    frequency: float
    amplitudes: tuple[float, ...]
    phases: tuple[float, ...] | None = None
    channel_gains: float | tuple[float, ...] | None = None
    channel_phases: float | tuple[float, ...] | None = None
    relative: bool = False

    def __post_init__(self):
        object.__setattr__(self, "frequency", real_number(self.frequency, "hum.frequency", positive=True))
        amplitudes = _levels(self.amplitudes, "hum.amplitudes", nonnegative=True, sequence=True)
        object.__setattr__(self, "amplitudes", amplitudes)
        if self.phases is not None:
            phases = _levels(self.phases, "hum.phases", sequence=True)
            if len(phases) != len(amplitudes):
                raise ModelError(f"gives {len(phases)} phases for {len(amplitudes)} harmonics", field="hum.phases")
            object.__setattr__(self, "phases", phases)
        if self.channel_gains is not None:
            object.__setattr__(self, "channel_gains",
                               _levels(self.channel_gains, "hum.channel_gains", nonnegative=True))
        if self.channel_phases is not None:
            object.__setattr__(self, "channel_phases", _levels(self.channel_phases, "hum.channel_phases"))
        object.__setattr__(self, "relative", _flag(self.relative, "hum.relative"))


@dataclass(frozen=True)
class DcOffsets:
    """A constant offset per channel (m/s², or fractions of the clean signal rms if ``relative``).

    Parameters
    ----------
    values : float or sequence of float
        One for all channels or one per channel, of either sign.
    relative : bool
        Offsets relative to each channel's clean signal rms.
    """

    values: float | tuple[float, ...]
    relative: bool = False

    def __post_init__(self):
        object.__setattr__(self, "values", _levels(self.values, "dc_offsets.values"))
        object.__setattr__(self, "relative", _flag(self.relative, "dc_offsets.relative"))


@dataclass(frozen=True)
class FieldConditions:
    """The field-like disturbances of one record; each None (or False) is off.

    ``FieldConditions()`` changes nothing: the record is the one simulated
    without it, bit for bit.

    Parameters
    ----------
    ambient_lowpass : LowPassLoading or None
        Coloured ambient loading (needs ``ambient``).
    drift : TensionDrift or None
        Slow tension drift within the record.
    pink_noise : PinkNoise or None
        1/f sensor noise.
    hum : MainsHum or None
        Mains hum in every channel.
    dc_offsets : DcOffsets or None
        Offsets per channel.
    float32 : bool
        Samples rounded to float32 (and written as float32 by
        :func:`~stcs_ident.simulate.simulate_campaign.simulate_campaign`).
    """

    ambient_lowpass: LowPassLoading | None = None
    drift: TensionDrift | None = None
    pink_noise: PinkNoise | None = None
    hum: MainsHum | None = None
    dc_offsets: DcOffsets | None = None
    float32: bool = False

    def __post_init__(self):
        kinds = {"ambient_lowpass": LowPassLoading, "drift": TensionDrift, "pink_noise": PinkNoise,
                 "hum": MainsHum, "dc_offsets": DcOffsets}
        for name, kind in kinds.items():
            value = getattr(self, name)
            if value is not None and not isinstance(value, kind):
                raise ModelError(f"must be a {kind.__name__} or None, got {type(value).__name__}",
                                 field=f"field.{name}")
        object.__setattr__(self, "float32", _flag(self.float32, "field.float32"))

    @property
    def sensor_side(self) -> bool:
        """Whether any part acts on the sensors' output (pink noise, hum, offsets, float32)."""
        return any((self.pink_noise, self.hum, self.dc_offsets, self.float32))

    def to_dict(self) -> dict:
        """JSON-ready: the parts that are on, as dictionaries of their fields."""
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if value is None or value is False:
                continue
            out[f.name] = value if isinstance(value, bool) else _jsonable(asdict(value))
        return out


@dataclass(frozen=True, eq=False)
class RecordTruth:
    """What a simulated record truly holds, beside the model's frequencies.

    Parameters
    ----------
    frequencies : ndarray (N,)
        Hz, natural frequencies of the true model at its tension.
    tension : float
        N, the true tension (at t = 0 if it drifts).
    sampling_rate : float
        Hz.
    n_samples : int
    relative_tension : ndarray (n_samples,) or None
        d[n] of :class:`TensionDrift` at the samples; None: constant.
    sensitivities : ndarray (N,) or None
        s_k = d ln f_k / d ln H; None without drift.
    damping : ndarray (N,) or None
        Each mode's damping ratio: the modal damping given, or, for a cable
        with dampers, the complex mode's −Re(s)/|s| (its frequency above is
        |s|/2π); at t = 0 under a drift.
    out : RecordTruth or None
        The out-of-plane modes' truth (the same fields, of the out-of-plane
        model), when a channel reads out-of-plane motion or a bridge moves
        the anchorages; None otherwise. ``frequencies`` and ``damping``
        above are the in-plane ones.
    structural : tuple of StructuralMode
        The deck's and pylons' modes that moved the anchorages
        (:mod:`~stcs_ident.simulate.bridge`).
    misalignment : ndarray (n_channels,) or None
        Degrees, each sensor's true axis from its stated direction.
    channel_directions : tuple or None
        The stated direction of each channel (None: all in-plane, none given).
    crossings : ndarray or None
        s, start times of the vehicles' crossings (with traffic).
    """

    frequencies: np.ndarray
    tension: float
    sampling_rate: float
    n_samples: int
    relative_tension: np.ndarray | None = None
    sensitivities: np.ndarray | None = None
    damping: np.ndarray | None = None
    out: RecordTruth | None = None
    structural: tuple = ()
    misalignment: np.ndarray | None = None
    channel_directions: tuple | None = None
    crossings: np.ndarray | None = None

    @property
    def drifts(self) -> bool:
        return self.relative_tension is not None

    @property
    def frequencies_in(self) -> np.ndarray:
        """Hz, the in-plane modes' (``frequencies``)."""
        return self.frequencies

    @property
    def frequencies_out(self) -> np.ndarray | None:
        """Hz, the out-of-plane modes' (None when they were not simulated)."""
        return None if self.out is None else self.out.frequencies

    @property
    def damping_out(self) -> np.ndarray | None:
        """The out-of-plane modes' damping ratios (None when they were not simulated)."""
        return None if self.out is None else self.out.damping

    @property
    def structural_frequencies(self) -> np.ndarray:
        """Hz, of the structural modes that moved the anchorages (their harmonics not listed)."""
        return np.array([m.frequency for m in self.structural], dtype=float)

    def instantaneous_frequencies(self, mode: int) -> np.ndarray:
        """f_k(t_n) = f_k (1 + d[n])^s_k, Hz, at every sample, of mode ``mode`` (1-based)."""
        k = mode - 1
        if self.relative_tension is None:
            return np.full(self.n_samples, self.frequencies[k])
        return self.frequencies[k] * np.exp(self.sensitivities[k] * np.log1p(self.relative_tension))

    @property
    def mean_frequencies(self) -> np.ndarray:
        """Hz: each mode's instantaneous frequency averaged over the record's samples."""
        return np.array([np.mean(self.instantaneous_frequencies(k + 1)) for k in range(len(self.frequencies))])

    @property
    def mean_tension(self) -> float:
        """N, averaged over the record's samples."""
        if self.relative_tension is None:
            return float(self.tension)
        return float(self.tension * (1 + np.mean(self.relative_tension)))


# --------------------------------------------------------------------------
# Random field-like conditions
# --------------------------------------------------------------------------


def random_field_conditions(rng: np.random.Generator, sampling_rate: float, duration: float, n_channels: int, *,
                            probability: float = 0.75, ambient: bool = True,
                            mains_frequency: float | None = None) -> FieldConditions:
    """Field-like conditions for one record, drawn from ``rng`` (for calibration studies).

    Each part is on with ``probability``, independently; its parameters are
    drawn whether it is on or not, so the stream's use is fixed and the
    same rng state gives the same parameters for any ``probability``.
    Levels are relative to each channel's clean signal rms; ranges
    ("log" = log-uniform):

    - ambient low-pass (only if ``ambient``): corner 0.3–5 Hz (log, at most
      0.4 × sampling rate), order 1 or 2;
    - tension drift over the record: a linear change of ±(2e-5–2e-4) (log),
      a sinusoid of amplitude 1e-5–1e-4 (log), period 60–600 s, random
      phase, and a random walk reaching 1e-5–1e-4 (log, 1 σ) at the end:
      modal frequencies wander by about half that, 1e-5–1e-4;
    - pink noise: rms 0.01–0.1 of the signal's (log);
    - hum: 50 or 60 Hz (or ``mains_frequency``) ± 0.05 Hz, 1–5 harmonics,
      the fundamental 1e-3–3e-2 of the signal rms (log), each further
      harmonic 0.1–1 of the one before, random phases, channel gains
      0.5–1.5 and random channel phases;
    - DC offsets: ±(0.01–3) × the signal rms (log) per channel;
    - float32 samples.

    Parameters
    ----------
    rng : numpy.random.Generator
    sampling_rate, duration : float
        Hz and s of the record.
    n_channels : int
        For the per-channel values.
    probability : float
        0–1, of each part being on.
    ambient : bool
        Whether the record has ambient loading (else no low-pass is drawn on).
    mains_frequency : float or None
        Fix the mains frequency (Hz) instead of drawing 50 or 60.
    """
    fs = real_number(sampling_rate, "sampling_rate", positive=True)
    T = real_number(duration, "duration", positive=True)
    p = real_number(probability, "probability", nonnegative=True)
    if p > 1:
        raise ModelError(f"must lie in [0, 1], got {probability!r}", field="probability")
    if isinstance(n_channels, bool) or not isinstance(n_channels, int | np.integer) or n_channels < 1:
        raise ModelError(f"must be an integer >= 1, got {n_channels!r}", field="n_channels")

    def log_uniform(lo, hi, size=None):
        return np.exp(rng.uniform(math.log(lo), math.log(hi), size))

    on = rng.random(6) < p
    lowpass = LowPassLoading(min(float(log_uniform(0.3, 5.0)), 0.4 * fs), int(rng.integers(1, 3)))
    change = float(log_uniform(2e-5, 2e-4)) * (1 if rng.random() < 0.5 else -1)
    drift = TensionDrift(rate=change / T, amplitude=float(log_uniform(1e-5, 1e-4)),
                         period=float(rng.uniform(60.0, 600.0)), phase=float(rng.uniform(0, 2 * math.pi)),
                         walk=float(log_uniform(1e-5, 1e-4)) / math.sqrt(T))
    pink = PinkNoise(float(log_uniform(0.01, 0.1)), relative=True)
    mains = float(rng.choice([50.0, 60.0])) + float(rng.uniform(-0.05, 0.05))
    if mains_frequency is not None:
        mains = real_number(mains_frequency, "mains_frequency", positive=True)
    n_harm = int(rng.integers(1, 6))
    amps = float(log_uniform(1e-3, 3e-2)) * np.cumprod(np.concatenate([[1.0], rng.uniform(0.1, 1.0, n_harm - 1)]))
    hum = MainsHum(mains, tuple(amps), phases=tuple(rng.uniform(0, 2 * math.pi, n_harm)),
                   channel_gains=tuple(rng.uniform(0.5, 1.5, n_channels)),
                   channel_phases=tuple(rng.uniform(0, 2 * math.pi, n_channels)), relative=True)
    dc = DcOffsets(tuple(log_uniform(0.01, 3.0, n_channels) * rng.choice([-1.0, 1.0], n_channels)), relative=True)
    return FieldConditions(ambient_lowpass=lowpass if on[0] and ambient else None, drift=drift if on[1] else None,
                           pink_noise=pink if on[2] else None, hum=hum if on[3] else None,
                           dc_offsets=dc if on[4] else None, float32=bool(on[5]))


# --------------------------------------------------------------------------
# Checks
# --------------------------------------------------------------------------


def _levels(value, name: str, *, nonnegative: bool = False, sequence: bool = False) -> float | tuple[float, ...]:
    """A number or a non-empty sequence of numbers (only a sequence if ``sequence``), checked."""
    if np.ndim(value) == 0 and not sequence:
        return real_number(value, name, nonnegative=nonnegative)
    if isinstance(value, str) or np.ndim(value) != 1 or len(value) == 0:
        raise ModelError(f"must be a {'' if sequence else 'number or a '}non-empty sequence of numbers, "
                         f"got {value!r}", field=name)
    return tuple(real_number(v, name, nonnegative=nonnegative) for v in value)


def _flag(value, name: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise ModelError(f"must be True or False, got {value!r}", field=name)
    return bool(value)


def _jsonable(value):
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    return value

