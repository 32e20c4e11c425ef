"""The out-of-plane forward model against the finite-element reference and Irvine's closed forms.

Out of the cable's plane the same segments, attachments and EI hold without the additional tension of
sag-extensibility; a spring acts with its ``stiffness_out``, a damper at angle α with sin²α of its values
(cos²α in-plane). The exact solver (DSM) and the finite-element model (FE, built independently of it) must
agree to 1e-6 on random cables; a taut string reproduces Irvine's in-plane/out-of-plane split of mode 1.
"""

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

from stcs_ident.core.model import Attachment, Cable, Campaign, Damper, Setup, Test
from stcs_ident.core.planes import PLANE_NAMES
from stcs_ident.forward import natural_frequencies
from stcs_ident.forward.compare import compare_forward
from stcs_ident.forward.damped import complex_modes
from stcs_ident.forward.fem import fe_frequencies
from stcs_ident.forward.fem_damped import fe_complex_modes
from stcs_ident.forward.statics import end_slopes, stretched_lengths
from tests.random_cables import random_configuration

N_CONFIGS = 200
N_MODES = 12
RTOL = 1e-6  # the acceptance for the out-of-plane frequencies against the FE reference


def out_of_plane_configuration(rng):
    """A random configuration of tests/random_cables.py whose springs get a different out-of-plane stiffness
    (none, a fraction or a multiple of the in-plane one, or one where there is none in-plane)."""
    cable, atts, H = random_configuration(rng)
    mapped = []
    for a in atts:
        pick = rng.integers(4)
        if pick == 1:
            a = replace(a, stiffness_out=a.stiffness * 10 ** rng.uniform(-1, 1))
        elif pick == 2:
            a = replace(a, stiffness_out=10 ** rng.uniform(-1, 2) * H / cable.length)
        elif pick == 3:
            a = replace(a, stiffness_out=0.0)
        mapped.append(a)
    return cable, mapped, H


def converged_error(exact, fe_at, meshes):
    """Largest relative FE-exact difference on the first mesh that reaches RTOL. The FE model converges as
    h⁴ (h⁶ for a string); where a mesh is not yet within RTOL the next, twice as fine, must move towards the
    exact answer (as tests/test_fe_agreement.py does), so a wrong exact root cannot pass by refinement."""
    err = None
    for n in meshes:
        new = float(np.abs(fe_at(n) / exact - 1).max())
        if err is not None:
            assert new < err, f"FE does not converge towards the exact solver ({err:.2e} -> {new:.2e})"
        err = new
        if err <= RTOL:
            break
    return err


def test_out_of_plane_frequencies_agree_with_finite_elements():
    """200 random cables (tests/random_cables.py) with out-of-plane spring stiffnesses of their own."""
    rng = np.random.default_rng(2024)
    worst, split = 0.0, 0
    for i in range(N_CONFIGS):
        cable, atts, H = out_of_plane_configuration(rng)
        exact = natural_frequencies(cable, atts, H, N_MODES, plane="out")
        err = converged_error(exact, lambda n, c=cable, a=atts, h=H: fe_frequencies(
            c, a, h, N_MODES, n_elements=n, grading=2.0, solver="sparse", plane="out"), (600, 1200, 2400))
        assert err <= RTOL, f"configuration {i}: {err:.2e}"
        worst = max(worst, err)
        in_plane = natural_frequencies(cable, atts, H, N_MODES, plane="in")
        split += np.abs(in_plane / exact - 1).max() > 1e-3
    # The check has teeth: in most configurations the planes differ by far more than RTOL (sag term, springs).
    assert split > N_CONFIGS // 2
    print(f"largest relative out-of-plane DSM-FE difference over {N_CONFIGS} configurations: {worst:.2e}")


