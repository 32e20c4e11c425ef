"""Modal peaks from acceleration records: detection, accuracy against the Cramér–Rao bound, honesty of 1σ.

Every record is synthetic, from known parameters and a seeded generator:
free decays are sums of damped sinusoids with mode shapes sin(kπx/l) at
the sensors; ambient records are white noise through the exact
(impulse-invariant) discrete SDOF filter of each mode. Sensor noise is
white. Tolerances are written out with their reason.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import signal, stats

from stcs_ident.core.errors import InputError
from stcs_ident.core.record import Record
from stcs_ident.spectra.crb import crb_decay_rate, crb_frequency
from stcs_ident.spectra.peaks import PeakResult, find_peaks

# ----------------------------------------------------------------------------------------------
# Synthetic records


def mode_shapes(positions, length: float, n_modes: int) -> np.ndarray:
    """sin(kπx/l) at the sensors, shape (n_modes, n_channels)."""
    k = np.arange(1, n_modes + 1)[:, None]
    return np.sin(k * np.pi * np.asarray(positions, dtype=float)[None, :] / length)


def make_record(x: np.ndarray, fs: float, positions) -> Record:
    names = tuple(f"A{i + 1}" for i in range(x.shape[1]))
    return Record(x, fs, names, np.asarray(positions, dtype=float))


def free_decay(frequencies, zeta, amplitudes, positions, length, fs, duration, onsets, rng):
    """Noise-free free decays: blows at `onsets` (s), each mode with a random phase per blow."""
    n = round(duration * fs)
    t = np.arange(n) / fs
    shapes = mode_shapes(positions, length, len(frequencies))
    x = np.zeros((n, len(positions)))
    for t0 in onsets:
        i0 = round(t0 * fs)
        tt = t[i0:] - t[i0]
        for k, f in enumerate(frequencies):
            sigma, omega_d = zeta * 2 * np.pi * f, 2 * np.pi * f * np.sqrt(1 - zeta**2)
            wave = amplitudes[k] * np.exp(-sigma * tt) * np.cos(omega_d * tt + rng.uniform(0, 2 * np.pi))
            x[i0:] += np.outer(wave, shapes[k])
    return x, shapes


def ambient(frequencies, zeta, positions, length, fs, duration, rng):
    """Noise-free ambient response: each modal coordinate is white noise through its exact discrete SDOF filter."""
    n, dt = round(duration * fs), 1.0 / fs
    shapes = mode_shapes(positions, length, len(frequencies))
    x = np.zeros((n, len(positions)))
    for k, f in enumerate(frequencies):
        sigma, omega_d = zeta * 2 * np.pi * f, 2 * np.pi * f * np.sqrt(1 - zeta**2)
        r = np.exp(-sigma * dt)
        b, a = [0.0, r * np.sin(omega_d * dt)], [1.0, -2 * r * np.cos(omega_d * dt), r**2]
        x += np.outer(signal.lfilter(b, a, rng.standard_normal(n)), shapes[k])
    return x


def hanger_frequencies(n_modes: int = 8) -> np.ndarray:
    """Pinned tensioned beam: l = 8 m, m = 30 kg/m, H = 400 kN, EI = 2e5 N m² (a short stiff hanger)."""
    length, mass, tension, ei = 8.0, 30.0, 4.0e5, 2.0e5
    k = np.arange(1, n_modes + 1)
    return k / (2 * length) * np.sqrt(tension / mass) * np.sqrt(1 + (k * np.pi) ** 2 * ei / (tension * length**2))


HANGER = {"length": 8.0, "positions": [0.9, 2.3, 3.7], "fs": 1024.0, "zeta": 0.003, "blow_at": 1.1}


def hanger_record(onsets, seed: int, duration: float = 60.0) -> tuple[Record, np.ndarray]:
    """3 sensors, ζ = 0.3 %, blows at 1.1 m (acceleration amplitude ∝ ω φ(x₀)), noise rms 2 % of signal rms."""
    rng = np.random.default_rng(seed)
    f = hanger_frequencies()
    k = np.arange(1, f.size + 1)
    amplitudes = 2 * np.pi * f * np.sin(k * np.pi * HANGER["blow_at"] / HANGER["length"]) / 100.0
    x, _ = free_decay(
        f, HANGER["zeta"], amplitudes, HANGER["positions"], HANGER["length"], HANGER["fs"], duration, onsets, rng
    )
    x += 0.02 * x.std() * rng.standard_normal(x.shape)
    return make_record(x, HANGER["fs"], HANGER["positions"]), f


def match(result: PeakResult, truth, rtol: float = 0.01):
    """For each true frequency, the nearest peak within rtol (or None)."""
    found = np.array([p.frequency for p in result.peaks])
    out = []
    for f in truth:
        i = int(np.argmin(np.abs(found - f))) if found.size else -1
        out.append(result.peaks[i] if i >= 0 and abs(found[i] - f) <= rtol * f else None)
    return out


def normalised_errors(result: PeakResult, truth) -> np.ndarray:
    peaks = match(result, truth)
    assert all(p is not None for p in peaks), f"missed modes: {[f for f, p in zip(truth, peaks) if p is None]}"
    return np.array([(p.frequency - f) / p.uncertainty for p, f in zip(peaks, truth)])


# A single normalised error beyond this is a failure of the 1σ (probability 6e-5 per value if honest).
Z_LIMIT = 4.0


# ----------------------------------------------------------------------------------------------
# Cramér–Rao bound


def numerical_fisher_std(amplitude, noise_std, n, fs, frequency, decay_rate, phase=0.4):
    """1σ of f and σ from the exact Fisher matrix of a real damped sinusoid (numerical derivatives)."""
    t = np.arange(n) / fs
    p0 = np.array([2 * np.pi * frequency, decay_rate, amplitude, phase])

    def model(p):
        return p[2] * np.exp(-p[1] * t) * np.cos(p[0] * t + p[3])

    jac = []
    for i in range(4):
        step = np.zeros(4)
        step[i] = 1e-6 * max(1.0, abs(p0[i]))
        jac.append((model(p0 + step) - model(p0 - step)) / (2 * step[i]))
    jac = np.array(jac).T
    cov = np.linalg.inv(jac.T @ jac / noise_std**2)
    return np.sqrt(cov[0, 0]) / (2 * np.pi), np.sqrt(cov[1, 1])


def test_crb_matches_exact_fisher_information():
    # The closed form drops sin·cos cross terms; with ~2000 periods recorded they are below 1 %.
    f_std, s_std = numerical_fisher_std(1.3, 0.2, 5000, 100.0, 7.3, 0.8)
    assert crb_frequency([1.3], 0.2, 5000, 100.0, decay_rate=0.8) == pytest.approx(f_std, rel=0.01)
    assert crb_decay_rate([1.3], 0.2, 5000, 100.0, decay_rate=0.8) == pytest.approx(s_std, rel=0.01)


def test_crb_undamped_closed_form_and_channels_add():
    n, fs, a, s = 1000, 50.0, 2.0, 0.3
    classical = np.sqrt(6 * s**2 / (np.pi**2 * a**2 * fs**-2 * n * (n**2 - 1)))
    assert crb_frequency([a], s, n, fs) == pytest.approx(classical, rel=1e-9)  # same formula, rounding only
    # Fisher information adds over channels and events: two equal channels give 1/√2 of one.
    assert crb_frequency([a, a], s, n, fs) == pytest.approx(classical / np.sqrt(2), rel=1e-9)
    two_events = crb_frequency([[a], [a]], s, [n, n], fs)
    assert two_events == pytest.approx(classical / np.sqrt(2), rel=1e-9)


# ----------------------------------------------------------------------------------------------
# Free decays


def test_free_decay_sensor_at_node_sees_mode_through_the_others():
    rng = np.random.default_rng(11)
    length, positions = 20.0, [5.0, 10.0, 13.3]  # 10 m is the node of mode 2 (and 4)
    truth = np.array([2.0 * k * np.sqrt(1 + 0.002 * k * k) for k in range(1, 5)])
    x, shapes = free_decay(truth, 0.005, np.ones(4), positions, length, 128.0, 60.0, [2.0], rng)
    x += 0.01 * rng.standard_normal(x.shape)  # 37 dB below a unit mode
    result = find_peaks(make_record(x, 128.0, positions))
    assert result.kind == "impulse" and len(result.events) == 1
    assert len(result.peaks) == 4
    z = normalised_errors(result, truth)
    assert np.all(np.abs(z) < Z_LIMIT)
    mode2 = match(result, truth)[1]
    assert mode2.channels == ("A1", "A3")
    # Channels with |φ| ≥ 0.5 see every mode (40 dB SNR: far above the 6 dB rule).
    for peak, phi in zip(match(result, truth), shapes):
        assert {f"A{c + 1}" for c in np.flatnonzero(np.abs(phi) >= 0.5)} <= set(peak.channels)
    # The sign pattern of the amplitudes is the sampled mode shape.
    assert np.sign(mode2.amplitude[[0, 2]]).tolist() == np.sign(shapes[1][[0, 2]]).tolist()


def interpolated_dft(segment: np.ndarray, fs: float, f_guess: float, padding: int = 8) -> float:
    """The classical estimator: parabola through the log of the zero-padded periodogram (summed over channels)."""
    n_fft = padding * segment.shape[0]
    power = (np.abs(np.fft.rfft(segment, n=n_fft, axis=0)) ** 2).sum(axis=1)
    k = round(f_guess * n_fft / fs)
    k += int(np.argmax(power[k - padding : k + padding + 1])) - padding
    y = np.log(power[k - 1 : k + 2])
    return (k + 0.5 * (y[0] - y[2]) / (y[0] - 2 * y[1] + y[2])) * fs / n_fft


def _free_decay_errors(seed: int) -> tuple[list, list, list]:
    """One record of the test below: per mode |error| / CRB, error / 1σ, and the interpolated DFT's |error| / CRB."""
    fs, length, positions = 128.0, 20.0, [5.0, 10.0, 13.3]
    truth, zeta = np.array([3.1, 6.25, 9.4]), 0.005
    ratio, z, ratio_idft = [], [], []
    rng = np.random.default_rng(1000 + seed)
    snr_db = rng.uniform(20.0, 40.0)
    noise = np.sqrt(0.5 / 10 ** (snr_db / 10))
    x, shapes = free_decay(truth, zeta, np.ones(3), positions, length, fs, 30.0, [1.0], rng)
    x += noise * rng.standard_normal(x.shape)
    result = find_peaks(make_record(x, fs, positions))
    [event] = result.events
    start, stop = round(event[0] * fs), round(event[1] * fs)
    for peak, f, phi in zip(match(result, truth), truth, shapes):
        crb = crb_frequency(phi, noise, stop - start, fs, decay_rate=zeta * 2 * np.pi * f)
        ratio.append(abs(peak.frequency - f) / crb)
        z.append((peak.frequency - f) / peak.uncertainty)
        f_damped = f * np.sqrt(1 - zeta**2)  # the periodogram peaks at the damped frequency
        ratio_idft.append(abs(interpolated_dft(x[start:stop], fs, f) - f_damped) / crb)
    return ratio, z, ratio_idft


