"""Records in both planes and along the cable, misaligned sensors, moving anchorages, traffic.

References: the forward model's in-plane and out-of-plane frequencies, the exact steady state of a taut
string whose end moves harmonically (w = U sin kx / sin kl), and the linear combination a misaligned sensor
reads. Each tolerance says why it is what it is.
"""

import math

import numpy as np
import pytest
from scipy.signal import welch

from stcs_ident.core.errors import ModelError
from stcs_ident.core.model import Attachment, Cable, Damper
from stcs_ident.forward import natural_frequencies
from stcs_ident.simulate.anchorage import AnchorageMotion, transverse_response
from stcs_ident.simulate.bridge import BridgeConditions, StructuralMode, Traffic
from stcs_ident.simulate.simulate import Ambient, Impulse, modal_basis, simulate_record, simulate_record_with_truth

# A long stay with sag: its first in-plane (symmetric) mode is stiffened by sag-extensibility, 0.470 Hz
# against 0.396 Hz out of plane; the antisymmetric modes (0.791 Hz, ...) are the same in both planes.
STAY = Cable(length=200.0, mass_per_length=80.0, EI=2e4, EA=2e9, inclination=math.radians(25))
STAY_TENSION = 2.0e6
# 600 s at 20 Hz: modes to 9 Hz (about 22 per plane), 12000 samples.
TEN_MINUTES = {"duration": 600.0, "sampling_rate": 20.0, "ambient": Ambient(2.0), "damping": 0.005}


def psd(signal, fs, nperseg=4096):
    # 4096 samples at 20 Hz: bins of 0.0049 Hz, 5 averages over 600 s (with 50 % overlap)
    return welch(signal, fs, nperseg=nperseg)


@pytest.mark.slow  # several records of each kind: about 10 s
def test_default_records_are_unchanged():
    """Directions all in-plane, or BridgeConditions(), take the new path and give the old record bit for bit
    (the in-plane signal and the noise are drawn as before; only the record's stated directions differ)."""
    cable = Cable(length=80.0, mass_per_length=60.0, EI=2e4, EA=1.5e9, inclination=math.radians(30))
    atts = [Attachment("m", 20.0, 30.0)]
    kw = {"duration": 30.0, "sampling_rate": 50.0, "ambient": Ambient(5.0), "snr_db": 30.0, "seed": 3,
          "impulses": [Impulse(2.0, 11.0, 40.0)]}
    old = simulate_record(cable, atts, 3e6, [13.0, 37.0], **kw)
    assert old.channel_directions is None
    new = simulate_record(cable, atts, 3e6, [13.0, 37.0], directions=["in", 0.0], **kw)
    assert new.channel_directions == ("in", "in")
    assert np.array_equal(old.acceleration, new.acceleration)
    assert np.array_equal(old.acceleration,
                          simulate_record(cable, atts, 3e6, [13.0, 37.0], bridge=BridgeConditions(), **kw).acceleration)
    # with a damper (complex modes) too
    damped = [Damper("d", 4.0, 5.0, coefficient=3000.0)]
    old = simulate_record(cable, damped, 3e6, [13.0, 37.0], **kw)
    new = simulate_record(cable, damped, 3e6, [13.0, 37.0], directions=["in", "in"], **kw)
    assert np.array_equal(old.acceleration, new.acceleration)


@pytest.fixture(scope="module")
def biaxial():
    """A biaxial sensor (in and out at one point) and an axial channel, ambient loading in both planes."""
    return simulate_record_with_truth(STAY, [], STAY_TENSION, [61.0, 61.0, 61.0], directions=["in", "out", "axial"],
                                      snr_db=40.0, seed=11, **TEN_MINUTES)


