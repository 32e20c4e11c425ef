"""Vertical cables (issue 34, part 5): the hangers of arch and suspension bridges, inclination ±90 degrees.

A vertical chord carries no weight normal to itself: no sag, no sag-extensibility (λ² = 0), its in-plane and
out-of-plane families equal. Checked against the closed form of a pinned tensioned beam, the finite-element
model (built independently of the exact solver) and, end to end, every command on a hanger campaign.
"""

from __future__ import annotations

import csv
import json
import math
import warnings
from dataclasses import replace

import h5py
import numpy as np
import pytest

from stcs_ident.cli.main import main
from stcs_ident.core.errors import CampaignError, InputError, ModelError
from stcs_ident.core.model import Attachment, Boundary, Cable, Damper, chord_components
from stcs_ident.forward import natural_frequencies
from stcs_ident.forward.damped import complex_modes
from stcs_ident.forward.fem import fe_frequencies
from stcs_ident.forward.fem_damped import fe_complex_modes
from stcs_ident.forward.statics import irvine_lambda2, sag_ratio
from stcs_ident.identify.quick import quick_tension
from stcs_ident.io.campaign import campaign_to_toml, load_campaign

VERTICAL = math.pi / 2  # math.radians(90.0) is exactly this
TENSION = 5.0e5
EI = 2.0e5
EA = 2.0e9
N_MODES = 12
#: Two hangers, a short stiff one (ξ = l √(H/EI) = 12.6) and a long one (47)
HANGERS = [(8.0, 40.0), (30.0, 60.0)]
ENDS = {"clamped": Boundary.clamped(), "pinned": Boundary.pinned()}


def hanger(length, mass, end="clamped", inclination=VERTICAL, ea=EA):
    return Cable(length, mass, EI, ea, inclination, boundary_a=ENDS[end], boundary_b=ENDS[end])


def pinned_beam(length, mass, n):
    """f_n = n/(2l) √(T/m) √(1 + n²π² EI / (T l²)), the pinned tensioned beam under uniform tension."""
    return n / (2 * length) * np.sqrt(TENSION / mass) * np.sqrt(1 + n**2 * np.pi**2 * EI / (TENSION * length**2))


# ---------------------------------------------------------------------------------------------------------
# The model
# ---------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("sign", [1, -1])
def test_a_vertical_cable_has_no_weight_normal_to_its_chord_and_no_sag(sign):
    cable = hanger(20.0, 50.0, inclination=sign * VERTICAL)
    # math.cos(π/2) is 6.1e-17: exactly 0 here, or a vertical hanger would get a spurious sag and λ²
    assert math.cos(cable.inclination) != 0.0
    assert (cable.chord_cosine, cable.chord_sine) == (0.0, float(sign)) and cable.vertical
    assert cable.weight_per_length == 0.0
    assert sag_ratio(cable, TENSION) == 0.0 and irvine_lambda2(cable, TENSION) == 0.0
    assert not hanger(20.0, 50.0, inclination=math.radians(89.9999)).vertical  # cos = 1.7e-6: not snapped
    assert chord_components(0.0) == (1.0, 0.0)


@pytest.mark.parametrize("degrees", [90.0001, -90.5, 180.0])
def test_beyond_vertical_is_still_refused(degrees):
    with pytest.raises(ModelError, match="cable.inclination.*<= 90 degrees"):
        Cable(20.0, 50.0, EI, inclination=math.radians(degrees))


@pytest.mark.parametrize("degrees", [90, -90, 90.0])
def test_a_campaign_reads_and_writes_a_vertical_cable(tmp_path, degrees):
    text = (f"[campaign]\nname = \"h\"\n\n[cable]\nlength = 20.0\nmass_per_length = 50.0\nEI = 2.0e5\n"
            f"inclination = {degrees}\n")
    (tmp_path / "campaign.toml").write_text(text)
    campaign = load_campaign(tmp_path)
    assert campaign.cable.inclination == math.copysign(VERTICAL, degrees) and campaign.cable.vertical
    out = tmp_path / "again"
    out.mkdir()
    (out / "campaign.toml").write_text(campaign_to_toml(campaign))
    assert f"inclination = {float(degrees)!r}\n" in campaign_to_toml(campaign)
    assert load_campaign(out).cable == campaign.cable


def test_a_campaign_beyond_vertical_names_the_file_and_field(tmp_path):
    (tmp_path / "campaign.toml").write_text("[campaign]\nname = \"h\"\n\n[cable]\nlength = 20.0\n"
                                            "mass_per_length = 50.0\nEI = 2.0e5\ninclination = 90.5\n")
    with pytest.raises(CampaignError) as info:
        load_campaign(tmp_path)
    assert "campaign.toml" in str(info.value) and "field 'cable.inclination'" in str(info.value)
    assert "<= 90 degrees, got 90.5" in str(info.value)