@pytest.mark.slow
def test_free_decay_accuracy_against_cramer_rao_and_honest_uncertainty():
    """40 records, 3 channels, 3 modes, SNR drawn in 20–40 dB (A²/2s² of a unit mode)."""
    ratio, z, ratio_idft = [], [], []
    # One test over all records, in seed order: the medians and the KS test are statistics of them all.
    for r, zz, r_idft in map(_free_decay_errors, range(40)):
        ratio += r
        z += zz
        ratio_idft += r_idft
    ratio, z = np.array(ratio), np.array(z)
    # Acceptance: median |error| within 2 CRB σ (an efficient estimator gives 0.674; measured ≈ 0.75).
    assert np.median(ratio) <= 2.0
    # The parametric fit is kept because it beats the interpolated DFT (measured: 2.3 against 0.72 here).
    assert np.median(ratio_idft) > 1.5 * np.median(ratio)
    # Honesty: for z ~ N(0, 1), median |z| = 0.674 with a sampling sd of 0.07 over 120 values;
    # the window is ±3 sd, widened upward by 10 % for the asymptotic (Fisher) 1σ at 20 dB.
    assert 0.45 <= np.median(np.abs(z)) <= 0.95
    assert stats.kstest(z, "norm").pvalue > 0.001
    assert np.max(np.abs(z)) < 5.0  # 120 values: P(max |z| > 5) = 7e-5 if honest