def test_truth_gives_both_planes_frequencies(biaxial):
    _, truth = biaxial
    n_in, n_out = len(truth.frequencies_in), len(truth.frequencies_out)
    assert np.allclose(truth.frequencies_in, natural_frequencies(STAY, [], STAY_TENSION, n_in), rtol=1e-12)
    assert np.allclose(truth.frequencies_out, natural_frequencies(STAY, [], STAY_TENSION, n_out, plane="out"),
                       rtol=1e-12)
    assert truth.frequencies_out[-1] < 0.45 * 20.0 and len(truth.damping_out) == n_out
    assert truth.channel_directions == ("in", "out", "axial")


def test_biaxial_channels_peak_at_their_planes_frequencies(biaxial):
    rec, truth = biaxial
    f_in, f_out = truth.frequencies_in[0], truth.frequencies_out[0]
    assert f_in - f_out > 0.05  # the sag makes them distinct (0.470 and 0.396 Hz)
    f, p_in = psd(rec.acceleration[:, 0], rec.sampling_rate)
    _, p_out = psd(rec.acceleration[:, 1], rec.sampling_rate)
    band = (f > 0.3) & (f < 0.6)
    # within 2 bins (0.01 Hz): the peak's half-power width 2ζf = 0.005 Hz plus the Welch bin of 0.005 Hz;
    # the two planes' first modes are 15 bins apart
    tol = 2 * f[1]
    assert abs(f[band][np.argmax(p_in[band])] - f_in) <= tol
    assert abs(f[band][np.argmax(p_out[band])] - f_out) <= tol
    # each plane's peak is absent from the other channel: what is left there is the other mode's tail,
    # (2ζ f / Δf)² ≈ 5e-3 of its peak for a mode 0.074 Hz away; 0.05 leaves room for the estimate's scatter
    k_in, k_out = np.argmin(abs(f - f_in)), np.argmin(abs(f - f_out))
    assert p_in[k_out] < 0.05 * p_out[k_out]
    assert p_out[k_in] < 0.05 * p_in[k_in]
    # the antisymmetric mode 2 is the same in both planes and both channels show it (within 2 bins, as above)
    f2 = truth.frequencies_in[1]
    assert abs(f2 - truth.frequencies_out[1]) < 1e-6 * f2
    near = (f > f2 - 0.03) & (f < f2 + 0.03)
    for p in (p_in, p_out):
        assert abs(f[near][np.argmax(p[near])] - f2) <= tol


def test_axial_channel_without_anchorage_motion_holds_only_noise(biaxial):
    rec, _ = biaxial
    rms = np.sqrt(np.mean(rec.acceleration**2, axis=0))
    # the transverse modes give no axial acceleration: the axial channel carries the sensors' noise, whose
    # rms is the transverse channels' mean × 10^(−40/20) (to its sampling scatter, 1/√12000 ≈ 1 %)
    expected = 10 ** (-40 / 20) * np.mean(np.sqrt(np.mean(rec.acceleration[:, :2] ** 2, axis=0)))
    assert rms[2] == pytest.approx(expected, rel=0.05)


def test_misaligned_sensor_reads_the_other_plane_with_ratio_tan_delta():
    """A sensor said to be in-plane but turned by δ reads cos δ·in + sin δ·out: its out-of-plane part over its
    in-plane part is tan δ."""
    delta = 7.0
    x = [61.0] * 3
    rec = simulate_record(STAY, [], STAY_TENSION, x, directions=["in", "in", "out"],
                          bridge=BridgeConditions(misalignment=(delta, 0.0, 0.0)), seed=5, duration=60.0,
                          sampling_rate=20.0, ambient=Ambient(2.0))
    a = rec.acceleration
    coef, *_ = np.linalg.lstsq(a[:, 1:], a[:, 0], rcond=None)
    # exact up to round-off: the channels are the same plane signals combined
    assert coef == pytest.approx([math.cos(math.radians(delta)), math.sin(math.radians(delta))], abs=1e-9)
    assert coef[1] / coef[0] == pytest.approx(math.tan(math.radians(delta)), rel=1e-9)
    # the stated direction stays in the record; the truth holds the misalignment
    _, truth = simulate_record_with_truth(STAY, [], STAY_TENSION, x, directions=["in", "in", "out"],
                                          bridge=BridgeConditions(misalignment=(delta, 0.0, 0.0)), seed=5,
                                          duration=60.0, sampling_rate=20.0, ambient=Ambient(2.0))
    assert rec.channel_directions == ("in", "in", "out")
    assert list(truth.misalignment) == pytest.approx([delta, 0.0, 0.0])
    # misaligned, an in-plane-only record must simulate the out-of-plane motion too
    assert truth.frequencies_out is not None