# ---------------------------------------------------------------------------------------------------------
# Forward: exact solver, closed form, finite elements
# ---------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("length, mass", HANGERS)
@pytest.mark.parametrize("end", ["clamped", "pinned"])
@pytest.mark.parametrize("loaded", [False, True])
def test_the_in_plane_family_of_a_vertical_cable_is_its_out_of_plane_one_exactly(length, mass, end, loaded):
    atts = (Attachment("clamp", 0.3 * length, mass=25.0),) if loaded else ()
    cable = hanger(length, mass, end)
    out = natural_frequencies(cable, atts, TENSION, N_MODES, plane="out")
    for model in ("uniform", "per-segment", "none"):  # no sag: every tension model is the taut beam
        assert np.array_equal(natural_frequencies(cable, atts, TENSION, N_MODES, tension_model=model), out), model
    assert np.array_equal(natural_frequencies(replace(cable, EA=None), atts, TENSION, N_MODES), out)
    assert np.array_equal(natural_frequencies(replace(cable, inclination=-VERTICAL), atts, TENSION, N_MODES), out)
    # The finite-element model keeps its sag vector g, exactly 0 here: its planes agree exactly too
    fe_in = fe_frequencies(cable, atts, TENSION, 6, n_elements=100)
    assert np.array_equal(fe_in, fe_frequencies(cable, atts, TENSION, 6, n_elements=100, plane="out"))


@pytest.mark.parametrize("length, mass", HANGERS)
def test_a_pinned_vertical_hanger_is_the_pinned_tensioned_beam(length, mass):
    f = natural_frequencies(hanger(length, mass, "pinned"), (), TENSION, N_MODES)
    expected = pinned_beam(length, mass, np.arange(1, N_MODES + 1))
    # 1e-9: the solver refines to 1e-12 relative; what is left is the rounding of the closed form's terms
    # (measured: 9e-14). A sag term (λ² = 0.2 for the 30 m hanger horizontal) would be a whole per cent.
    np.testing.assert_allclose(f, expected, rtol=1e-9)
    horizontal = natural_frequencies(hanger(length, mass, "pinned", inclination=0.0), (), TENSION, N_MODES)
    assert abs(horizontal[0] / expected[0] - 1) > 1e-4  # the same cable horizontal: mode 1 lifted by its sag


@pytest.mark.parametrize("length, mass", HANGERS)
@pytest.mark.parametrize("end", ["clamped", "pinned"])
@pytest.mark.parametrize("loaded", [False, True])
def test_a_vertical_hanger_agrees_with_the_finite_element_model(length, mass, end, loaded):
    atts = (Attachment("clamp", 0.3 * length, mass=25.0),) if loaded else ()
    cable = hanger(length, mass, end)
    exact = natural_frequencies(cable, atts, TENSION, N_MODES)
    coarse, fine = (np.abs(fe_frequencies(cable, atts, TENSION, N_MODES, n_elements=n) / exact - 1).max()
                    for n in (200, 400))
    # The FE frequencies converge as h⁴ towards the exact ones: 400 elements leave at most 1.1e-7 on the
    # first 12 modes of these hangers (measured); 1e-6 is far below a mode spacing (a missed or doubled root)
    assert fine < 1e-6, fine
    assert 10 < coarse / fine < 20, (coarse, fine)  # halving h divides the error by about 16


def test_the_vertical_limit_is_continuous():
    """Towards 90° the in-plane family goes smoothly to the vertical one (no jump, no sign flip): the sag term
    vanishes as λ² ∝ cos²θ."""
    atts = (Attachment("clamp", 9.0, mass=25.0),)
    vertical = natural_frequencies(hanger(30.0, 60.0), atts, TENSION, 6)
    gaps = [np.abs(natural_frequencies(hanger(30.0, 60.0, inclination=math.radians(90 - d)), atts, TENSION, 6)
                   / vertical - 1).max() for d in (1.0, 0.1, 0.01)]
    assert gaps[0] > 0 and gaps[0] < 1e-3
    # λ² (hence the shift of mode 1) falls as cos²θ: 100x per decade of the angle from vertical (within 5 %)
    assert 95 < gaps[0] / gaps[1] < 105 and 95 < gaps[1] / gaps[2] < 105, gaps