def test_short_stiff_hanger_one_blow_first_eight_modes():
    record, truth = hanger_record(onsets=[5.0], seed=1)
    result = find_peaks(record)
    assert result.kind == "impulse" and len(result.events) == 1
    relative = np.abs([(p.frequency - f) / f for p, f in zip(match(result, truth), truth)])
    assert np.median(relative) <= 2e-4  # the requirement; measured ≈ 1e-6
    assert np.all(np.abs(normalised_errors(result, truth)) < Z_LIMIT)
    dampings = np.array([p.damping for p in match(result, truth)])
    np.testing.assert_allclose(dampings, HANGER["zeta"], rtol=0.05)  # 1σ ≤ 1 % at this SNR


def test_repeated_blows_overlapping_decays_no_fringes():
    """5 blows 8 s apart: the first mode has decayed only to 1/3 when the next blow comes."""
    one, truth = hanger_record(onsets=[5.0], seed=2)
    five, _ = hanger_record(onsets=[5.0, 13.0, 21.0, 29.0, 37.0], seed=2)
    single, repeated = find_peaks(one), find_peaks(five)
    assert len(repeated.events) == 5
    for (start, end), next_blow in zip(repeated.events, [13.0, 21.0, 29.0, 37.0]):
        assert start > next_blow - 8.0 and end < next_blow  # each segment stops before the next blow
    rel_single = np.median(np.abs([(p.frequency - f) / f for p, f in zip(match(single, truth), truth)]))
    rel_repeated = np.median(np.abs([(p.frequency - f) / f for p, f in zip(match(repeated, truth), truth)]))
    assert len(repeated.peaks) == len(truth)  # no fringe peaks
    assert rel_repeated <= 2e-4
    # As accurate as one blow: within a factor 3 (both are a few 1e-6; fringes would give ~1e-3).
    assert rel_repeated <= 3 * max(rel_single, 1e-6)
    assert np.all(np.abs(normalised_errors(repeated, truth)) < Z_LIMIT)


