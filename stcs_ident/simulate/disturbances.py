"""Field-like disturbances of a simulated record, all off by default.

Records simulated with white loading, a constant tension and white sensor
noise are kinder than field records. :class:`~.conditions.FieldConditions` groups what
field records carry besides the cable's response, each part optional and
validated when built (a :class:`~stcs_ident.core.errors.ModelError` names the
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
from collections.abc import Sequence

import numpy as np
from scipy.linalg import solve_discrete_lyapunov
from scipy.signal import butter

from ..core.errors import ModelError
from ..core.model import Attachment, Cable
from ..forward.dsm import natural_frequencies
from .conditions import DRIFT_LIMIT, FieldConditions, LowPassLoading, MainsHum, TensionDrift

__all__ = [
    "apply_sensor_disturbances", "check_field", "field_rng", "filter_state_space", "lowpass_force_filter",
    "mains_hum", "pink_noise", "relative_tension", "tension_sensitivities", "write_record_as",
]

_SENSITIVITY_STEP = 1e-3  # relative tension step of the central difference d ln f / d ln H


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
    """Write ``record`` with :func:`~stcs_ident.io.records.hdf5.write_record`, its samples as float32 if asked
    (whole or not at all, as write_record)."""
    from ..io.records.hdf5 import write_record

    write_record(record, path, float32=float32)




# --------------------------------------------------------------------------
# Checks
# --------------------------------------------------------------------------


def _per_channel(value, n: int, name: str, default: float | None) -> np.ndarray:
    if value is None:
        return np.full(n, default)
    if np.ndim(value) == 0:
        return np.full(n, float(value))
    if len(value) != n:
        raise ModelError(f"gives {len(value)} values for {n} channels", field=name)
    return np.asarray(value, dtype=float)