def test_support_motion_answer_is_the_taut_string_steady_state():
    """End B moving as U cos ωt: a taut string's exact steady state is w = U sin(kx)/sin(kl) cos ωt."""
    # EI = 1 N m²: a string to 4e-5 in frequency (ξ = l√(H/EI) = 5e4) with a boundary layer of 1 mm
    string = Cable(length=50.0, mass_per_length=50.0, EI=1.0)
    H, fs, n = 1.0e6, 100.0, 5000
    shapes = modal_basis(string, [], H, fs)  # f_k = k·1.414 Hz up to 45 Hz: 31 modes
    f = 2.0  # between modes 1 and 2; 100 whole periods in the record, so one FFT bin holds it all
    t = np.arange(n) / fs
    u = np.cos(2 * math.pi * f * t)
    acc = np.zeros((n, 3))
    acc[:, 0] = u
    motion = AnchorageMotion({"B": acc}, np.zeros(0))
    x = np.array([5.0, 20.0, 37.0])
    zeta = np.full(len(shapes.frequencies), 1e-4)
    got = transverse_response(motion, "in", shapes, zeta, [], string.length, string.mass_per_length, x, fs, n)
    k = 2 * math.pi * f / math.sqrt(H / string.mass_per_length)
    exact = np.sin(k * x) / np.sin(k * string.length)
    ratio = (got.T @ u) / (u @ u)
    # the modal sum truncated after 31 modes misses Σ_{k>31} φ_k Γ_k ω²/ω_k² ~ 1e-4 of the chord line; the
    # damping ζ = 1e-4 shifts the gain by ~ζ ω ω_k/|ω_k² − ω²| < 1e-3: 2e-3 covers both
    assert ratio == pytest.approx(exact, abs=2e-3)
    # in phase but for the damping's quadrature part, ~2ζωω_k/|ω_k² − ω²| ≈ 3e-4 of the motion
    assert np.abs(got - np.outer(u, ratio)).max() < 1e-3
    assert not np.allclose(exact, x / string.length, rtol=0.05)  # the dynamics matter at this frequency