def test_blow_with_ambient_loading_underneath():
    """A blow on a cable that wind keeps moving: modes the blow barely excites are random resonances."""
    rng = np.random.default_rng(5)
    fs, length, positions = 512.0, 8.0, HANGER["positions"]
    truth = hanger_frequencies(6)
    k = np.arange(1, 7)
    amplitudes = 2 * np.pi * truth * np.sin(k * np.pi * 1.1 / length) / 100.0
    x, _ = free_decay(truth, 0.003, amplitudes, positions, length, fs, 60.0, [5.0], rng)
    wind = ambient(truth, 0.003, positions, length, fs, 60.0, rng)
    x += 0.3 * x.std() / wind.std() * wind
    x += 0.02 * x.std() * rng.standard_normal(x.shape)
    result = find_peaks(make_record(x, fs, positions))
    assert len(result.peaks) == len(truth)
    assert np.all(np.abs(normalised_errors(result, truth)) < Z_LIMIT)


# ----------------------------------------------------------------------------------------------
# Ambient records


def test_ambient_frequencies_and_damping():
    rng = np.random.default_rng(7)
    fs, length, positions, zeta = 64.0, 20.0, [5.0, 10.0, 13.3], 0.01
    truth = np.array([2.0, 4.05, 6.1, 8.2])
    x = ambient(truth, zeta, positions, length, fs, 600.0, rng)
    x += 0.3 * x.std() * rng.standard_normal(x.shape)
    result = find_peaks(make_record(x, fs, positions))
    assert result.kind == "ambient" and result.events == []
    assert len(result.peaks) == 4
    assert np.all(np.abs(normalised_errors(result, truth)) < Z_LIMIT)
    peaks = match(result, truth)
    dampings = np.array([p.damping for p in peaks])
    damping_z = (dampings - zeta) / np.array([p.damping_uncertainty for p in peaks])
    # Reported 1σ of ζ is 10–17 % here: the median over modes within 30 %, each within 4σ.
    assert np.median(np.abs(dampings / zeta - 1)) <= 0.3
    assert np.all(np.abs(damping_z) < Z_LIMIT)
    # Sensor at 10 m: the node of modes 2 and 4, so it does not see them.
    assert "A2" not in peaks[1].channels and "A2" not in peaks[3].channels
    assert "A2" in peaks[0].channels


