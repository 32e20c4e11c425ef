"""The record simulator: exact modal superposition, excitation, noise, hidden effects.

Reference values are closed forms (the SDOF impulse response, the SDOF
spectral variance) or the exact DSM frequencies; each tolerance says why it
is what it is.
"""

import json
import math

import numpy as np
import pytest
from scipy.signal import find_peaks

from stcs_ident.core.errors import ModelError
from stcs_ident.core.model import Attachment, Boundary, Cable, Campaign, Setup, Test
from stcs_ident.forward import natural_frequencies
from stcs_ident.io.campaign import load_campaign
from stcs_ident.simulate.effects import Effects, true_model
from stcs_ident.simulate.modal_response import (
    exponential_gram,
    modal_force_covariance,
    stationary_covariance,
    zoh_transition,
)
from stcs_ident.simulate.simulate import (
    UNCORRELATED_LENGTH,
    Ambient,
    Impulse,
    modal_basis,
    simulate_record,
)

# A taut bare strand: f1 ≈ 3.04 Hz, near-harmonic, ξ = l√(H/EI) ≈ 170.
LENGTH, MASS, EI = 20.0, 10.0, 2000.0
TENSION = MASS * (2 * LENGTH * 3.0) ** 2
CABLE = Cable(length=LENGTH, mass_per_length=MASS, EI=EI)
HIT = Impulse(time=0.5, position=2.74, magnitude=20.0)


def spectrum(signal, fs):
    return np.fft.rfftfreq(len(signal), 1 / fs), np.abs(np.fft.rfft(signal))


# 200 s at 40 Hz: FFT bins of 0.005 Hz, modes 1-5 kept (below 18 Hz). ζ = 0.002 keeps each peak's
# half-power width (2ζf ≤ 0.06 Hz) small against the mode spacing (3 Hz), so the neighbours' tails do
# not move a peak by a bin; mode 1 decays by e^-7.6 over the record (little truncation leakage).
# With ζ = 0.005 and modes up to 45 Hz, overlapping tails move the upper peaks by up to 5 bins.
LONG = {"duration": 200.0, "sampling_rate": 40.0, "impulses": [HIT], "damping": 0.002}


@pytest.fixture(scope="module")
def long_impulse_record():
    return simulate_record(CABLE, [], TENSION, [4.2, LENGTH / 2], **LONG)


def test_impulse_spectrum_peaks_at_dsm_frequencies(long_impulse_record):
    rec = long_impulse_record
    f, X = spectrum(rec.acceleration[:, 0], rec.sampling_rate)
    df = f[1]
    dsm = natural_frequencies(CABLE, [], TENSION, 6)
    assert dsm[4] < 0.45 * rec.sampling_rate < dsm[5]
    peaks, _ = find_peaks(X)
    top = peaks[np.argsort(X[peaks])[::-1][:5]]
    # within one bin: the damped frequency differs from f_k by ζ²/2 = 2e-6 relative, far below a bin
    assert all(np.min(np.abs(dsm - f[i])) <= df for i in top)
    for fk in dsm[:5]:
        assert np.min(np.abs(f[top] - fk)) <= df


def test_midspan_sensor_has_no_mode_2(long_impulse_record):
    rec = long_impulse_record
    f, X_side = spectrum(rec.acceleration[:, 0], rec.sampling_rate)
    _, X_mid = spectrum(rec.acceleration[:, 1], rec.sampling_rate)
    f1, f2 = natural_frequencies(CABLE, [], TENSION, 2)
    k2 = np.argmin(np.abs(f - f2))
    # what remains at f2 at midspan is the tails of modes 1 and 3, ≈ σ_3/Δω = 0.6 % of mode 3's peak
    assert X_mid[k2] < 2e-2 * X_side[k2]
    peaks, _ = find_peaks(X_mid)
    assert np.min(np.abs(f[peaks] - f2)) > 0.5  # and no peak at all near f2
    k1 = np.argmin(np.abs(f - f1))
    assert X_mid[k1] > X_side[k1]  # mode 1 is largest at midspan


