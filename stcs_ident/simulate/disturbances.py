"""Field-like disturbances of a simulated record, all off by default.

Records simulated with white loading, a constant tension and white sensor
noise are kinder than field records. :class:`FieldConditions` groups what
field records carry besides the cable's response, each part optional and
validated when built (a :class:`~stcs_ident.errors.ModelError` names the
field, e.g. ``drift.period``):

- :class:`LowPassLoading`: the ambient pressure coloured by a Butterworth
  low-pass (wind buffeting: most energy below a few Hz);
- :class:`TensionDrift`: the tension drifts slowly within the record
  (linear trend, slow sinusoid, random walk), so each modal frequency
  wanders; the record's time-averaged frequencies are the truth to report
  (:class:`RecordTruth`);
- :class:`PinkNoise`: 1/f sensor noise, besides the white noise of
  ``snr_db``;
- :class:`MainsHum`: a common-mode hum at the mains frequency and its
  harmonics in every channel, each channel with its own gain and phase;
  harmonics at or above the Nyquist frequency are **skipped**, as after an
  ideal anti-alias filter (none is aliased);
- :class:`DcOffsets`: a constant offset per channel;
- ``float32``: the samples rounded to single precision, and written so.

Hand blows under continuing ambient excitation need nothing here: give
both ``impulses`` and ``ambient`` to
:func:`~stcs_ident.simulate.simulate.simulate_record`; the responses add
(the model is linear) and the ambient goes on through the decays.

The sensor-side parts (pink noise, hum, offsets, float32) are applied after
the white noise, in that order. Their random draws (and the drift's random
walk) come from a stream independent of the one that makes the signal and
the white noise, so turning one of them on leaves the rest of the record as
it was (a coloured loading or a drift makes another signal).
:func:`random_field_conditions` draws field-like conditions for a record
from a seeded generator.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields

import numpy as np
from scipy.linalg import solve_discrete_lyapunov
from scipy.signal import butter

from ..errors import ModelError
from ..forward.dsm import natural_frequencies
from ..model import Attachment, Cable

__all__ = [
    "DRIFT_LIMIT", "DcOffsets", "FieldConditions", "LowPassLoading", "MainsHum", "PinkNoise", "RecordTruth",
    "TensionDrift", "apply_sensor_disturbances", "check_field", "field_rng", "lowpass_force_filter", "mains_hum", "pink_noise",
    "random_field_conditions", "relative_tension", "tension_sensitivities", "write_record_as",
]

#: Largest relative tension excursion a drift may reach within a record: beyond it the fixed mode shapes
#: and the frequencies' power law in the tension (fitted at the true tension) would no longer hold.
DRIFT_LIMIT = 0.01
_SENSITIVITY_STEP = 1e-3  # relative tension step of the central difference d ln f / d ln H


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
                           _number(self.corner_frequency, "ambient_lowpass.corner_frequency", positive=True))
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
            object.__setattr__(self, name, _number(getattr(self, name), f"drift.{name}"))
        for name in ("amplitude", "walk"):
            object.__setattr__(self, name, _number(getattr(self, name), f"drift.{name}", nonnegative=True))
        object.__setattr__(self, "period", _number(self.period, "drift.period", positive=True))


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
        object.__setattr__(self, "frequency", _number(self.frequency, "hum.frequency", positive=True))
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
    """

    frequencies: np.ndarray
    tension: float
    sampling_rate: float
    n_samples: int
    relative_tension: np.ndarray | None = None
    sensitivities: np.ndarray | None = None

    @property
    def drifts(self) -> bool:
        return self.relative_tension is not None

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
# Realising them
# --------------------------------------------------------------------------


def check_field(field, n_channels: int, sampling_rate: float, has_ambient: bool) -> None:
    """Refuse, before simulating, what ``field`` cannot do for this record (the error names the field)."""
    if not isinstance(field, FieldConditions):
        raise ModelError(f"must be a FieldConditions or None, got {type(field).__name__}", field="field")
    if field.ambient_lowpass is not None:
        if not has_ambient:
            raise ModelError("colours the ambient loading: give ambient too", field="ambient_lowpass")
        lowpass_force_filter(field.ambient_lowpass, sampling_rate)
    checks = []
    if field.pink_noise is not None:
        checks.append((field.pink_noise.rms, "pink_noise.rms"))
    if field.hum is not None:
        checks += [(field.hum.channel_gains, "hum.channel_gains"), (field.hum.channel_phases, "hum.channel_phases")]
    if field.dc_offsets is not None:
        checks.append((field.dc_offsets.values, "dc_offsets.values"))
    for value, name in checks:
        _per_channel(value, n_channels, name, 0.0)