@pytest.mark.parametrize("n_channels", [1, 3, 16])
def test_pure_noise_gives_no_peaks(n_channels):
    """False-alarm control: white and low-pass noise, 5 records each, no peak and no blow."""
    for seed in range(5):
        rng = np.random.default_rng(seed)
        white = rng.standard_normal((120 * 128, n_channels))
        b, a = signal.butter(2, 0.2)
        coloured = signal.lfilter(b, a, white, axis=0) + 0.05 * white
        for x in (white, coloured):
            result = find_peaks(make_record(x, 128.0, np.arange(n_channels, dtype=float)))
            assert result.peaks == [], [p.frequency for p in result.peaks]
            assert result.kind == "ambient"


# ----------------------------------------------------------------------------------------------
# Interface


def test_result_tables_and_frequency_band():
    rng = np.random.default_rng(3)
    truth = np.array([2.0, 4.02, 6.06])
    x, _ = free_decay(truth, 0.005, np.ones(3), [5.0, 10.0, 13.3], 20.0, 64.0, 40.0, [1.0], rng)
    x += 0.01 * rng.standard_normal(x.shape)
    record = make_record(x, 64.0, [5.0, 10.0, 13.3])
    result = find_peaks(record)
    table = result.to_dataframe()
    assert list(table.columns[:6]) == [
        "frequency_Hz",
        "uncertainty_Hz",
        "damping_ratio",
        "damping_ratio_uncertainty",
        "snr_db",
        "channels",
    ]
    assert "amplitude_m_per_s2[A2]" in table.columns and len(table) == 3
    summary = json.loads(json.dumps(result.summary()))
    assert summary["kind"] == "impulse" and len(summary["frequencies"]) == 3
    assert result.channel_spectra.shape == (result.frequency_axis.size, 3)
    banded = find_peaks(record, f_min=3.0, f_max=7.0)
    assert [round(p.frequency, 1) for p in banded.peaks] == [4.0, 6.1]
    assert len(find_peaks(record, max_peaks=1).peaks) == 1
    assert find_peaks(record, kind="ambient").kind == "ambient"


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"kind": "random"}, "kind"),
        ({"f_max": 40.0}, "f_max"),
        ({"f_min": 5.0, "f_max": 4.0}, "f_max"),
        ({"f_min": -1.0}, "f_min"),
        ({"max_peaks": 0}, "max_peaks"),
        ({"min_snr_db": float("nan")}, "min_snr_db"),
    ],
)
def test_bad_arguments_name_the_field(kwargs, field):
    record = make_record(np.random.default_rng(0).standard_normal((1024, 2)), 64.0, [1.0, 2.0])
    with pytest.raises(InputError, match=field) as info:
        find_peaks(record, **kwargs)
    assert info.value.field == field


def test_non_finite_record_is_refused():
    x = np.random.default_rng(0).standard_normal((1024, 2))
    x[10, 1] = np.nan
    with pytest.raises(InputError, match="acceleration"):
        find_peaks(make_record(x, 64.0, [1.0, 2.0]))


# ----------------------------------------------------------------------------------------------
# Speed


@pytest.mark.slow
def test_sixteen_channels_ten_minutes_finds_every_mode():
    # Its time (the 2 s) is measured by benchmarks/spectra.py --throughput, not asserted here:
    # a timed test fails on a loaded machine and says nothing about the code.
    rng = np.random.default_rng(0)
    fs, length = 256.0, 100.0
    positions = np.linspace(4.7, 89.0, 16)
    truth = np.array([1.1 * k * np.sqrt(1 + 0.001 * k * k) for k in range(1, 21)])
    x = ambient(truth, 0.005, positions, length, fs, 600.0, rng)
    x += 0.2 * x.std() * rng.standard_normal(x.shape)
    record = make_record(x, fs, positions)
    result = find_peaks(record)
    assert len(result.peaks) == 20
    found = np.sort([p.frequency for p in result.peaks])
    assert np.all(np.abs(found - truth) < 0.01 * truth)


# ----------------------------------------------------------------------------------------------
# Guards found on field-like records (benchmarks/validate_diagnosis.py, stay seed 1009)


def _peak(frequency: float, uncertainty: float, snr_db: float):
    from stcs_ident.spectra.peaks import Peak

    return Peak(frequency=frequency, uncertainty=uncertainty, damping=0.002, damping_uncertainty=0.001,
                channels=("A1",), amplitude=np.ones(1), snr_db=snr_db, channel_snr_db=np.full(1, snr_db))