def test_single_mode_impulse_response_is_the_closed_form():
    """n_modes = 1, ζ = 0.02: the record is (A/ω_d) e^{-ζωτ}[(σ²−ω_d²) sin ω_dτ − 2σω_d cos ω_dτ]."""
    zeta, fs, x_s = 0.02, 1000.0, 7.0
    rec = simulate_record(CABLE, [], TENSION, [x_s], duration=20.0, sampling_rate=fs, impulses=[HIT],
                          damping=zeta, n_modes=1)
    shapes = modal_basis(CABLE, [], TENSION, fs, n_modes=1)
    omega = 2 * math.pi * shapes.frequencies[0]
    A = shapes([x_s])[0, 0] * shapes([HIT.position])[0, 0] * HIT.magnitude
    # the mass-normalised shape is close to the string's √(2/ml) sin(πx/l) (bending: ~1 %)
    assert shapes([LENGTH / 2])[0, 0] == pytest.approx(math.sqrt(2 / (MASS * LENGTH)), rel=0.02)
    sigma, wd = zeta * omega, omega * math.sqrt(1 - zeta**2)
    tau = rec.time - HIT.time
    on = tau >= 0
    exact = np.where(on, A / wd * np.exp(-sigma * tau) * ((sigma**2 - wd**2) * np.sin(wd * tau)
                                                           - 2 * sigma * wd * np.cos(wd * tau)), 0.0)
    np.testing.assert_allclose(rec.acceleration[:, 0], exact, rtol=0, atol=1e-12 * np.abs(exact).max())

    # the peak envelope decays as exp(-ζωt) with amplitude A ω²/ω_d; sampled peaks are low by at most
    # (π f/fs)²/2 ≈ 5e-5 and the envelope shifts each peak by ~ζ²/2 = 2e-4, hence 1e-3
    a = np.abs(rec.acceleration[on, 0])
    peaks, _ = find_peaks(a)
    slope, intercept = np.polyfit(tau[on][peaks], np.log(a[peaks]), 1)
    assert -slope == pytest.approx(sigma, rel=1e-3)
    assert math.exp(intercept) == pytest.approx(abs(A) * omega**2 / wd, rel=1e-3)


def held_force_variance(omega, zeta, dt):
    """Var(q̈[n]) / Var(f) of a unit-mass SDOF under a white force held over each sample (closed form).

    A force held over [0, dt) is a step minus a delayed step, so the sampled acceleration
    response is h[0] = 1, h[m] = g(m dt) − g((m−1) dt), with g(t) = e^{−σt}(cos ω_d t − (σ/ω_d) sin ω_d t)
    the acceleration after a unit step; for white f, Var(q̈) / Var(f) = Σ h[m]².
    """
    sigma, wd = zeta * omega, omega * math.sqrt(1 - zeta**2)
    t = np.arange(int(40 / (sigma * dt)) + 2) * dt  # to e^-40
    g = np.exp(-sigma * t) * (np.cos(wd * t) - sigma / wd * np.sin(wd * t))
    return 1 + np.sum(np.diff(g) ** 2)


def test_ambient_modal_variance_matches_sdof_theory():
    """Uncorrelated pressure on one mode: Var(a) = φ(x)² σ_f² Σ h², σ_f² = σ_p² ℓ ∫φ² = σ_p² ℓ / m.

    (∫φ² = 1/m for a bare cable with mass-normalised shapes.) The estimator of the variance
    of a resonant process has relative standard deviation at most 1/√(T ζ ω) = 1.6 % here
    (observed over 30 seeds: 1.0 %, the white part of the acceleration being estimated
    better); 5 % is 3 of the bound. The 30-seed mean matched to 1e-4.
    """
    zeta, fs, duration, sigma_p, x_s = 0.05, 50.0, 4000.0, 5.0, 6.0
    rec = simulate_record(CABLE, [], TENSION, [x_s], duration=duration, sampling_rate=fs,
                          ambient=Ambient(sigma_p), damping=zeta, n_modes=1, seed=7)
    shapes = modal_basis(CABLE, [], TENSION, fs, n_modes=1)
    omega = 2 * math.pi * shapes.frequencies[0]
    force_var = sigma_p**2 * UNCORRELATED_LENGTH / MASS
    ratio = held_force_variance(omega, zeta, 1 / fs)
    # its resonant part is the classical white-noise result ω⁴ · π S₀ / (2ζω³) with S₀ = σ_f² dt / 2π
    # (two-sided, per rad/s), up to the hold's (ω dt)² effects: 0.2 % at ω dt = 0.38
    assert ratio - 1 == pytest.approx(omega / (4 * zeta * fs), rel=0.01)
    expected = shapes([x_s])[0, 0] ** 2 * force_var * ratio
    assert 1 / math.sqrt(duration * zeta * omega) < 0.017
    assert np.var(rec.acceleration[:, 0]) == pytest.approx(expected, rel=0.05)


