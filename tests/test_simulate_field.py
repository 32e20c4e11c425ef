"""Field-like disturbances of the simulator (stcs_ident.simulate.disturbances), all off by default.

Each disturbance is checked to be in the record with the size it states,
against a closed form or an estimate computed here independently of the
simulator; each tolerance says why it is what it is. Where a disturbance
adds to the record, the check is on the difference from the same record
without it (same seed): the disturbances draw from their own stream, so
the difference is the disturbance alone.
"""

import json
import math

import h5py
import numpy as np
import pytest
from scipy.signal import butter, freqz, hilbert, lfilter, welch

from stcs_ident.core.errors import ModelError
from stcs_ident.core.model import Cable, Campaign, Setup, Test
from stcs_ident.forward import natural_frequencies
from stcs_ident.io.records.hdf5 import read_record
from stcs_ident.simulate import (
    Ambient,
    DcOffsets,
    FieldConditions,
    Impulse,
    LowPassLoading,
    MainsHum,
    PinkNoise,
    TensionDrift,
    random_field_conditions,
    simulate_record,
    simulate_record_with_truth,
)
from stcs_ident.simulate.disturbances import lowpass_force_filter, relative_tension
from stcs_ident.simulate.field_response import augmented_stationary_covariance
from stcs_ident.simulate.modal_response import stationary_covariance, zoh_transition

# The taut bare strand of test_simulate.py: f1 ≈ 3.04 Hz, near-harmonic modes, s_k = d ln f / d ln H ≈ 0.49.
LENGTH, MASS, EI = 20.0, 10.0, 2000.0
TENSION = MASS * (2 * LENGTH * 3.0) ** 2
CABLE = Cable(length=LENGTH, mass_per_length=MASS, EI=EI)
HIT = Impulse(time=0.5, position=2.74, magnitude=20.0)


def record(field=None, positions=(4.2, 10.0), **kwargs):
    options = {"duration": 20.0, "sampling_rate": 50.0, "ambient": Ambient(5.0), "seed": 3} | kwargs
    return simulate_record(CABLE, [], TENSION, list(positions), field=field, **options).acceleration


# --------------------------------------------------------------------------
# Off by default
# --------------------------------------------------------------------------


def test_empty_field_conditions_change_nothing():
    kwargs = {"impulses": [HIT], "ambient": Ambient(5.0, 2.0), "snr_db": 20.0, "seed": 11}
    np.testing.assert_array_equal(record(FieldConditions(), **kwargs), record(None, **kwargs))


def test_sensor_side_disturbances_leave_the_signal_and_white_noise_alone():
    """Hum + offsets: the difference from the plain record is exactly the deterministic hum + offsets."""
    kwargs = {"snr_db": 20.0, "duration": 10.0, "sampling_rate": 250.0}
    hum = MainsHum(50.0, (0.02,))
    field = FieldConditions(hum=hum, dc_offsets=DcOffsets(0.1))
    t = np.arange(2500) / 250.0
    expected = np.tile(0.02 * np.cos(2 * np.pi * 50.0 * t)[:, None] + 0.1, (1, 2))
    # round-off of adding and subtracting signals of ~1 m/s²
    np.testing.assert_allclose(record(field, **kwargs) - record(None, **kwargs), expected, rtol=0, atol=1e-13)


# --------------------------------------------------------------------------
# 1. Hand blows under continuing ambient excitation
# --------------------------------------------------------------------------


def test_blows_ride_on_a_continuing_ambient_response():
    kwargs = {"duration": 60.0, "sampling_rate": 40.0, "damping": 0.02, "seed": 5}
    both = record(impulses=[HIT, Impulse(20.0, 7.0, -30.0)], **kwargs)
    ambient = record(**kwargs)
    blows = simulate_record(CABLE, [], TENSION, [4.2, 10.0], impulses=[HIT, Impulse(20.0, 7.0, -30.0)],
                            **kwargs).acceleration
    # linear superposition: equal to round-off (the ambient draws the same stream with or without blows)
    np.testing.assert_allclose(both, ambient + blows, rtol=0, atol=1e-12 * np.abs(both).max())
    # the ambient goes on through the decays: after the second blow has decayed (ζω₁ ≈ 0.38/s, e^-11 by
    # t = 50 s) the record is the ambient response, whose level over those 10 s is that of the whole record
    late = np.arange(len(both)) / 40.0 > 50.0
    np.testing.assert_allclose(both[late], ambient[late], rtol=0, atol=1e-4 * np.abs(both).max())
    assert np.std(both[late]) > 0.3 * np.std(ambient)
    # and during the decay, both are present: the record differs from the blows alone by the ambient
    early = (np.arange(len(both)) / 40.0 > 20.0) & (np.arange(len(both)) / 40.0 < 25.0)
    assert np.std(both[early] - blows[early]) == pytest.approx(np.std(ambient[early]), rel=1e-9)