def test_a_deck_mode_at_a_cable_frequency_resonates_in_that_modes_shape():
    """End B moving at the string's mode-2 frequency: the cable answers in mode 2's shape, amplified by 1/(2ζ).
    For a string φ_k = √(2/(ml)) sin(kπx/l) and Γ_k = ∫ m φ_k x/l dx = √(2m/l) (−1)^(k+1) l/(kπ), so mode 2's
    term at resonance is Γ_2 φ_2(x) / (2iζ) = i sin(2πx/l) / (2πζ): 31.8 at x = l/4 for ζ = 0.005."""
    string = Cable(length=50.0, mass_per_length=50.0, EI=1.0)
    H, fs, n, zeta = 1.125e6, 100.0, 20000, 0.005  # c = 150 m/s: f_k = 1.5 k Hz (EI shifts them by 4e-5)
    shapes = modal_basis(string, [], H, fs)
    f2 = shapes.frequencies[1]
    t = np.arange(n) / fs
    u = np.cos(2 * math.pi * 3.0 * t)  # 600 whole periods: one FFT bin; 3.0 Hz is f2 to 1.2e-4 Hz « ζ f2
    assert abs(f2 - 3.0) < 2e-4
    acc = np.zeros((n, 3))
    acc[:, 0] = u
    x = np.array([12.5, 37.5])  # l/4 and 3l/4: mode 2's antinodes, of opposite sign
    got = transverse_response(AnchorageMotion({"B": acc}, np.zeros(0)), "in", shapes,
                              np.full(len(shapes.frequencies), zeta), [], 50.0, 50.0, x, fs, n)
    quadrature = np.sin(2 * math.pi * 3.0 * t)
    amplitude = np.hypot(got.T @ u, got.T @ quadrature) / (u @ u)
    # the other modes and the chord line add at most ~1 to the 31.8 of mode 2 (their gains are O(1)): 5 %
    assert amplitude == pytest.approx([1 / (2 * math.pi * zeta)] * 2, rel=0.05)
    # in mode 2's shape: the two antinodes move in opposition, and a quarter period behind the anchorage
    assert (got[:, 0] @ got[:, 1]) < -0.9 * np.sqrt((got[:, 0] @ got[:, 0]) * (got[:, 1] @ got[:, 1]))
    assert abs(got[:, 0] @ u) < 0.1 * abs(got[:, 0] @ quadrature)


@pytest.mark.slow  # complex modes of an FE model: about 15 s
def test_support_motion_answer_of_complex_modes_matches_the_real_modes_for_a_negligible_damper():
    """A cable with a damper answers through its complex modes; with a dashpot of 1 N s/m (ζ added ~1e-7) the
    answer is the undamped modes' one, to the finite-element Ritz basis's error against the exact shapes
    (measured 1.1e-5 of the motion here; 5e-5 allows for it)."""
    from stcs_ident.simulate.damped_modes import damped_modes

    string = Cable(length=50.0, mass_per_length=50.0, EI=1.0)
    H, fs, n = 1.0e6, 100.0, 5000
    atts = [Damper("d", 2.0, coefficient=1.0)]
    t = np.arange(n) / fs
    acc = np.zeros((n, 3))
    acc[:, 0] = np.cos(2 * math.pi * 2.0 * t) + 0.5 * np.sin(2 * math.pi * 3.7 * t)
    motion = AnchorageMotion({"B": acc}, np.zeros(0))
    x = np.array([5.0, 20.0, 37.0])
    modes = damped_modes(string, atts, H, fs, None, lambda k: np.full(k, 1e-4), 0.45)
    shapes = modal_basis(string, [], H, fs)
    complex_answer = transverse_response(motion, "in", modes, None, atts, 50.0, 50.0, x, fs, n)
    real_answer = transverse_response(motion, "in", shapes, np.full(len(shapes.frequencies), 1e-4), [], 50.0,
                                      50.0, x, fs, n)
    assert np.abs(complex_answer - real_answer).max() < 5e-5 * np.abs(real_answer).max()
    # and a record of a damped stay with a deck mode is made end to end, the deck mode on its channels
    rec = simulate_record(STAY, [Damper("d", 4.0, coefficient=2e4, angle=math.radians(30))], STAY_TENSION,
                          [61.0, 61.0], directions=["in", "out"], duration=120.0, sampling_rate=10.0,
                          bridge=BridgeConditions(anchorage_motion=[StructuralMode(0.65, 0.02,
                                                                                  direction=(0.8, 0.6, 0.0))]))
    assert np.all(np.isfinite(rec.acceleration)) and np.all(np.std(rec.acceleration, axis=0) > 0)


@pytest.fixture(scope="module")
def deck_record():
    deck = StructuralMode(0.65, 0.02, damping=0.01, end="B", direction=(0.6, 0.48, 0.64))
    kw = {"duration": 600.0, "sampling_rate": 20.0, "ambient": Ambient(0.5), "seed": 9}
    x = [61.0, 61.0, 61.0]
    dirs = ["in", "out", "axial"]
    with_deck = simulate_record_with_truth(STAY, [], STAY_TENSION, x, directions=dirs,
                                           bridge=BridgeConditions(anchorage_motion=[deck]), **kw)
    without = simulate_record(STAY, [], STAY_TENSION, x, directions=dirs, **kw)
    return deck, with_deck, without