def test_stationary_covariance_is_the_fixed_point():
    omega, zeta = np.array([10.0, 60.0]), np.array([0.01, 0.05])
    Ad, Bd = zoh_transition(omega, zeta, 0.01)
    C = np.array([[2.0, 0.7], [0.7, 1.0]])
    P = stationary_covariance(Ad, Bd, C)
    A = np.zeros((4, 4))
    B = np.zeros((4, 2))
    for k in range(2):
        A[2 * k:2 * k + 2, 2 * k:2 * k + 2], B[2 * k:2 * k + 2, k] = Ad[k], Bd[k]
    np.testing.assert_allclose(P, A @ P @ A.T + B @ C @ B.T, rtol=0, atol=1e-12 * np.abs(P).max())


def test_correlated_pressure_loads_symmetric_modes():
    shapes = modal_basis(CABLE, [], TENSION, 40.0)
    speed = math.sqrt(TENSION / MASS)
    # L ≫ l: the pressure is uniform along the cable, f_k = p ∫φ_k; antisymmetric modes get nothing
    C = modal_force_covariance(shapes, 1.0, 1e6 * LENGTH, length=LENGTH, wave_speed=speed, uncorrelated_length=1.0)
    x, w = shapes.quadrature()
    integral = w @ shapes(x)
    np.testing.assert_allclose(np.diag(C)[::2], integral[::2] ** 2, rtol=1e-3)  # grid: trapezoid, h ≤ λ/40
    assert np.all(np.diag(C)[1::2] < 1e-6 * C[0, 0])
    # L small against the wavelengths: the white limit 2Lσ² ∫φ_kφ_j (continuity across the switch)
    L = 0.05
    C = modal_force_covariance(shapes, 1.0, L, length=LENGTH, wave_speed=speed, uncorrelated_length=1.0)
    G = modal_force_covariance(shapes, 1.0, None, length=LENGTH, wave_speed=speed, uncorrelated_length=1.0)
    np.testing.assert_allclose(np.diag(C), 2 * L * np.diag(G), rtol=0.02)  # O((kL)²) with kL ≤ 0.2


def test_exponential_kernel_recursion_equals_the_double_sum():
    """The O(n) one-pole recursion reproduces the O(n²) double sum on the same grid (round-off only)."""
    shapes = modal_basis(CABLE, [], TENSION, 20.0)
    L, spacing = 3.0, 0.05
    C = exponential_gram(shapes, LENGTH, L, spacing)
    x = np.linspace(0, LENGTH, math.ceil(LENGTH / spacing) + 1)
    w = np.full(x.size, x[1] - x[0])
    w[[0, -1]] /= 2
    v = shapes(x) * w[:, None]
    dense = v.T @ np.exp(-np.abs(x[:, None] - x[None, :]) / L) @ v
    np.testing.assert_allclose(C, dense, rtol=0, atol=1e-12 * np.abs(dense).max())