def test_a_wide_uncertainty_does_not_swallow_well_located_neighbours():
    """A fundamental whose fit returned σ = 5 Hz (the strongest peak) once removed modes 2–14 as its duplicates."""
    from stcs_ident.spectra.peak_filters import deduplicate

    peaks = [_peak(1.096, 5.14, 35.0)] + [_peak(1.096 * k, 0.002, 28.0) for k in range(2, 15)]
    kept = deduplicate(peaks)
    assert [round(p.frequency, 3) for p in kept] == [round(p.frequency, 3) for p in peaks]
    # Two fits of one mode still collapse to the stronger.
    twin = deduplicate([_peak(5.850, 0.002, 20.0), _peak(5.851, 0.002, 25.0)])
    assert len(twin) == 1 and twin[0].snr_db == 25.0


def test_a_flat_whittle_likelihood_is_not_an_estimate():
    """A pole narrower than the record resolves: ζ at its bound (its damping ratio NaN, its 1σ the resolution
    cell's; before, a degenerate information's 1σ of hertz). It must not replace a decay fit."""
    from types import SimpleNamespace

    from stcs_ident.spectra.peaks import _sound

    flat = SimpleNamespace(converged=True, frequency_std=5.14, damping=0.004)
    unresolved = SimpleNamespace(converged=True, frequency_std=0.001, damping=float("nan"))
    good = SimpleNamespace(converged=True, frequency_std=0.004, damping=0.004)
    assert not _sound(flat, 0.274) and not _sound(unresolved, 0.274)
    assert _sound(good, 0.274) and not _sound(None, 0.274)


def test_blows_ringing_at_different_frequencies_widen_the_uncertainty():
    """Tension wander between blows: the σ of the joint estimate covers the events' disagreement.

    Two clean decays 1e-3 apart in relative frequency (hundreds of their
    own σ): the joint σ must reach at least a third of the half-difference
    (the mean of two events known to ±τ/√2, τ ≈ half the difference).
    Without the wander (same frequency), σ stays at the noise's level.
    """
    from stcs_ident.spectra.decay_fit import event_spectra, fit_decay

    fs, n, f0, zeta = 256.0, 4096, 12.0, 0.003
    rng = np.random.default_rng(3)
    t = np.arange(n) / fs

    def decay(f):
        s = zeta * 2 * np.pi * f
        return np.exp(-s * t) * np.cos(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))

    sigmas = {}
    for label, shift in (("same", 0.0), ("wander", 1e-3)):
        x = np.concatenate([decay(f0), decay(f0 * (1 + shift))])[:, None] * np.array([[1.0, 0.6]])
        x = x + 1e-3 * rng.standard_normal(x.shape)
        fit = fit_decay(event_spectra(x, [(0, n), (n, 2 * n)]), fs, f0, 0.5)
        assert fit is not None and fit.converged
        sigmas[label] = fit.frequency_std
    assert sigmas["wander"] >= 0.5 * f0 * 1e-3 / 3
    assert sigmas["same"] < 0.05 * sigmas["wander"]


def _stay_record_at_a_node(impulse, ambient, snr_db, damping, seed, conditions):
    """A record of calibrate_spectra's stay (120 m, 64 Hz, 600 s, 3 sensors) with one blow, and the true means."""
    import math

    from stcs_ident.core.model import Attachment, Cable
    from stcs_ident.simulate import simulate_record_with_truth

    cable = Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=math.radians(30))
    record, truth = simulate_record_with_truth(
        cable, (Attachment("damper", 3.0, 50.0),), 4.0e6, [27.6, 60.0, 85.2], duration=600.0, sampling_rate=64.0,
        damping=damping, impulses=(impulse,), ambient=ambient, snr_db=snr_db, seed=seed, field=conditions)
    return record, truth.mean_frequencies[:12]


def _node_case(name):
    from stcs_ident.simulate import Ambient, FieldConditions, Impulse, MainsHum, TensionDrift

    # Full precision (calibrate_spectra's draws): the simulator's wind, an eigen-factor of the force covariance,
    # is not continuous in its level.
    if name == "hum60 seed 7 #10":  # mode 3, blown at 80.8 m (its node at 80 m)
        return _stay_record_at_a_node(
            Impulse(15.243027522018394, 80.8138246150208, 17.508392742420774), Ambient(0.4467884700751033),
            32.70017052631475, 0.008505342733147469, [7, 10, 7],
            FieldConditions(hum=MainsHum(59.9759, (1.475e-3, 2.53e-4, 1.56e-4), relative=True)))
    # drift seed 11 #5: mode 7, blown at 34.5 m (its node at 34.3 m), light wind, a tension drift
    drift = TensionDrift(rate=-1.8445202800231834e-07, amplitude=3.8445943306435285e-05, period=66.0749029180868,
                         phase=5.120505727902901, walk=1.1549000769659634e-06)
    return _stay_record_at_a_node(
        Impulse(47.070387976612096, 34.48921426568736, 50.666290160337226), Ambient(0.05638569987563043),
        39.93718880833344, 0.008585714641648066, [11, 5, 7], FieldConditions(drift=drift))