def test_deck_mode_appears_on_every_channel(deck_record):
    deck, (rec, truth), quiet = deck_record
    assert list(truth.structural_frequencies) == [deck.frequency]
    f, _ = psd(rec.acceleration[:, 0], rec.sampling_rate)
    k = np.argmin(abs(f - deck.frequency))
    for c in range(3):
        _, p = psd(rec.acceleration[:, c], rec.sampling_rate)
        _, p0 = psd(quiet.acceleration[:, c], rec.sampling_rate)
        # a peak at the deck's frequency (within 2 bins: its band 2ζf = 0.013 Hz is ~3 bins wide) that the
        # record without it does not have (the same streams otherwise); 10x is far below the observed ratio
        near = (f > deck.frequency - 0.05) & (f < deck.frequency + 0.05)
        assert abs(f[near][np.argmax(p[near])] - deck.frequency) <= 2 * f[1]
        assert p[k] > 10 * max(p0[k], 1e-30)


def test_axial_channel_reads_the_anchorage_axial_motion(deck_record):
    deck, (rec, _), _ = deck_record
    axial = rec.acceleration[:, 2]
    # the chord line carries x/l of end B's axial motion: rms = 0.64 · (61/200) · 0.02 m/s² expected; the
    # narrow band's envelope has a time constant 1/(ζω_s) = 24 s, so 600 s hold ~12 independent variance
    # estimates: ±29 % (1σ) on the variance, ±15 % on the rms; 30 % is 2σ (this seed lands well inside)
    expected = deck.direction[2] * (61.0 / 200.0) * deck.amplitude
    assert np.sqrt(np.mean(axial**2)) == pytest.approx(expected, rel=0.3)
    # and it is only that: no cable mode in it. Its spectrum is the deck's band-pass |B(f)|², which at the
    # cable's mode 2 (0.791 Hz) is (2ζ f f_s / |f_s² − f²|)² = 2.6e-3 of its peak; a factor 2 for Welch's
    # leakage. The in-plane channel, at the same point, shows mode 2 far above that.
    f, p = psd(axial, rec.sampling_rate)
    _, p_in = psd(rec.acceleration[:, 0], rec.sampling_rate)
    k2, k = np.argmin(abs(f - 0.791)), np.argmin(abs(f - deck.frequency))
    fs_, f2 = deck.frequency, f[k2]
    band_tail = (2 * deck.damping * f2 * fs_ / abs(fs_**2 - f2**2)) ** 2
    assert p[k2] / p[k] < 2 * band_tail
    assert p_in[k2] / p_in[k] > 10 * band_tail


def test_bridge_motion_alone_is_an_excitation_and_traffic_bursts():
    traffic = Traffic(120.0, duration_s=10.0, amplitude=3.0, broadband=0.05)
    bridge = BridgeConditions(anchorage_motion=[StructuralMode(0.65, 0.02)], traffic=traffic)
    rec, truth = simulate_record_with_truth(STAY, [], STAY_TENSION, [61.0], directions=["in"], bridge=bridge,
                                            duration=300.0, sampling_rate=20.0, seed=2)
    assert truth.crossings is not None and truth.crossings.size > 0
    # 120 crossings an hour over 310 s: Poisson mean 10.3; its 6-sigma range is 0..30
    assert truth.crossings.size < 30
    # the record is louder while a vehicle crosses: the deck motion up to 4x, broadband motion on top
    t = np.arange(rec.n_samples) / rec.sampling_rate
    crossing = np.zeros(t.size, bool)
    for t0 in truth.crossings:
        crossing |= (t >= t0 + 3.0) & (t < t0 + 7.0)  # the middle of each 10 s crossing: envelope >= 0.65
    a = rec.acceleration[:, 0]
    # the envelope at least 0.65 there: deck motion >= 2.95x, so the mean square >= ~4x the quiet one's;
    # 2x leaves room for the narrow band's scatter and the cable's ring-down carrying energy out of bursts
    assert np.mean(a[crossing] ** 2) > 2 * np.mean(a[~crossing] ** 2)
    with pytest.raises(ModelError, match="excitation"):
        simulate_record(STAY, [], STAY_TENSION, [61.0], duration=10.0, sampling_rate=20.0,
                        bridge=BridgeConditions())