def test_snr_sets_the_noise_level():
    kwargs = {"duration": 100.0, "sampling_rate": 100.0, "ambient": Ambient(5.0), "seed": 3}
    clean = simulate_record(CABLE, [], TENSION, [4.2, 10.0], **kwargs)
    noisy = simulate_record(CABLE, [], TENSION, [4.2, 10.0], snr_db=20.0, **kwargs)
    noise = noisy.acceleration - clean.acceleration
    ratio = np.sqrt(np.mean(noise**2, axis=0) / np.mean(clean.acceleration**2, axis=0))
    # 10^(-20/20) = 0.1; the rms of 10 000 Gaussian samples is within 1/√(2n) = 0.7 % (1 σ)
    np.testing.assert_allclose(ratio, 0.1, rtol=0.05)
    assert noisy.channel_names == ("A1", "A2")
    np.testing.assert_array_equal(noisy.channel_positions, [4.2, 10.0])


def test_same_seed_same_record():
    kwargs = {"duration": 5.0, "sampling_rate": 100.0, "ambient": Ambient(5.0, 2.0), "snr_db": 10.0, "impulses": [HIT]}
    a = simulate_record(CABLE, [], TENSION, [4.2], seed=11, **kwargs)
    b = simulate_record(CABLE, [], TENSION, [4.2], seed=11, **kwargs)
    c = simulate_record(CABLE, [], TENSION, [4.2], seed=12, **kwargs)
    np.testing.assert_array_equal(a.acceleration, b.acceleration)
    assert not np.allclose(a.acceleration, c.acceleration)


def test_extra_mass_lowers_the_frequencies_in_the_record(long_impulse_record):
    effects = Effects(extra_mass=(20.0, 8.3))
    rec = simulate_record(CABLE, [], TENSION, [4.2, LENGTH / 2], effects=effects, **LONG)

    def first_peak(record):
        f, X = spectrum(record.acceleration[:, 1], record.sampling_rate)
        band = (f > 2.0) & (f < 4.0)
        return f[band][np.argmax(X[band])], f[1]

    nominal, df = first_peak(long_impulse_record)
    true, _ = first_peak(rec)
    true_f1 = natural_frequencies(*true_model(CABLE, [], TENSION, effects), 1)[0]
    assert true == pytest.approx(true_f1, abs=df)
    assert nominal - true > 10 * df  # 20 kg on a 200 kg cable near midspan: ≈ 5 % lower


# --------------------------------------------------------------------------
# Effects
# --------------------------------------------------------------------------

W1 = Attachment("W1", 5.0, mass=8.3)


@pytest.mark.parametrize("effects,check", [
    (Effects(tension_ratio=1.05), lambda c, a, t: t == pytest.approx(1.05 * TENSION)),
    (Effects(EI_ratio=0.9), lambda c, a, t: c.EI == pytest.approx(0.9 * EI)),
    (Effects(length_ratio=0.98), lambda c, a, t: c.length == pytest.approx(0.98 * LENGTH) and a[0].position == 5.0),
    (Effects(end_stiffness=(1e5, math.inf)),
     lambda c, a, t: c.boundary_a == Boundary(1e5) and c.boundary_b.is_clamped),
    (Effects(extra_mass=(3.0, 12.0)),
     lambda c, a, t: [(x.position, x.mass) for x in a] == [(5.0, 8.3), (12.0, 3.0)]),
    (Effects(extra_spring=(1e4, 2.0)),
     lambda c, a, t: [(x.position, x.stiffness) for x in a] == [(2.0, 1e4), (5.0, 0.0)]),
    (Effects(attachment_positions={"W1": 9.0}), lambda c, a, t: [(x.name, x.position) for x in a] == [("W1", 9.0)]),
    (Effects(attachment_masses={"W1": 12.0}), lambda c, a, t: a[0].mass == 12.0 and a[0].position == 5.0),
    (Effects(extra_mass=(1.0, 5.0), extra_spring=(2e3, 5.0)),  # coincident: merged into one node
     lambda c, a, t: len(a) == 1 and (a[0].mass, a[0].stiffness) == (9.3, 2e3)),
])
def test_true_model_applies_each_effect(effects, check):
    cable, atts, tension = true_model(CABLE, [W1], TENSION, effects)
    assert check(cable, atts, tension)
    untouched = {"tension_ratio": tension == TENSION, "EI_ratio": cable.EI == EI,
                 "length_ratio": cable.length == LENGTH}
    for name, same in untouched.items():
        assert same == (getattr(effects, name) is None)