def test_a_damper_on_a_vertical_hanger_agrees_with_the_finite_element_model():
    cable = hanger(20.0, 50.0)
    damper = Damper("D", 1.0, mass=5.0, coefficient=4.0e4)
    exact = complex_modes(cable, (damper,), TENSION, 4)
    fe = fe_complex_modes(cable, (damper,), TENSION, 4, n_elements=400, grading=2.0)
    # The FE discretisation (h⁴, the mesh graded at the clamped ends) leaves 7e-10 on the frequencies and 1e-8
    # on the damping ratios (measured); 1e-7 and 1e-6 leave room for another LAPACK, far below a mode's shift
    np.testing.assert_allclose(fe.frequency, exact.frequency, rtol=1e-7)
    np.testing.assert_allclose(fe.damping, exact.damping, rtol=1e-6)
    assert np.all(exact.damping > 1e-3)
    # Acting in-plane only (angle 0): out of plane it is a weightless point (sin²0 = 0 of its dashpot and moving
    # mass), and the out-of-plane family is the bare hanger's, undamped
    out = complex_modes(cable, (damper,), TENSION, 4, plane="out")
    np.testing.assert_allclose(out.frequency, natural_frequencies(cable, (), TENSION, 4, plane="out"), rtol=1e-9)
    assert np.all(np.abs(out.damping) < 1e-12)


# ---------------------------------------------------------------------------------------------------------
# The quick answer and the simulator
# ---------------------------------------------------------------------------------------------------------


def test_the_quick_tension_of_a_vertical_hanger():
    length, mass = 20.0, 50.0
    f = natural_frequencies(hanger(length, mass), (), TENSION, 4)
    value, _ = quick_tension(length, mass, f, EI=EI, EA=EA, inclination=90.0, uncertainty=1e-4,
                             EI_tolerance=0.0).tension("exact")
    # The model's own frequencies: its tension back, to the fit's convergence (measured: 1e-10)
    assert abs(value / TENSION - 1) < 1e-6, value
    value_out, _ = quick_tension(length, mass, f, EI=EI, inclination=-90.0, uncertainty=1e-4, EI_tolerance=0.0,
                                 plane="out").tension("exact")
    assert abs(value_out / value - 1) < 1e-9, (value_out, value)
    with pytest.raises(InputError, match="inclination"):
        quick_tension(length, mass, f, EI=EI, inclination=90.01)


def _sim(argv):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return main([str(a) for a in argv])


CAMPAIGN = """\
[campaign]
name = "hanger"

[cable]
length = 20.0
mass_per_length = 50.0
EI = 2.0e5
EA = 1.0e9
inclination = {inclination}
boundary = "clamped"

[[setup]]
name = "bare"

[[setup]]
name = "clamp"
[[setup.attachment]]
name = "M1"
position = 3.0
mass = 40.0

[[test]]
name = "T1"
setup = "bare"
tension = 5.0e5

[[test]]
name = "T2"
setup = "clamp"
tension = 5.5e5
"""


def write_campaign(directory, inclination=90.0):
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "campaign.toml").write_text(CAMPAIGN.format(inclination=inclination))
    return directory


@pytest.mark.parametrize("inclination", [90.0, -90.0])
def test_a_deck_mode_moves_a_vertical_hanger_along_its_chord_only(tmp_path, inclination):
    """simulate --deck-modes: a deck's vertical motion is all axial at a vertical hanger's anchorage, so with no
    other excitation its transverse channels read exactly nothing (not cos(π/2) = 6e-17 of the deck)."""
    nominal = write_campaign(tmp_path / "nominal", inclination)
    out = tmp_path / "sim"
    assert _sim(["simulate", nominal, "--out", out, "--test", "T1", "--triaxial", "--sensors", "0.5",
                 "--impulses", "0", "--duration", "120", "--sampling-rate", "50", "--deck-modes", "1.3:0.05"]) == 0
    with h5py.File(out / "records" / "T1.h5") as f:
        acc = f["acceleration"][()]
        directions = [d.decode() if isinstance(d, bytes) else d for d in f["channel_direction"][()]]
    assert directions == ["in", "out", "axial"]
    assert np.all(acc[:, 0] == 0) and np.all(acc[:, 1] == 0)
    rms = np.sqrt(np.mean(acc[:, 2] ** 2))
    # the chord line's axial motion at mid-length: half the deck's 0.05 m/s² rms in expectation; a 120-s record
    # of a 1 % damped narrow band holds about ten lengths of its envelope's correlation (12 s), so the sample
    # rms scatters by about 20 % (measured on six seeds: 0.020-0.029): a factor 2 either way
    assert 0.5 * 0.05 / 2 < rms < 0.5 * 0.05 * 2, rms


# ---------------------------------------------------------------------------------------------------------
# Every command on a hanger campaign
# ---------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def hanger_records(tmp_path_factory):
    """The vertical hanger's two tests (bare; a 40 kg clamp) simulated with a triaxial sensor at two positions,
    ambient and one blow, a deck mode and traffic."""
    root = tmp_path_factory.mktemp("vertical")
    nominal = write_campaign(root / "nominal")
    out = root / "sim"
    assert _sim(["simulate", nominal, "--out", out, "--triaxial", "--sensors", "0.23,0.41", "--ambient", "10",
                 "--impulses", "1", "--duration", "120", "--sampling-rate", "100", "--deck-modes", "1.3:0.05",
                 "--traffic", "30:0.01", "--seed", "2"]) == 0
    return root