@pytest.mark.parametrize("bad, field", [
    ({"directions": ["in", "up"]}, "directions[1]"),
    ({"directions": ["in"]}, "directions"),
    ({"bridge": BridgeConditions(misalignment=(1.0, 2.0, 3.0))}, "bridge.misalignment"),
    ({"bridge": "deck"}, "bridge"),
])
def test_bad_options_are_refused_naming_the_field(bad, field):
    kw = {"duration": 10.0, "sampling_rate": 20.0, "ambient": Ambient(1.0), **bad}
    with pytest.raises(ModelError) as err:
        simulate_record(STAY, [], STAY_TENSION, [30.0, 61.0], **kw)
    assert err.value.field == field


@pytest.mark.parametrize("build, field", [
    (lambda: Impulse(1.0, 20.0, 5.0, "axial"), "impulse.direction"),
    (lambda: StructuralMode(0.6, 0.01, end="C"), "structural_mode.end"),
    (lambda: StructuralMode(0.6, 0.01, direction=(0, 0, 0)), "structural_mode.direction"),
    (lambda: StructuralMode(0.6, 0.01, damping=1.5), "structural_mode.damping"),
    (lambda: Traffic(-1.0), "traffic.rate_per_hour"),
    (lambda: BridgeConditions(anchorage_motion=[0.6]), "bridge.anchorage_motion"),
])
def test_bad_bridge_parts_are_refused_naming_the_field(build, field):
    with pytest.raises(ModelError) as err:
        build()
    assert err.value.field == field


def test_campaign_with_a_triaxial_sensor_writes_both_planes_truth(tmp_path):
    import json

    from stcs_ident.core.model import Campaign, Setup, Test
    from stcs_ident.io.records.hdf5 import read_record
    from stcs_ident.simulate.simulate_campaign import simulate_campaign

    campaign = Campaign("stay", STAY, (Setup("bare"),), (Test("T1", "bare", STAY_TENSION),))
    deck = StructuralMode(0.65, 0.02, direction=(0.9, 0.0, 0.44), harmonics=(0.3,))
    bridge = BridgeConditions(misalignment=(2.0, 0.0, 0.0, 0.0), anchorage_motion=[deck],
                              traffic=Traffic(60.0, broadband=0.01))
    out = simulate_campaign(campaign, tmp_path / "sim", positions=[61.0, 61.0, 61.0, 140.0],
                            directions=["in", "out", "axial", "in"], duration=60.0, sampling_rate=20.0,
                            ambient=Ambient(1.0), snr_db=40.0, bridge=bridge)
    record = read_record(out / "records" / "T1.h5")
    assert record.channel_directions == ("in", "out", "axial", "in")  # as stated, not as misaligned
    truth = json.loads((out / "truth.json").read_text())
    t1 = truth["tests"][0]
    assert t1["frequencies_in"] == t1["frequencies"]
    n_out = len(t1["modes_out"])
    assert t1["frequencies_out"] == pytest.approx(natural_frequencies(STAY, [], STAY_TENSION, n_out, plane="out"),
                                                  rel=1e-12)
    assert t1["channel_directions"] == ["in", "out", "axial", "in"]
    assert t1["structural_frequencies"] == [0.65] and t1["misalignment"] == [2.0, 0.0, 0.0, 0.0]
    assert t1["bridge"]["anchorage_motion"][0]["harmonics"] == [0.3]
    assert isinstance(t1["traffic_crossings"], list)
    assert truth["options"]["directions"] == ["in", "out", "axial", "in"]