def damped_configuration(rng):
    """A random configuration with a damper at a random angle (0–90°) near an end: its dashpot 0.1–10 times
    the one that damps mode 1 best, a small moving mass, sometimes a spring; the other attachments kept 3 %
    of the span away from it."""
    cable, atts, H = out_of_plane_configuration(rng)
    length, m = cable.length, cable.mass_per_length
    xd = rng.uniform(0.02, 0.1) * length
    c_best = math.sqrt(H * m) / (math.pi * xd / length)  # Krenk's optimum for mode 1 of a taut string
    damper = Damper("D", xd, rng.uniform(0, 0.02) * m * length,
                    (10 ** rng.uniform(-1, 1) * H / length) if rng.random() < 0.3 else 0.0,
                    coefficient=c_best * 10 ** rng.uniform(-1, 1), angle=math.radians(rng.uniform(0, 90)))
    kept = [a for a in atts if abs(a.position - xd) > 0.03 * length]
    return cable, sorted([*kept, damper], key=lambda a: a.position), H


def fe_matched(cable, atts, H, exact, n_elements, plane):
    """The FE roots nearest the exact ones (two more asked, so none drops off the top), each taken once. The
    FE also finds roots of damping ratio above 0.5, which the exact solver leaves out by design (no record
    shows them as a peak): every FE root below the exact ones' top with ζ < 0.5 must be among them."""
    fe = fe_complex_modes(cable, atts, H, exact.size + 2, n_elements=n_elements, grading=2.0, plane=plane).s
    pairs = np.argmin(np.abs(exact[:, None] - fe[None, :]), axis=1)
    assert np.unique(pairs).size == pairs.size, "one FE root taken for two exact ones"
    below = fe[(np.abs(fe) < np.abs(exact).max() * (1 - 1e-6)) & (-fe.real / np.abs(fe) < 0.5 * (1 - 1e-3))]
    assert np.all(np.min(np.abs(below[:, None] - exact[None, :]), axis=1) < 1e-4 * np.abs(below)), \
        "an FE mode the exact solver missed"
    return fe[pairs]


@pytest.mark.parametrize("plane", ["in", "out"])
def test_complex_modes_with_an_angled_damper_agree_with_finite_elements(plane):
    """Complex roots s (frequency and damping together, relative to |s|) on 30 random cables per plane."""
    rng = np.random.default_rng(31)
    worst = 0.0
    for i in range(30):
        cable, atts, H = damped_configuration(rng)
        exact = complex_modes(cable, atts, H, 8, plane=plane).s
        err = converged_error(exact, lambda n, c=cable, a=atts, h=H, e=exact: fe_matched(c, a, h, e, n, plane),
                              (400, 800, 1600))
        assert err <= RTOL, f"configuration {i} ({PLANE_NAMES[plane]}): {err:.2e}"
        worst = max(worst, err)
    print(f"largest relative {PLANE_NAMES[plane]} complex-root DSM-FE difference over 30 configurations: {worst:.2e}")


# ------------------------------------------------------------------ Irvine


def exact_lambda2(cable, H):
    """λ² = (w l/H)² l EA / (H L_e) with L_e = ∫(1 + y'²)^{3/2} dx of the parabolic profile, as the solver
    uses it (docs/model.md)."""
    w = cable.weight_per_length
    seg, s0, s1 = end_slopes(np.array([cable.length]), np.zeros((1, 0)), np.array([w / H]), np.zeros((1, 0)))
    Le = stretched_lengths(seg, s0, s1).sum()
    return (w * cable.length / H) ** 2 * cable.length * cable.EA / (H * Le)


def irvine_split(lambda2):
    """f₁ in-plane / f₁ out-of-plane of Irvine's string for λ² < 4π² (mode 1 is symmetric): ω̄/π with ω̄/2 the
    root of tan(x) = x − (4/λ²) x³ in (π/2, π] (out of plane ω̄ = π)."""
    x = brentq(lambda x: math.tan(x) - x + 4.0 / lambda2 * x**3, math.pi / 2 + 1e-12, math.pi,
               xtol=1e-15, rtol=1e-15)
    return 2 * x / math.pi