# --------------------------------------------------------------------------
# 2. Low-pass (coloured) ambient loading
# --------------------------------------------------------------------------


def filter_power(b, a, n=20000):
    """Σ h[n]² of the filter's impulse response: its variance gain for white input (Parseval)."""
    impulse = np.zeros(n)
    impulse[0] = 1.0
    return float(np.sum(lfilter(b, a, impulse) ** 2))


@pytest.mark.parametrize("order", [1, 2])
def test_lowpass_ambient_spectrum_follows_the_filter(order):
    """The PSD of the response to coloured loading / to white loading is |H(f)|² / Σh² (an LTI system).

    Noise-free records of the same cable, one mode band at a time (±0.25 Hz around each of the 5 modes,
    where that mode dominates), averaged over the band's Welch bins.
    """
    fs, fc = 40.0, 4.0
    kwargs = {"duration": 1000.0, "sampling_rate": fs, "damping": 0.05, "positions": (4.2,)}
    white = record(None, seed=1, **kwargs)[:, 0]
    coloured = record(FieldConditions(ambient_lowpass=LowPassLoading(fc, order)), seed=2, **kwargs)[:, 0]
    f, P_white = welch(white, fs, nperseg=512)
    _, P_col = welch(coloured, fs, nperseg=512)
    b, a = butter(order, fc, fs=fs)
    _, Hf = freqz(b, a, worN=f, fs=fs)
    expected = np.abs(Hf) ** 2 / filter_power(b, a)
    modes = natural_frequencies(CABLE, [], TENSION, 5)
    ratios = []
    for fk in modes:
        band = np.abs(f - fk) < 0.25
        ratios.append(np.mean(P_col[band] / P_white[band] / expected[band]))
    # each Welch bin has ~155 averages (±8 %); the ratio of two ±11 %, over 13 correlated bins ≈ ±5 %:
    # 15 % is 3 σ. The expected ratio itself falls by a factor 60-200 from mode 1 to mode 5.
    np.testing.assert_allclose(ratios, 1.0, rtol=0.15)
    assert expected[np.argmin(np.abs(f - modes[4]))] < 0.05 * expected[np.argmin(np.abs(f - modes[0]))]


def test_lowpass_keeps_the_pressure_variance():
    b, a = lowpass_force_filter(LowPassLoading(1.5, 2), 50.0)
    assert filter_power(b, a) == pytest.approx(1.0, rel=1e-9)  # the impulse response is summed to 1e-20
    b0, a0 = butter(2, 1.5, fs=50.0)
    np.testing.assert_allclose(a, a0, rtol=1e-12)  # the Butterworth, only rescaled
    np.testing.assert_allclose(b / b0, (b / b0)[0], rtol=1e-12)
    _, H0 = freqz(b0, a0, worN=[1.5], fs=50.0)
    assert abs(H0[0]) ** 2 == pytest.approx(0.5, rel=1e-9)  # −3 dB at the corner


def test_augmented_stationary_covariance_is_the_cascade_variance():
    """Var(q) of a mode driven by filtered white force = Σ (impulse response of filter then mode)², computed
    here by stepping the exact one-step matrices; the Lyapunov solution must agree (to the sum's truncation)."""
    omega, zeta, dt = np.array([12.0]), np.array([0.05]), 0.02
    Ad, Bd = zoh_transition(omega, zeta, dt)
    b, a = butter(2, 3.0, fs=50.0)
    P = augmented_stationary_covariance(Ad, Bd, np.array([[1.0]]), b, a)
    impulse = np.zeros(6000)  # ζω = 0.6/s: e^-72 after 120 s
    impulse[0] = 1.0
    force = lfilter(b, a, impulse)
    s, q = np.zeros(2), []
    for fn in force:
        q.append(s.copy())
        s = Ad[0] @ s + Bd[0] * fn
    q = np.array(q)
    np.testing.assert_allclose(P[:2, :2], q.T @ q, rtol=1e-9)
    # a pass-through "filter" gives the white-force covariance of modal_response
    P1 = augmented_stationary_covariance(Ad, Bd, np.array([[1.0]]), np.array([1.0, 0.0]), np.array([1.0, 0.0]))
    np.testing.assert_allclose(P1[:2, :2], stationary_covariance(Ad, Bd, np.array([[1.0]])), rtol=1e-12)