#: The mode each case blows at its node.
BLOWN_AT_NODE = {"hum60 seed 7 #10": 3, "drift seed 11 #5": 7}


@pytest.mark.parametrize("case", ["hum60 seed 7 #10", pytest.param("drift seed 11 #5", marks=pytest.mark.slow)])
def test_a_blow_at_a_node_under_wind_is_not_fitted_to_one_noise_bin(case):
    """A mode blown at its node under wind: nothing decays at its frequency, only its random response is there.

    The decay fit once locked on one χ² spike of that response (hum60:
    mode 3, ζ 5e-5 for the true 0.0085, σ 8e-5 Hz, z = 76; drift: mode 7,
    ζ 9e-5, 1 % off, z = 64). Either the record-wide (Whittle) fit is used,
    or, where it fails too, the peak is refitted with a damping like its
    neighbours' or kept with the 1σ of its own width. (In the hum60 case
    the 60 Hz hum lies above the Nyquist frequency and is not recorded.)
    """
    record, true_f = _node_case(case)
    blown = BLOWN_AT_NODE[case]
    result = find_peaks(record, f_min=0.5 * true_f[0], f_max=1.15 * true_f[-1])
    f = np.array([p.frequency for p in result.peaks])
    spacing = float(np.min(np.diff(true_f)))
    for k, fk in enumerate(true_f):
        j = int(np.argmin(np.abs(f - fk)))
        if abs(f[j] - fk) > 0.25 * spacing:  # no peak of this mode (the nearest is a neighbour's)
            # Only the mode blown at its node may be missed: under light wind its random response alone can
            # stay below the detection threshold (the simulated wind decides, record by record).
            assert k + 1 == blown, f"mode {k + 1} ({fk:.5f} Hz) not found"
            continue
        z = (f[j] - fk) / result.peaks[j].uncertainty
        # 4σ: twelve modes, one record; a lock on a noise bin is tens of σ off.
        assert abs(z) < 4, f"mode {k + 1}: {f[j]:.5f} Hz for {fk:.5f}, z = {z:.1f}"


def test_a_line_among_damped_modes_is_refitted_or_widened_but_hum_is_left():
    from stcs_ident.spectra.decay_fit import DecayFit
    from stcs_ident.spectra.peaks import _without_lines

    def fit(f, zeta):
        return DecayFit(f, 1e-4, 0.0, 0.0, zeta, 1e-4, np.ones((1, 1)), np.ones(1), np.ones(1), 1.0, 10.0, True)

    modes = [fit(1.1 * k, 0.008) for k in (1, 2, 4, 5)] + [fit(3.3, 5e-5), fit(100.0, 1e-5)]  # a line, and 100 Hz hum
    calls = {id(m): (m.frequency, 0.3, ()) for m in modes}
    pairs = [(None, m) for m in modes]
    refitted = fit(3.29, 0.007)
    seen = []

    def refit(f0, half_width, poles, zeta_min):
        seen.append((f0, zeta_min))
        return refitted

    out, widened = _without_lines(pairs, calls, refit)
    assert seen == [(3.3, pytest.approx(3 * 0.008 / 10))]  # only the line off the mains harmonics, floored at median/3.3
    assert out[4][1] is refitted and out[5][1] is modes[5] and not widened
    out, widened = _without_lines(pairs, calls, lambda *args: None)  # no decay to fit: kept, 1σ = ζ_median · f
    assert out[4][1].frequency_std == pytest.approx(0.008 * 3.3) and widened == {id(out[4][1])}
    lines = [(None, fit(1.1 * k, 5e-5)) for k in range(1, 5)]  # all undamped alike: nothing singled out
    assert _without_lines(lines, {id(m): (0, 0, ()) for _, m in lines}, refit)[0] == lines