def test_irvine_split_of_mode_1_is_reproduced_over_lambda2_01_to_10():
    """A string (EI = 0, where Irvine's theory is exact) inclined 20°: EA set for λ² from 0.1 to 10. The
    solver's in-plane model is Irvine's linear shallow-sag theory itself and its out-of-plane model the
    taut string, so the split agrees to the roots' refinement (1e-12), not just to the ~1e-6 of a
    discretisation: 1e-9 leaves room for the root refinement and rounding only. The out-of-plane f₁ is
    also checked against 1/(2l) √(H/m)."""
    length, m, H = 100.0, 5.0, 1.5e5
    unit = exact_lambda2(Cable(length=length, mass_per_length=m, EI=0.0, EA=1.0, inclination=math.radians(20)), H)
    worst = 0.0
    for lambda2 in np.geomspace(0.1, 10.0, 21):
        cable = Cable(length=length, mass_per_length=m, EI=0.0, EA=lambda2 / unit, inclination=math.radians(20))
        f_in = natural_frequencies(cable, [], H, 1, plane="in")[0]
        f_out = natural_frequencies(cable, [], H, 1, plane="out")[0]
        assert f_out == pytest.approx(math.sqrt(H / m) / (2 * length), rel=1e-12)  # root refinement ~2e-13
        ratio = f_in / f_out
        expected = irvine_split(lambda2)
        assert ratio == pytest.approx(expected, rel=1e-9)
        worst = max(worst, abs(ratio / expected - 1))
    # The split is not trivial: from ~0.2 % at λ² = 0.1 to ~30 % at λ² = 10.
    assert irvine_split(0.1) - 1 > 1e-3 and irvine_split(10.0) - 1 > 0.2
    print(f"largest relative difference from Irvine's split over λ² 0.1-10: {worst:.2e}")


# ---------------------------------------------------------- damper at an angle

L, M, H = 100.0, 50.0, 2.0e6
XD = 0.02 * L


@pytest.mark.parametrize("degrees", [0.0, 20.0, 45.0, 70.0, 90.0])
def test_an_angled_damper_acts_in_each_plane_as_a_damper_of_cos2_or_sin2_of_its_values(degrees):
    """The uncoupled model's identity: at angle α the in-plane roots are those of the damper with
    cos²α of its dashpot, spring and moving mass acting in-plane, the out-of-plane roots those of sin²α of
    them on the cable without the sag term. Both sides are exact roots of the same equations, so they
    agree to the solver's refinement (1e-10 leaves room for it)."""
    alpha = math.radians(degrees)
    cable = Cable(length=L, mass_per_length=M, EI=2e4, EA=2e9, inclination=math.radians(25))
    c, md, kd = 3e5, 40.0, 2e5
    damper = Damper("D", XD, md, kd, coefficient=c, angle=alpha)
    others = [Attachment("W", 30.0, 20.0, 1e4, stiffness_out=3e4)]
    for plane, share, twin in (("in", math.cos(alpha) ** 2, cable), ("out", math.sin(alpha) ** 2,
                                                                     replace(cable, EA=None))):
        got = complex_modes(cable, [damper, *others], H, 5, plane=plane)
        if share * c < 1e-6:  # no dashpot in this plane (cos²90°, sin²0°): the undamped modes
            assert np.all(got.damping == 0)
            continue
        same = Damper("D", XD, md * share, kd * share, coefficient=c * share)
        k_other = 1e4 if plane == "in" else 3e4
        want = complex_modes(twin, [same, Attachment("W", 30.0, 20.0, k_other)], H, 5, plane="in")
        np.testing.assert_allclose(got.s, want.s, rtol=1e-10, atol=0)
    if 0 < degrees < 90:  # the planes differ: the identity above compares different problems per plane
        zin = complex_modes(cable, [damper, *others], H, 3, plane="in").damping
        zout = complex_modes(cable, [damper, *others], H, 3, plane="out").damping
        assert np.abs(zin / zout - 1).max() > 1e-3