def test_command_line_makes_a_triaxial_campaign_with_a_deck_mode(tmp_path, capsys):
    import json
    from pathlib import Path

    from stcs_ident.cli.main import main
    from stcs_ident.io.records.hdf5 import read_record

    han = Path(__file__).resolve().parents[1] / "campaigns" / "han2020"
    out = tmp_path / "sim"
    assert main(["simulate", str(han), "--out", str(out), "--test", "case1-L4", "--duration", "20", "--ambient", "2",
                 "--sensors", "0.3,0.6", "--triaxial", "--deck-modes", "1.9:0.05", "--traffic", "60:0.02",
                 "--misalignment", "3"]) == 0
    record = read_record(out / "records" / "case1-L4.h5")
    assert record.channel_directions == ("in", "out", "axial") * 2
    assert record.channel_positions[0] == record.channel_positions[2] != record.channel_positions[3]
    truth = json.loads((out / "truth.json").read_text())["tests"][0]
    assert truth["structural_frequencies"] == [1.9] and truth["misalignment"] == [3.0] * 6
    assert len(truth["frequencies_out"]) == len(truth["modes_out"]) > 0
    # a bad value is one line naming the option
    capsys.readouterr()
    assert main(["simulate", str(han), "--out", str(tmp_path / "bad"), "--deck-modes", "1.9"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--deck-modes" in err[0]
    assert main(["simulate", str(han), "--out", str(tmp_path / "bad"), "--triaxial", "--directions", "in"]) == 2
    capsys.readouterr()
    assert main(["simulate", str(han), "--out", str(tmp_path / "bad"), "--traffic", "60"]) == 2  # nothing to swell
    assert "--deck-modes" in capsys.readouterr().err


def test_blows_act_in_their_direction():
    x = [61.0, 61.0]
    kw = {"duration": 30.0, "sampling_rate": 20.0, "directions": ["in", "out"]}
    out_blow = simulate_record(STAY, [], STAY_TENSION, x, impulses=[Impulse(1.0, 40.0, 50.0, "out")], **kw)
    assert np.all(out_blow.acceleration[:, 0] == 0) and np.abs(out_blow.acceleration[:, 1]).max() > 0
    in_blow = simulate_record(STAY, [], STAY_TENSION, x, impulses=[Impulse(1.0, 40.0, 50.0)], **kw)
    assert np.all(in_blow.acceleration[:, 1] == 0)
    tilted = simulate_record(STAY, [], STAY_TENSION, x, impulses=[Impulse(1.0, 40.0, 50.0, 30.0)], **kw)
    # cos 30° of the blow in-plane and sin 30° out of plane: the model is linear (to round-off)
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    np.testing.assert_allclose(tilted.acceleration[:, 0], c * in_blow.acceleration[:, 0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(tilted.acceleration[:, 1], s * out_blow.acceleration[:, 1], rtol=1e-9, atol=1e-12)


def test_out_of_plane_loading_scales_with_its_ratio():
    x = [61.0, 61.0]
    kw = {"duration": 30.0, "sampling_rate": 20.0, "directions": ["in", "out"], "ambient": Ambient(2.0), "seed": 4}
    one = simulate_record(STAY, [], STAY_TENSION, x, **kw).acceleration
    two = simulate_record(STAY, [], STAY_TENSION, x, bridge=BridgeConditions(out_of_plane_ratio=2.0), **kw).acceleration
    none = simulate_record(STAY, [], STAY_TENSION, x, bridge=BridgeConditions(out_of_plane_ratio=0.0),
                           **kw).acceleration
    assert np.array_equal(one[:, 0], two[:, 0])  # the in-plane loading is its own
    # the same draws at twice the rms (to the round-off of the covariances' square roots)
    np.testing.assert_allclose(two[:, 1], 2 * one[:, 1], rtol=1e-8, atol=1e-12 * np.abs(one[:, 1]).max())
    assert np.all(none[:, 1] == 0)
    # and the out-of-plane pressure is independent of the in-plane one: their correlation is small
    # (|r| of two independent series with ~60 effective samples (30 s / 0.5 s) is below 3/√60 = 0.4)
    r = np.corrcoef(one[:, 0], one[:, 1])[0, 1]
    assert abs(r) < 0.4


@pytest.mark.slow  # drifting records in both planes: about 20 s
def test_a_drift_moves_both_planes_alike():
    from stcs_ident.simulate import FieldConditions, TensionDrift

    field = FieldConditions(drift=TensionDrift(amplitude=2e-3, period=20.0, walk=1e-4))
    _, truth = simulate_record_with_truth(STAY, [], STAY_TENSION, [61.0, 61.0], directions=["in", "out"],
                                          duration=30.0, sampling_rate=20.0, ambient=Ambient(2.0), field=field)
    assert truth.out.drifts and np.array_equal(truth.out.relative_tension, truth.relative_tension)
    # each plane's modes follow it with their own sensitivities (mode 1 in-plane is stiffened by the sag,
    # whose share falls as the tension rises: its sensitivity differs from the out-of-plane string's 1/2)
    assert truth.out.sensitivities[0] == pytest.approx(0.5, abs=0.01)  # a string's, to the bending's 1 %
    assert abs(truth.sensitivities[0] - truth.out.sensitivities[0]) > 0.01


def test_misaligned_axial_channel_reads_in_plane_motion():
    delta = 5.0
    rec = simulate_record(STAY, [], STAY_TENSION, [61.0, 61.0], directions=["in", "axial"],
                          bridge=BridgeConditions(misalignment=(0.0, delta)), duration=30.0, sampling_rate=20.0,
                          ambient=Ambient(2.0))
    # no anchorage motion: the axial channel is sin δ of the in-plane motion alone (exactly, to round-off)
    np.testing.assert_allclose(rec.acceleration[:, 1], math.sin(math.radians(delta)) * rec.acceleration[:, 0],
                               rtol=1e-12, atol=1e-15)


def test_structural_motion_has_its_rms_and_its_harmonics():
    from stcs_ident.simulate.anchorage import anchorage_motion

    fs, n = 20.0, 200_000
    mode = StructuralMode(1.0, 0.03, damping=0.05, end="A", direction=(0.0, 0.0, 1.0), harmonics=(0.5,))
    motion = anchorage_motion(BridgeConditions(anchorage_motion=[mode]), n, fs, np.random.default_rng(1))
    assert set(motion.acceleration) == {"A"}
    axial = motion.component("A", "axial")
    assert not np.any(motion.component("A", "in"))
    # rms² = fundamental² + harmonic² = (1 + 0.5²) A²: the harmonic r·A(t)cos 2θ has the fundamental's rms.
    # Its envelope's time constant 1/(ζω) = 3.2 s gives ~1500 independent variance estimates in 10000 s:
    # ±2.6 % (1σ) on the variance; 10 % is ~4σ
    assert np.mean(axial**2) == pytest.approx(1.25 * mode.amplitude**2, rel=0.1)
    f, p = welch(axial, fs, nperseg=4096)
    peaks = f[np.argsort(p)[::-1]]
    assert abs(peaks[0] - 1.0) < 0.02  # the fundamental, within its band (ζ f = 0.05 Hz half-width)
    near_2 = (f > 1.8) & (f < 2.2)
    assert abs(f[near_2][np.argmax(p[near_2])] - 2.0) < 0.1  # the 2nd harmonic, twice the band's width