def test_true_model_without_effects_is_nominal():
    assert true_model(CABLE, [W1], TENSION, None) == (CABLE, (W1,), TENSION)
    assert true_model(CABLE, [W1], TENSION, Effects()) == (CABLE, (W1,), TENSION)


def test_effect_names_use_the_diagnose_vocabulary():
    e = Effects(tension_ratio=0.97, extra_mass=(10.0, 3.0), end_stiffness=(1e6, 1e6), attachment_masses={"W1": 9})
    assert e.names == ["tension", "attachment_mass", "unmodeled_mass", "end_restraint"]
    assert json.loads(json.dumps(e.to_dict()))["extra_mass"] == {"mass": 10.0, "position": 3.0}


@pytest.mark.parametrize("effects,field", [
    (Effects(attachment_positions={"W9": 3.0}), "effects.attachment_positions[W9]"),
    (Effects(extra_mass=(5.0, 25.0)), "effects.extra_mass"),
    (Effects(attachment_positions={"W1": 21.0}), "effects.attachment_positions[W1]"),
    (Effects(length_ratio=0.2), "effects.length_ratio"),  # true span 4 m: W1 at 5 m falls outside
])
def test_true_model_refuses_impossible_effects(effects, field):
    with pytest.raises(ModelError) as err:
        true_model(CABLE, [W1], TENSION, effects)
    assert err.value.field == field


@pytest.mark.parametrize("kwargs,field", [
    ({"tension_ratio": 0.0}, "effects.tension_ratio"),
    ({"extra_mass": (-1.0, 3.0)}, "effects.extra_mass"),
    ({"end_stiffness": (1.0,)}, "effects.end_stiffness"),
    ({"attachment_masses": {"W1": -2.0}}, "effects.attachment_masses[W1]"),
])
def test_effects_validate_their_fields(kwargs, field):
    with pytest.raises(ModelError) as err:
        Effects(**kwargs)
    assert err.value.field == field


@pytest.mark.parametrize("kwargs,field", [
    ({"impulses": ()}, "excitation"),
    ({"positions": [0.0]}, "positions"),
    ({"positions": [25.0]}, "positions"),
    ({"impulses": [Impulse(0.0, 30.0, 1.0)]}, "impulse.position"),
    ({"damping": [0.01, 0.02]}, "damping"),
    ({"damping": 1.5}, "damping"),
    ({"n_modes": 20}, "n_modes"),  # mode 20 ≈ 66 Hz is above Nyquist at 100 Hz
    ({"duration": -1.0}, "duration"),
    ({"snr_db": math.nan}, "snr_db"),
    ({"channel_names": ["a", "b"]}, "channel_names"),
])
def test_bad_options_name_the_field(kwargs, field):
    options = {"positions": [4.2], "duration": 2.0, "sampling_rate": 100.0, "impulses": [HIT]}
    options.update(kwargs)
    with pytest.raises(ModelError) as err:
        simulate_record(CABLE, [], TENSION, options.pop("positions"), **options)
    assert err.value.field == field


def test_bad_excitation_objects_name_the_field():
    with pytest.raises(ModelError) as err:
        Ambient(-1.0)
    assert err.value.field == "ambient.rms_pressure"
    with pytest.raises(ModelError) as err:
        Impulse(math.inf, 3.0, 1.0)
    assert err.value.field == "impulse.time"


def test_attachment_at_a_node_of_modes_is_handled():
    """A string with a mass at midspan: antisymmetric modes do not move the only attachment."""
    string = Cable(length=LENGTH, mass_per_length=MASS, EI=0.0)
    rec = simulate_record(string, [Attachment("M", LENGTH / 2, mass=5.0)], TENSION, [4.2], duration=2.0,
                          sampling_rate=50.0, impulses=[HIT])
    assert np.all(np.isfinite(rec.acceleration)) and np.abs(rec.acceleration).max() > 0