@pytest.mark.parametrize("n", [1, 2, 3])
@pytest.mark.parametrize("eta", [0.3, 1.0, 3.0])
def test_the_out_of_plane_damping_follows_krenk_s_curve_with_sin2_of_the_dashpot(n, eta):
    """A taut string with a damper near an end at 60°: out of plane it damps mode n like a dashpot
    c sin²α, ζ_n/(x_d/l) = η/(1 + η²), η = π n (x_d/l) c sin²α / √(H m)."""
    alpha = math.radians(60.0)
    c = eta * math.sqrt(H * M) / (math.pi * n * XD / L) / math.sin(alpha) ** 2
    cable = Cable(L, M, 0.0, EA=1e9)  # the sag term must not matter out of plane
    modes = complex_modes(cable, [Damper("D", XD, coefficient=c, angle=alpha)], H, 4, plane="out")
    krenk = (XD / L) * eta / (1 + eta**2)
    assert modes.damping[n - 1] == pytest.approx(krenk, rel=0.04)  # Krenk's asymptote is O(x_d/l) = 2 %
    assert modes.frequency[n - 1] == pytest.approx(n * math.sqrt(H / M) / (2 * L), rel=0.03)  # shift < x_d/l


# ---------------------------------------------------------- stiffness_out and EA


def spring_string_frequencies(length, m, H, K, a, n):
    """Taut string with a spring K to ground at x = a: roots of H q sin(q l) + K sin(q a) sin(q b) = 0,
    q = ω √(m/H) (the point-mass equation with −K for M ω²), first ``n`` in Hz."""
    def g(q):
        return H * q * np.sin(q * length) + K * np.sin(q * a) * np.sin(q * (length - a))

    grid = np.linspace(1e-9, (n + 1.5) * math.pi / length, 200000)
    vals = g(grid)
    roots = [brentq(g, grid[i], grid[i + 1], xtol=1e-300, rtol=1e-15)
             for i in np.flatnonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0)]
    return np.array(roots[:n]) * math.sqrt(H / m) / (2 * math.pi)


@pytest.mark.parametrize("k_in,k_out", [(0.0, 4e5), (4e5, 0.0), (1e5, 2e6)])
def test_an_attachment_s_out_of_plane_stiffness_is_honoured(k_in, k_out):
    """A string with a spring at 0.3 l: each plane's frequencies are the closed form with its own stiffness
    (the sag term off, EA = None, so the in-plane closed form holds too); 1e-9: exact roots both sides."""
    length, m, tension, a = 40.0, 8.0, 5e5, 12.0
    cable = Cable(length=length, mass_per_length=m, EI=0.0)
    spring = Attachment("S", a, 0.0, k_in, stiffness_out=k_out)
    for plane, k in (("in", k_in), ("out", k_out)):
        got = natural_frequencies(cable, [spring], tension, 6, plane=plane)
        np.testing.assert_allclose(got, spring_string_frequencies(length, m, tension, k, a, 6), rtol=1e-9)
        fe = fe_frequencies(cable, [spring], tension, 6, n_elements=400, solver="sparse", plane=plane)
        np.testing.assert_allclose(fe, got, rtol=1e-7)  # a string's FE error ~h⁶ is ~1e-10 at 400 elements
    # stiffness_out=None: the in-plane stiffness in both planes
    same = Attachment("S", a, 0.0, k_in)
    np.testing.assert_allclose(natural_frequencies(cable, [same], tension, 6, plane="out"),
                               natural_frequencies(cable, [same], tension, 6, plane="in"), rtol=1e-12)