@pytest.mark.slow  # simulate, spectra, identify, diagnose and track on the hanger: about 25 s
def test_every_command_on_a_vertical_hanger(hanger_records, tmp_path, capsys):
    nominal, sim = hanger_records / "nominal", hanger_records / "sim"
    capsys.readouterr()

    assert _sim(["forward", nominal, "--plane", "both", "--json", tmp_path / "f.json"]) == 0
    for test in json.loads((tmp_path / "f.json").read_text())["tests"]:
        assert test["frequencies"]["dsm"] == test["out_of_plane"]["frequencies"]["dsm"], test["name"]
        assert test["frequencies"]["dsm"][0] > test["frequencies"]["beam_pinned"][0]  # clamped: above pinned

    truth = {t["name"]: t for t in json.loads((sim / "truth.json").read_text())["tests"]}
    assert all(t["frequencies_in"] == t["frequencies_out"] for t in truth.values())

    assert _sim(["spectra", sim, "--json", tmp_path / "s.json"]) == 0
    for test in json.loads((tmp_path / "s.json").read_text())["tests"]:
        assert {"in", "out"} <= set(test["planes"])
        family = truth[test["name"]]["frequencies_in"]
        for mode, f, sigma in zip(test["modes"], test["frequencies"], test["uncertainty"]):
            # 5σ: one record's error is a draw of its 1σ (coverage is tested elsewhere, over many records); a
            # mode given the wrong number would be a mode spacing (2.7 Hz) off
            assert abs(f - family[mode - 1]) <= 5 * sigma, (test["name"], mode, f, family[mode - 1], sigma)

    assert _sim(["identify", sim, "--json", tmp_path / "i.json"]) == 0
    result = json.loads((tmp_path / "i.json").read_text())
    for name, ratio in result["parameters"]["tension_ratio"].items():
        sigma = result["uncertainty"]["tension_ratio"][name]
        # simulated at the stated tension: within 3σ (one draw), and σ small enough to mean something (the
        # nominal tolerances of length and mass dominate it: about 1 %)
        assert abs(ratio - 1) <= 3 * sigma and sigma < 0.03, (name, ratio, sigma)

    assert _sim(["diagnose", sim, "--json", tmp_path / "d.json"]) == 0
    cause = json.loads((tmp_path / "d.json").read_text())["cause"]
    assert cause["explained_by_nominal"], cause["statement"]  # the records hold nothing the model lacks

    f1 = truth["T1"]["frequencies_in"][:4]
    assert _sim(["tension", "--length", "20", "--mass", "50", "--EI", "2e5", "--EA", "1e9", "--inclination", "90",
                 "--frequencies", ",".join(f"{f:.6f}" for f in f1), "--json", tmp_path / "t.json"]) == 0
    exact = json.loads((tmp_path / "t.json").read_text())["methods"]["exact"]
    # frequencies printed to 1e-6 Hz: the tension back to 1e-5 (its σ from the frequencies alone is smaller)
    assert abs(exact["tension"] / 5.0e5 - 1) < 1e-5, exact
    assert _sim(["tension", "--length", "20", "--mass", "50", "--inclination", "90.5", "--frequencies", "2.7"]) == 2
    assert "option '--inclination': must be between -90 and 90 degrees, got 90.5" in capsys.readouterr().err

    arch = tmp_path / "arch"
    assert _sim(["simulate", nominal, "--out", arch, "--archive", "0.25", "--cables", "2", "--interval", "3600",
                 "--duration", "180", "--sampling-rate", "100", "--seed", "4"]) == 0
    assert _sim(["track", arch, "--out", tmp_path / "h", "--json", tmp_path / "ts.json"]) == 0
    summary = json.loads((tmp_path / "ts.json").read_text())
    assert {name: c["processed"] for name, c in summary["cables"].items()} == {"C1": 6, "C2": 6}
    with open(tmp_path / "h" / "records.csv") as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == 12 and all(row["status"] == "ok" for row in rows), rows
    history = json.loads((arch / "truth.json").read_text())["cables"]
    true = {(c, r["record"]): r["tension"] for c, v in history.items() for r in v["records"]}
    for row in rows:
        t, sigma = float(row["tension_N"]), float(row["tension_sigma_N"])
        # each record's own σ (0.06 %) with 4σ: one draw each of twelve
        assert abs(t - true[(row["cable"], row["record"])]) < 4 * sigma, (row["record"], t, sigma)