def test_progress_is_reported():
    calls = []
    simulate_record(CABLE, [], TENSION, [4.2], duration=400.0, sampling_rate=100.0, impulses=[HIT],
                    progress=lambda done, total: calls.append((done, total)))
    assert len(calls) > 1 and calls[-1] == (40000, 40000)


# --------------------------------------------------------------------------
# A whole campaign
# --------------------------------------------------------------------------


@pytest.fixture()
def nominal_campaign():
    setups = (Setup("bare"), Setup("weights", (W1,)))
    tests = (Test("T1", "bare", TENSION, frequencies=(3.0, 6.1)), Test("T2/b", "weights", 1.1 * TENSION))
    return Campaign("sim", CABLE, setups, tests, description="for tests")


def test_simulate_campaign_writes_a_nominal_campaign(tmp_path, nominal_campaign):
    io = pytest.importorskip("stcs_ident.io.records.hdf5")
    from stcs_ident.simulate.simulate_campaign import simulate_campaign

    effects = {"T2/b": Effects(tension_ratio=0.97, extra_mass=(10.0, 13.0))}
    seen = []
    out = simulate_campaign(nominal_campaign, tmp_path / "sim", positions=[4.2, 10.0], duration=10.0,
                            sampling_rate=50.0, impulses=[HIT], snr_db=30.0, effects=effects,
                            progress=lambda d, n: seen.append((d, n)))
    assert seen == [(1, 2), (2, 2)]
    loaded = load_campaign(out)
    assert loaded.cable == CABLE and loaded.setups == nominal_campaign.setups  # the nominal model only
    assert [t.tension for t in loaded.tests] == [TENSION, 1.1 * TENSION]
    for test in loaded.tests:
        assert test.frequencies is None and test.record.startswith("records/")
        record = io.read_record(out / test.record)
        np.testing.assert_array_equal(record.channel_positions, [4.2, 10.0])
        assert record.sampling_rate == 50.0 and record.n_samples == 500
    assert loaded.tests[1].record == "records/T2_b.h5"  # '/' is not a file-name character

    truth = json.loads((out / "truth.json").read_text())
    t1, t2 = truth["tests"]
    assert t1["effect_names"] == [] and t1["frequencies"] == pytest.approx(t1["nominal_frequencies"], rel=1e-12)
    assert t2["effect_names"] == ["tension", "unmodeled_mass"]
    assert t2["tension"] == pytest.approx(0.97 * 1.1 * TENSION)
    assert {"name": "(extra mass)", "position": 13.0, "mass": 10.0, "stiffness": 0.0} in t2["attachments"]
    true_f = natural_frequencies(*true_model(CABLE, [W1], 1.1 * TENSION, effects["T2/b"]), len(t2["modes"]))
    np.testing.assert_allclose(t2["frequencies"], true_f, rtol=1e-12)
    assert max(t2["frequencies"]) < 0.45 * 50.0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sim"]  # no temporary left behind


def test_simulate_campaign_refuses_a_non_empty_directory(tmp_path, nominal_campaign):
    pytest.importorskip("stcs_ident.io.records.hdf5")
    from stcs_ident.simulate.simulate_campaign import simulate_campaign

    out = tmp_path / "sim"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    options = {"positions": [4.2], "duration": 4.0, "sampling_rate": 50.0, "impulses": [HIT], "tests": ["T1"]}
    with pytest.raises(FileExistsError):
        simulate_campaign(nominal_campaign, out, **options)
    assert (out / "keep.txt").read_text() == "mine"
    simulate_campaign(nominal_campaign, out, overwrite=True, **options)
    assert sorted(p.name for p in out.iterdir()) == ["campaign.toml", "records", "truth.json"]
    assert [t.name for t in load_campaign(out).tests] == ["T1"]
    # a failure part-way leaves the target as it was and no temporary behind
    with pytest.raises(ModelError):
        simulate_campaign(nominal_campaign, out, overwrite=True, **{**options, "positions": [30.0]})
    assert (out / "campaign.toml").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sim"]