def test_out_of_plane_frequencies_do_not_depend_on_ea():
    """Random cables with their sag term: the out-of-plane frequencies are the same for EA as given, 1000
    times larger and None (both solvers), while the in-plane ones move (the check has teeth)."""
    rng = np.random.default_rng(7)
    moved = 0
    for _ in range(20):
        cable, atts, H = out_of_plane_configuration(rng)
        if cable.EA is None:
            continue
        base = natural_frequencies(cable, atts, H, 8, plane="out")
        for EA in (cable.EA * 1e3, None):
            other = replace(cable, EA=EA)
            np.testing.assert_allclose(natural_frequencies(other, atts, H, 8, plane="out"), base, rtol=1e-11)
            np.testing.assert_allclose(fe_frequencies(other, atts, H, 8, n_elements=200, solver="sparse", plane="out"),
                                       fe_frequencies(cable, atts, H, 8, n_elements=200, solver="sparse", plane="out"),
                                       rtol=1e-12)  # the same matrices: rounding only
        stiff = natural_frequencies(replace(cable, EA=cable.EA * 1e3), atts, H, 8, plane="in")
        moved += np.abs(stiff / natural_frequencies(cable, atts, H, 8, plane="in") - 1).max() > 1e-3
    assert moved >= 5


# ---------------------------------------------------------- the forward comparison

def two_plane_campaign():
    """A sagging cable (λ² ≈ 3.5, so mode 1 differs by ~5 % between the planes) with a spring whose
    out-of-plane stiffness is three times its in-plane one; test T measured modes 1 and 2 in-plane and mode 1
    out-of-plane (0.1 % and 0.2 % off the model), with a reference column equal to each plane's model to its
    printed 0.0001 Hz; test U (setup D) has a light damper at 60° and no frequencies."""
    cable = Cable(length=100.0, mass_per_length=50.0, EI=2e4, EA=2e9, inclination=0.4)
    plain = Setup("S", (Attachment("W", 30.0, 20.0, 1e4, stiffness_out=3e4),))
    damped = Setup("D", (Damper("DA", 2.0, coefficient=5e4, angle=math.radians(60)),))
    H = 2e6
    f_in = natural_frequencies(cable, plain.attachments, H, 2, plane="in")
    f_out = natural_frequencies(cable, plain.attachments, H, 1, plane="out")
    test = Test("T", "S", H, frequencies=(f_in[0] * 1.001, f_in[1] * 1.001, f_out[0] * 0.998), modes=(1, 2, 1),
                planes=("in", "in", "out"),
                reference=(("paper", tuple(round(f, 4) for f in (f_in[0], f_in[1], f_out[0]))),))
    campaign = Campaign("planes", cable, (plain, damped), (test, Test("U", "D", H)))
    return campaign, f_in, f_out


def test_forward_compares_each_measured_frequency_with_the_mode_of_its_own_plane():
    campaign, f_in, f_out = two_plane_campaign()
    assert abs(f_out[0] / f_in[0] - 1) > 0.01  # comparing with the other plane's mode would show
    result = compare_forward(campaign)  # default: both, T has an out-of-plane frequency
    assert result.planes == ("in", "out")
    t_in, t_out = result.test("T"), result.test("T", plane="out")
    np.testing.assert_allclose(t_in.dsm[:2], f_in, rtol=1e-12)
    np.testing.assert_allclose(t_out.dsm[:1], f_out, rtol=1e-12)
    np.testing.assert_allclose(t_in.error("dsm")[:2], [100 * (1 / 1.001 - 1)] * 2, rtol=1e-9)
    assert t_out.error("dsm")[0] == pytest.approx(100 * (1 / 0.998 - 1), rel=1e-9)
    assert t_in.modes == (1, 2) and t_out.modes == (1,)  # each plane shows its measured modes
    check = result.reference_checks[0]  # each reference value against its own plane's model
    assert check.reproduced
    assert check.max_nominal <= 5e-5  # rounded to 0.0001 Hz: half a step at most
    # the damper at 60°: a quarter of its dashpot in-plane, three quarters out of plane
    u_in, u_out = result.test("U"), result.test("U", plane="out")
    assert len(u_in.modes) == len(u_out.modes) == 6  # not measured: the first 6 of each plane
    # a light damper (η₁ = 0.08 in-plane, 0.24 out of plane): ζ nearly ∝ its share, 3 times more out of plane
    # for mode 1 (measured 3.0), less as η_n = n η₁ nears Krenk's optimum
    assert np.all(u_out.damping[:3] > 2 * u_in.damping[:3])
    table = result.tables()["frequencies"]
    assert list(table.columns[:3]) == ["test", "plane", "mode"] and set(table["plane"]) == {"in", "out"}