def field_rng(rng: np.random.Generator) -> np.random.Generator:
    """The stream of the disturbances' random draws: ``rng``'s bit generator jumped ahead (independent)."""
    jumped = getattr(rng.bit_generator, "jumped", None)
    if jumped is None:
        raise ModelError(f"a {type(rng.bit_generator).__name__} cannot give the disturbances an independent "
                         "stream: pass an int or a SeedSequence", field="seed")
    return np.random.Generator(jumped())


def lowpass_force_filter(loading: LowPassLoading, sampling_rate: float) -> tuple[np.ndarray, np.ndarray]:
    """IIR (b, a) of the ambient's low-pass, scaled so that white input keeps its variance.

    Butterworth (bilinear transform with pre-warping: −3 dB at the corner).
    The output variance of unit white input is P₀₀ + b₀², P the stationary
    covariance of lfilter's state; b is divided by its square root.
    """
    fs = float(sampling_rate)
    if loading.corner_frequency >= fs / 2:
        raise ModelError(f"{loading.corner_frequency:g} Hz is not below the Nyquist frequency ({fs / 2:g} Hz)",
                         field="ambient_lowpass.corner_frequency")
    b, a = butter(loading.order, loading.corner_frequency, btype="low", fs=fs)
    b, a = np.asarray(b, float) / a[0], np.asarray(a, float) / a[0]
    Af, Bf = filter_state_space(b, a)
    P = solve_discrete_lyapunov(Af, np.outer(Bf, Bf))
    return b / math.sqrt(P[0, 0] + b[0] ** 2), a