# --------------------------------------------------------------------------
# 3. Slow tension drift
# --------------------------------------------------------------------------

T_DRIFT, FS_DRIFT = 200.0, 20.0
DRIFT = TensionDrift(rate=2e-4 / T_DRIFT, amplitude=2e-4, period=50.0, phase=0.4)


def imposed_frequency(t, f0, s):
    """f0 (1 + d(t))^s for DRIFT (no random walk), written out here."""
    d = DRIFT.rate * t + DRIFT.amplitude * (np.sin(2 * np.pi * t / DRIFT.period + DRIFT.phase) - math.sin(DRIFT.phase))
    return f0 * (1 + d) ** s


def sensitivities(n):
    """d ln f / d ln H by a central difference of step 1e-4 (the simulator uses 1e-3)."""
    up = natural_frequencies(CABLE, [], TENSION * (1 + 1e-4), n)
    down = natural_frequencies(CABLE, [], TENSION * (1 - 1e-4), n)
    return np.log(up / down) / math.log((1 + 1e-4) / (1 - 1e-4))


def test_drift_makes_the_instantaneous_frequency_wander():
    """A single, lightly damped mode after one blow: its phase (Hilbert) is ∫ 2π f(t) dt."""
    rec, truth = simulate_record_with_truth(CABLE, [], TENSION, [7.0], duration=T_DRIFT, sampling_rate=FS_DRIFT,
                                            impulses=[Impulse(-0.3, 2.74, 20.0)], damping=1e-4, n_modes=1,
                                            field=FieldConditions(drift=DRIFT))
    t = rec.time
    s = sensitivities(1)
    assert s[0] == pytest.approx(0.5, abs=0.01)  # √H to first order (bending: s slightly below 1/2)
    f0 = natural_frequencies(CABLE, [], TENSION, 1)[0]
    imposed = imposed_frequency(t, f0, s[0])
    np.testing.assert_allclose(truth.instantaneous_frequencies(1), imposed, rtol=1e-12)
    wander = np.ptp(imposed) / f0
    assert 2e-4 < wander < 3e-4  # ≈ s × (2 × amplitude + trend) less the sinusoid's partial cancellation

    phase = np.unwrap(np.angle(hilbert(rec.acceleration[:, 0])))
    a, b = int(0.1 * len(t)), int(0.9 * len(t))  # away from the Hilbert transform's edge effects
    w = int(2 * FS_DRIFT)  # local frequency: slope of the phase over 2 s windows
    starts = np.arange(a, b - w, w // 2)
    local = np.array([np.polyfit(t[i:i + w] - t[i], phase[i:i + w], 1)[0] / (2 * np.pi) for i in starts])
    expected = np.array([np.mean(imposed[i:i + w]) for i in starts])
    # measured within 3e-6 relative (the 1-s tension steps, the windows' fit): 5 % of the wander is 1.3e-5
    np.testing.assert_allclose(local, expected, rtol=0, atol=0.05 * wander * f0)
    assert np.ptp(local) / f0 == pytest.approx(np.ptp(expected) / f0, rel=0.05)
    # the mean frequency over the window is the imposed mean (phase advance / time: 1e-7 relative measured)
    measured_mean = (phase[b] - phase[a]) / (2 * np.pi * (t[b] - t[a]))
    assert measured_mean == pytest.approx(np.mean(imposed[a:b]), rel=1e-6)
    assert abs(np.mean(imposed[a:b]) / f0 - 1) > 5e-6  # ... and that differs from the static frequency
    # the truth is the whole record's mean
    assert truth.mean_frequencies[0] == pytest.approx(np.mean(imposed), rel=1e-12)


def test_drift_of_zero_is_the_constant_tension_record():
    """The drift kernel (1-s segments, state carried) reproduces the closed-form / IIR record to round-off."""
    kwargs = {"impulses": [HIT, Impulse(-2.0, 7.0, 5.0), Impulse(7.77, 3.0, -9.0)], "snr_db": 20.0}
    plain = record(None, **kwargs)
    drifting = record(FieldConditions(drift=TensionDrift()), **kwargs)
    np.testing.assert_allclose(drifting, plain, rtol=0, atol=1e-12 * np.abs(plain).max())


def test_random_walk_has_the_stated_diffusion():
    rng = np.random.default_rng(0)
    d = relative_tension(TensionDrift(walk=1e-5), 100_000, 100.0, rng)
    steps = np.diff(d)
    # walk · √dt per sample; the std of 1e5 normal steps is within 1/√(2n) = 0.22 % (1 σ)
    assert np.std(steps) == pytest.approx(1e-5 * math.sqrt(0.01), rel=0.01)
    assert d[0] == 0.0


def test_campaign_truth_has_the_time_averaged_frequencies(tmp_path):
    campaign = Campaign("sim", CABLE, (Setup("bare"),), (Test("T1", "bare", TENSION), Test("T2", "bare", TENSION)))
    from stcs_ident.simulate import simulate_campaign

    out = simulate_campaign(campaign, tmp_path / "sim", positions=[4.2, 10.0], duration=T_DRIFT,
                            sampling_rate=FS_DRIFT, impulses=[HIT], ambient=Ambient(2.0), snr_db=30.0,
                            field={"T1": FieldConditions(drift=DRIFT, float32=True)})
    truth = json.loads((out / "truth.json").read_text())
    t1, t2 = truth["tests"]
    n = len(t1["modes"])
    t = np.arange(round(T_DRIFT * FS_DRIFT)) / FS_DRIFT
    s = sensitivities(n)
    mean = [np.mean(imposed_frequency(t, f0, sk)) for f0, sk in zip(t1["frequencies"], s)]
    # s here and in the simulator differ by ~1e-8 (steps 1e-4 and 1e-3): 1e-12 in f over a 2e-4 drift
    np.testing.assert_allclose(t1["time_averaged_frequencies"], mean, rtol=1e-11)
    assert t1["field"] == {"drift": {"rate": 1e-6, "amplitude": 2e-4, "period": 50.0, "phase": 0.4, "walk": 0.0},
                           "float32": True}
    assert t1["mean_tension"] == pytest.approx(TENSION * (1 + np.mean(imposed_frequency(t, 1.0, 1.0) - 1)))
    assert "field" not in t2 and "time_averaged_frequencies" not in t2
    with h5py.File(out / "records/T1.h5") as h5, h5py.File(out / "records/T2.h5") as h5b:
        assert h5["acceleration"].dtype == np.float32 and h5b["acceleration"].dtype == np.float64


# --------------------------------------------------------------------------
# 4. Pink sensor noise
# --------------------------------------------------------------------------


def test_pink_noise_has_slope_minus_one_and_the_stated_rms():
    positions = np.linspace(1.0, 19.0, 16)
    kwargs = {"duration": 100.0, "sampling_rate": 100.0, "positions": positions}
    noise = record(FieldConditions(pink_noise=PinkNoise(0.05)), **kwargs) - record(None, **kwargs)
    # power over 16 channels: each channel's power has relative sd √Σk⁻² / Σk⁻¹ ≈ 0.14 (5000 bins of 1/f):
    # the mean of 16, 3.5 %, on the rms 1.8 %: 6 % is over 3 σ
    assert math.sqrt(np.mean(noise**2)) == pytest.approx(0.05, rel=0.06)
    assert np.abs(np.mean(noise, axis=0)).max() < 1e-12  # no power at 0 Hz: a mean of 0 up to round-off
    f, P = welch(noise, 100.0, nperseg=1000, axis=0)
    band = (f >= 0.5) & (f <= 40.0)  # from 5 bins (Hann leakage at the lowest bins) to below Nyquist
    slope = np.polyfit(np.log(f[band]), np.log(P[band].mean(axis=1)), 1)[0]
    # 16 channels × 19 Welch averages per bin: ±6 % per bin, over 396 bins spread on 2 decades: slope ±0.005
    assert slope == pytest.approx(-1.0, abs=0.05)


def test_relative_pink_noise_scales_with_each_channel():
    kwargs = {"duration": 100.0, "sampling_rate": 100.0, "positions": np.linspace(1.0, 19.0, 16)}
    clean = record(None, **kwargs)
    noise = record(FieldConditions(pink_noise=PinkNoise(0.1, relative=True)), **kwargs) - clean
    ratio = np.sqrt(np.mean(noise**2, axis=0) / np.mean(clean**2, axis=0))
    # each channel's rms has relative sd ≈ 7 % (see above): the mean of 16 ratios within 6 % (3.4 σ)
    assert np.mean(ratio) == pytest.approx(0.1, rel=0.06)


# --------------------------------------------------------------------------
# 5. Mains hum
# --------------------------------------------------------------------------


def test_mains_hum_lines_have_the_stated_amplitudes_and_none_above_nyquist():
    """250 Hz for 10 s: 50 and 100 Hz fall on FFT bins; 150 Hz is above Nyquist and is skipped, not aliased
    (it would alias onto 100 Hz and change that line)."""
    fs, duration = 250.0, 10.0
    hum = MainsHum(50.0, (0.02, 0.01, 0.005), phases=(0.0, 1.0, 2.0), channel_gains=(1.0, 0.5),
                   channel_phases=(0.0, 0.3))
    kwargs = {"duration": duration, "sampling_rate": fs, "snr_db": 30.0}
    diff = record(FieldConditions(hum=hum), **kwargs) - record(None, **kwargs)
    X = np.fft.rfft(diff, axis=0) * 2 / len(diff)
    f = np.fft.rfftfreq(len(diff), 1 / fs)
    k50, k100 = np.argmin(np.abs(f - 50.0)), np.argmin(np.abs(f - 100.0))
    # exact sinusoids on bins: amplitude and phase to round-off
    np.testing.assert_allclose(np.abs(X[k50]), [0.02, 0.01], rtol=1e-9)
    np.testing.assert_allclose(np.abs(X[k100]), [0.01, 0.005], rtol=1e-9)
    np.testing.assert_allclose(np.angle(X[k50]), [0.0, 0.3], atol=1e-9)
    np.testing.assert_allclose(np.angle(X[k100]), [1.0, 1.3], atol=1e-9)
    others = np.ones(len(f), bool)
    others[[k50, k100]] = False
    assert np.abs(X[others]).max() < 1e-12


def test_hum_at_nyquist_or_above_is_skipped():
    kwargs = {"duration": 4.0, "sampling_rate": 100.0}
    diff = record(FieldConditions(hum=MainsHum(50.0, (0.02, 0.01))), **kwargs) - record(None, **kwargs)
    assert np.abs(diff).max() < 1e-13  # 50 Hz is Nyquist at 100 Hz; 100 Hz above it


# --------------------------------------------------------------------------
# 6. DC offsets, 7. float32
# --------------------------------------------------------------------------


def test_dc_offsets_are_the_means():
    kwargs = {"duration": 60.0}
    plain = record(None, **kwargs)
    shifted = record(FieldConditions(dc_offsets=DcOffsets((0.3, -0.2))), **kwargs)
    np.testing.assert_allclose(shifted.mean(axis=0) - plain.mean(axis=0), [0.3, -0.2], rtol=1e-12)
    # the response has zero mean: its sample mean is far below the offsets (rms ~0.1 m/s², 3000 samples)
    np.testing.assert_allclose(shifted.mean(axis=0), [0.3, -0.2], atol=0.01)
    rel = record(FieldConditions(dc_offsets=DcOffsets(2.0, relative=True)), **kwargs)
    np.testing.assert_allclose(rel.mean(axis=0) - plain.mean(axis=0), 2.0 * np.sqrt(np.mean(plain**2, axis=0)),
                               rtol=1e-12)


def test_float32_samples_are_written_and_read_back(tmp_path):
    from stcs_ident.simulate import simulate_campaign

    campaign = Campaign("sim", CABLE, (Setup("bare"),), (Test("T1", "bare", TENSION),))
    field = FieldConditions(float32=True, dc_offsets=DcOffsets(0.5))
    kwargs = {"positions": [4.2, 10.0], "duration": 10.0, "sampling_rate": 50.0, "impulses": [HIT], "seed": 4}
    out = simulate_campaign(campaign, tmp_path / "sim", field=field, **kwargs)
    with h5py.File(out / "records/T1.h5") as h5:
        assert h5["acceleration"].dtype == np.float32
    written = read_record(out / "records/T1.h5").acceleration
    # the simulated record holds float32 values already, so the file gives them back exactly
    stream = np.random.SeedSequence(4).spawn(1)[0]
    rec = simulate_record(CABLE, [], TENSION, kwargs["positions"], duration=10.0, sampling_rate=50.0,
                          impulses=[HIT], seed=stream, field=field).acceleration
    np.testing.assert_array_equal(written, rec)
    np.testing.assert_array_equal(rec.astype(np.float32).astype(np.float64), rec)
    full = simulate_record(CABLE, [], TENSION, kwargs["positions"], duration=10.0, sampling_rate=50.0,
                           impulses=[HIT], seed=stream, field=FieldConditions(dc_offsets=DcOffsets(0.5))).acceleration
    # rounded to the nearest single: within half an ulp, 2^-24 relative (and not all exact)
    assert np.all(np.abs(rec - full) <= 2.0**-24 * np.abs(full)) and np.abs(rec - full).max() > 0


# --------------------------------------------------------------------------
# Random field conditions; validation
# --------------------------------------------------------------------------


def test_random_field_conditions_are_seeded_and_simulate():
    a = random_field_conditions(np.random.default_rng(7), 50.0, 60.0, 2, probability=1.0)
    b = random_field_conditions(np.random.default_rng(7), 50.0, 60.0, 2, probability=1.0)
    assert a == b
    assert all(x is not None for x in (a.ambient_lowpass, a.drift, a.pink_noise, a.hum, a.dc_offsets)) and a.float32
    none = random_field_conditions(np.random.default_rng(7), 50.0, 60.0, 2, probability=0.0)
    assert none == FieldConditions()
    rec, truth = simulate_record_with_truth(CABLE, [], TENSION, [4.2, 10.0], duration=60.0, sampling_rate=50.0,
                                            ambient=Ambient(5.0), impulses=[HIT], field=a)
    assert np.all(np.isfinite(rec.acceleration))
    wander = max(np.ptp(truth.instantaneous_frequencies(k + 1)) / f for k, f in enumerate(truth.frequencies))
    assert 1e-6 < wander < 3e-4  # the drawn drift: ~1e-5-1e-4 in frequency
    assert json.loads(json.dumps(a.to_dict()))["hum"]["relative"] is True


@pytest.mark.parametrize("build,field", [
    (lambda: LowPassLoading(-1.0), "ambient_lowpass.corner_frequency"),
    (lambda: LowPassLoading(2.0, 3), "ambient_lowpass.order"),
    (lambda: TensionDrift(period=0.0), "drift.period"),
    (lambda: TensionDrift(walk=-1e-5), "drift.walk"),
    (lambda: TensionDrift(rate=math.nan), "drift.rate"),
    (lambda: PinkNoise(-0.1), "pink_noise.rms"),
    (lambda: PinkNoise(0.1, relative=1), "pink_noise.relative"),
    (lambda: MainsHum(0.0, (0.1,)), "hum.frequency"),
    (lambda: MainsHum(50.0, ()), "hum.amplitudes"),
    (lambda: MainsHum(50.0, 0.1), "hum.amplitudes"),
    (lambda: MainsHum(50.0, (0.1, 0.2), phases=(0.0,)), "hum.phases"),
    (lambda: MainsHum(50.0, (0.1,), channel_gains=(1.0, -1.0)), "hum.channel_gains"),
    (lambda: DcOffsets("a"), "dc_offsets.values"),
    (lambda: FieldConditions(drift=0.1), "field.drift"),
    (lambda: FieldConditions(float32="yes"), "field.float32"),
])
def test_conditions_validate_their_fields(build, field):
    with pytest.raises(ModelError) as err:
        build()
    assert err.value.field == field


@pytest.mark.parametrize("kwargs,field", [
    ({"field": FieldConditions(ambient_lowpass=LowPassLoading(2.0)), "ambient": None, "impulses": [HIT]},
     "ambient_lowpass"),
    ({"field": FieldConditions(ambient_lowpass=LowPassLoading(30.0))}, "ambient_lowpass.corner_frequency"),
    ({"field": FieldConditions(dc_offsets=DcOffsets((0.1, 0.2, 0.3)))}, "dc_offsets.values"),
    ({"field": FieldConditions(pink_noise=PinkNoise((0.1,)))}, "pink_noise.rms"),
    ({"field": FieldConditions(hum=MainsHum(50.0, (0.1,), channel_phases=(0.0, 1.0, 2.0)))}, "hum.channel_phases"),
    ({"field": FieldConditions(drift=TensionDrift(rate=1e-3))}, "drift"),  # 2 % over 20 s: beyond DRIFT_LIMIT
    ({"field": "drift"}, "field"),
])
def test_impossible_conditions_name_the_field(kwargs, field):
    with pytest.raises(ModelError) as err:
        record(**kwargs)
    assert err.value.field == field