def test_forward_json_keeps_the_in_plane_keys_and_adds_the_out_of_plane_family():
    campaign, f_in, f_out = two_plane_campaign()
    both = compare_forward(campaign, ["T"]).summary()
    entry = both["tests"][0]
    assert both["planes"] == ["in", "out"]
    assert set(entry) >= {"name", "setup", "tension", "modes", "frequencies", "measured", "errors", "reference",
                          "out_of_plane"}
    assert entry["measured"][:2] == pytest.approx([f * 1.001 for f in f_in], rel=1e-12)
    assert entry["out_of_plane"]["measured"][0] == pytest.approx(f_out[0] * 0.998, rel=1e-12)
    assert entry["out_of_plane"]["reference"]["paper"][0] == round(f_out[0], 4)
    only_in = compare_forward(campaign, ["T"], plane="in").summary()
    assert only_in["planes"] == ["in"] and "out_of_plane" not in only_in["tests"][0]
    assert only_in["tests"][0]["measured"][:2] == entry["measured"][:2]
    assert only_in["reference_checks"][0]["reproduced"]  # the in-plane values alone
    only_out = compare_forward(campaign, ["T"], plane="out").summary()
    assert only_out["planes"] == ["out"] and "modes" not in only_out["tests"][0]
    assert only_out["tests"][0]["out_of_plane"] == entry["out_of_plane"]
    # a campaign without out-of-plane frequencies: the in-plane family only, as before the planes
    plain = replace(campaign, tests=(replace(campaign.test("T"), frequencies=(f_in[0],), modes=(1,), planes=None,
                                             reference=()),))
    result = compare_forward(plain)
    assert result.planes == ("in",) and not result.out_of_plane
    assert "plane" not in result.tables()["frequencies"].columns


def test_forward_command_plane_option(tmp_path, capsys):
    from stcs_ident.cli.main import main
    from stcs_ident.io.campaign_toml import campaign_to_toml

    campaign, _, f_out = two_plane_campaign()
    (tmp_path / "campaign.toml").write_text(campaign_to_toml(campaign), encoding="utf-8")
    assert main(["forward", str(tmp_path), "--test", "T", "--plane", "both", "--json", "-"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["tests"][0]["out_of_plane"]["frequencies"]["dsm"][0] == pytest.approx(f_out[0], rel=1e-12)
    assert main(["forward", str(tmp_path), "--test", "T"]) == 0  # default: both (T measured out of plane)
    text = capsys.readouterr().out
    assert "Test T (setup S, tension 2000.0 kN), in-plane" in text and "out-of-plane" in text
    assert main(["forward", str(tmp_path), "--test", "T", "--plane", "in"]) == 0
    assert "out-of-plane" not in capsys.readouterr().out
    with pytest.raises(SystemExit) as refused:  # argparse refuses a bad choice, as the console script exits
        main(["forward", str(tmp_path), "--plane", "sideways"])
    assert refused.value.code == 2 and "--plane" in capsys.readouterr().err


def test_the_shapes_of_a_bare_string_out_of_plane_are_sines():
    """A bare string (EI = 0, no attachment) has no nodal unknown; out of plane it has no sag term either, so
    the shapes need nodes the solver adds itself. They are sin(kπx/l) (mass-normalised: √(2/(m l)))."""
    from stcs_ident.forward.shapes import mode_shapes

    cable = Cable(100.0, 10.0, 0.0, EA=1e9)
    shapes = mode_shapes(cable, [], 1e5, 4, plane="out")
    x = np.array([13.0, 50.0, 70.0])
    k = np.arange(1, 5)
    expected = np.sqrt(2 / (10.0 * 100.0)) * np.sin(np.pi * np.outer(x, k) / 100.0)
    got = shapes(x)
    np.testing.assert_allclose(np.abs(got), np.abs(expected), atol=1e-9)  # to rounding; the sign is free