def filter_state_space(b: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) of lfilter's transposed direct form II state z (a[0] = 1): z' = A z + B u, y = z₀ + b₀ u."""
    m = len(a) - 1
    A = np.zeros((m, m))
    A[:, 0] = -a[1:]
    A[np.arange(m - 1), np.arange(1, m)] = 1.0
    return A, b[1:] - a[1:] * b[0]


def relative_tension(drift: TensionDrift, n_samples: int, sampling_rate: float,
                     rng: np.random.Generator) -> np.ndarray:
    """d[n] = d(n / sampling_rate) of ``drift`` (the random walk drawn from ``rng`` only if walk > 0)."""
    t = np.arange(n_samples) / sampling_rate
    d = drift.rate * t
    if drift.amplitude:
        d = d + drift.amplitude * (np.sin(2 * np.pi * t / drift.period + drift.phase) - math.sin(drift.phase))
    if drift.walk:
        steps = rng.standard_normal(n_samples - 1) * (drift.walk / math.sqrt(sampling_rate))
        d = d + np.concatenate([[0.0], np.cumsum(steps)])
    worst = float(np.max(np.abs(d)))
    if worst > DRIFT_LIMIT:
        raise ModelError(f"reaches a relative tension change of {worst:.3g} within the record; at most "
                         f"{DRIFT_LIMIT:g} is simulated", field="drift")
    return d


def tension_sensitivities(cable: Cable, attachments: Sequence[Attachment], tension: float,
                          n_modes: int) -> np.ndarray:
    """s_k = d ln f_k / d ln H of the first ``n_modes`` modes, by a central difference (step 1e-3).

    The frequencies are exact to 1e-12, so s_k is to ~1e-9; its own change
    over the step is second order and does not matter within DRIFT_LIMIT.
    """
    e = _SENSITIVITY_STEP
    up = natural_frequencies(cable, attachments, tension * (1 + e), n_modes)
    down = natural_frequencies(cable, attachments, tension * (1 - e), n_modes)
    return np.log(up / down) / math.log((1 + e) / (1 - e))


def pink_noise(n_samples: int, sampling_rate: float, rms: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """(n_samples, len(rms)) Gaussian noise with PSD ∝ 1/f from 1/duration to Nyquist, expected rms ``rms``.

    Built in the frequency domain: bin k (0 < k <= n/2) gets amplitude
    f_k^(−1/2) times a complex normal, the mean (k = 0) none. Of
    ``irfft``, Var x = (4 Σ_{0<k<n/2} w_k² + w_{n/2}²) / n² (the last term
    for even n only, whose Nyquist bin is real), which scales it.
    """
    rms = np.asarray(rms, dtype=float)
    n = int(n_samples)
    k = np.arange(1, n // 2 + 1)
    w = np.zeros(n // 2 + 1)
    w[1:] = (k * sampling_rate / n) ** -0.5
    spectrum = (rng.standard_normal((w.size, rms.size)) + 1j * rng.standard_normal((w.size, rms.size))) * w[:, None]
    power = 4 * np.sum(w[1:] ** 2)
    if n % 2 == 0:
        power -= 3 * w[-1] ** 2  # the Nyquist bin: one real part, counted once
        spectrum[-1] = spectrum[-1].real
    return np.fft.irfft(spectrum, n, axis=0) * (rms / math.sqrt(power / n**2))


def mains_hum(n_samples: int, sampling_rate: float, hum: MainsHum, scale: np.ndarray) -> np.ndarray:
    """(n_samples, n_channels) hum; ``scale`` (n_channels,) multiplies each channel (1, or its rms if relative).

    Harmonics at or above Nyquist are skipped (an ideal anti-alias filter).
    """
    n_ch = len(scale)
    gains = _per_channel(hum.channel_gains, n_ch, "hum.channel_gains", 1.0) * scale
    offsets = _per_channel(hum.channel_phases, n_ch, "hum.channel_phases", 0.0)
    phases = hum.phases or (0.0,) * len(hum.amplitudes)
    t = np.arange(n_samples) / sampling_rate
    out = np.zeros((n_samples, n_ch))
    for h, (amp, theta) in enumerate(zip(hum.amplitudes, phases), start=1):
        f = h * hum.frequency
        if f >= sampling_rate / 2 or amp == 0:
            continue
        out += amp * gains * np.cos(2 * np.pi * f * t[:, None] + theta + offsets)
    return out


def apply_sensor_disturbances(signal: np.ndarray, clean: np.ndarray, sampling_rate: float,
                              field: FieldConditions, rng: np.random.Generator) -> np.ndarray:
    """``signal`` plus pink noise, hum and offsets, then rounded to float32, as ``field`` says.

    ``clean`` is the noise-free signal: relative levels are fractions of its
    rms per channel. ``rng`` is the disturbances' own stream.
    """
    if not field.sensor_side:
        return signal
    n, n_ch = signal.shape
    clean_rms = np.sqrt(np.mean(clean**2, axis=0))
    out = np.array(signal, dtype=float)
    if (p := field.pink_noise) is not None:
        rms = _per_channel(p.rms, n_ch, "pink_noise.rms", None) * (clean_rms if p.relative else 1.0)
        out += pink_noise(n, sampling_rate, rms, rng)
    if (h := field.hum) is not None:
        out += mains_hum(n, sampling_rate, h, clean_rms if h.relative else np.ones(n_ch))
    if (d := field.dc_offsets) is not None:
        out += _per_channel(d.values, n_ch, "dc_offsets.values", None) * (clean_rms if d.relative else 1.0)
    if field.float32:
        out = out.astype(np.float32).astype(np.float64)
    return out


def write_record_as(record, path: str | os.PathLike, *, float32: bool = False) -> None:
    """Write ``record`` with :func:`~stcs_ident.spectra.io_hdf5.write_record`, its samples as float32 if asked.

    The layout is io_hdf5's; for float32 the file is copied with the
    acceleration dataset cast (whole or not at all, as write_record).
    """
    import h5py

    from ..spectra.io_hdf5 import write_record

    write_record(record, path)
    if not float32:
        return
    target = os.fspath(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(target)}.", dir=os.path.dirname(target) or ".")
    os.close(fd)
    try:
        with h5py.File(target, "r") as src, h5py.File(tmp, "w") as dst:
            dst.attrs.update(dict(src.attrs))
            for name in src:
                if name == "acceleration":
                    dst.create_dataset(name, data=np.asarray(src[name][()], dtype=np.float32))
                else:
                    src.copy(name, dst)
        os.chmod(tmp, os.stat(target).st_mode & 0o777)
        os.replace(tmp, target)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


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
    fs = _number(sampling_rate, "sampling_rate", positive=True)
    T = _number(duration, "duration", positive=True)
    p = _number(probability, "probability", nonnegative=True)
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
        mains = _number(mains_frequency, "mains_frequency", positive=True)
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


def _number(value, name: str, *, positive: bool = False, nonnegative: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise ModelError(f"must be a number, got {value!r}", field=name)
    v = float(value)
    if not math.isfinite(v) or (positive and v <= 0) or (nonnegative and v < 0):
        bound = " > 0" if positive else " >= 0" if nonnegative else ""
        raise ModelError(f"must be a finite number{bound}, got {value!r}", field=name)
    return v


def _levels(value, name: str, *, nonnegative: bool = False, sequence: bool = False) -> float | tuple[float, ...]:
    """A number or a non-empty sequence of numbers (only a sequence if ``sequence``), checked."""
    if np.ndim(value) == 0 and not sequence:
        return _number(value, name, nonnegative=nonnegative)
    if isinstance(value, str) or np.ndim(value) != 1 or len(value) == 0:
        raise ModelError(f"must be a {'' if sequence else 'number or a '}non-empty sequence of numbers, "
                         f"got {value!r}", field=name)
    return tuple(_number(v, name, nonnegative=nonnegative) for v in value)


def _flag(value, name: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise ModelError(f"must be True or False, got {value!r}", field=name)
    return bool(value)


def _per_channel(value, n: int, name: str, default: float | None) -> np.ndarray:
    if value is None:
        return np.full(n, default)
    if np.ndim(value) == 0:
        return np.full(n, float(value))
    if len(value) != n:
        raise ModelError(f"gives {len(value)} values for {n} channels", field=name)
    return np.asarray(value, dtype=float)


def _jsonable(value):
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    return value
