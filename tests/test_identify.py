"""Identification on synthetic data from the forward model: exact data give the
true parameters back, the parameter abstraction, results, tables and bad input."""

import json
import math

import numpy as np
import pytest

from stcs_ident.core.errors import InputError
from stcs_ident.core.model import Attachment, Cable, Campaign, Setup, Test
from stcs_ident.forward import batch_frequencies
from stcs_ident.identify import IdentifiabilityWarning, Measurement, identify, parse_parameters
from stcs_ident.identify.corrected import corrected_campaign

CABLE = Cable(length=19.715, mass_per_length=16.6, EI=117338.3, EA=4.1382e8)
SETUPS = (
    Setup("bare"),
    Setup("one", (Attachment("W1", 7.0, 40.0),)),
    Setup("two", (Attachment("W1", 6.0, 40.0), Attachment("W2", 13.0, 25.0))),
    Setup("sensor", (Attachment("S1", 5.0, 0.0),)),
    Setup("mid", (Attachment("W1", 19.715 / 2, 40.0),)),
)
TENSION = 1.2e6
SIGMA = 0.005  # Hz, the stated uncertainty of synthetic frequencies
N_MODES = 8

# Exact data: the solver is accurate to 1e-12 and the fits converge to 1e-14, so
# 1e-6 relative (the acceptance criterion) leaves a wide margin.
EXACT_RTOL = 1e-6


def assert_recovers(result, truth, rtol=EXACT_RTOL):
    """Every identified variable equals the truth to ``rtol`` relative."""
    np.testing.assert_allclose(result.estimate, truth, rtol=rtol, atol=0)


def synthetic(setup="bare", tension_ratio=1.0, EI_ratio=1.0, positions=None, n_modes=N_MODES,
              tensions=(TENSION,), noise=None, rng=None):
    """A campaign whose tests' frequencies come from the forward model with the
    true values, and the matching measurements (uncertainty SIGMA)."""
    atts = next(s for s in SETUPS if s.name == setup).attachments
    kw = {} if positions is None else {"positions": positions}
    tests, picked = [], {}
    for i, H in enumerate(tensions):
        f = batch_frequencies(CABLE, atts, H * tension_ratio, n_modes, EI=CABLE.EI * EI_ratio, **kw)
        if noise is not None:
            f = f + rng.normal(0.0, noise, f.shape)
        test = Test(f"T{i + 1}", setup, H, tuple(f))
        tests.append(test)
        picked[test.name] = Measurement(test, np.arange(1, n_modes + 1), f, SIGMA, "given")
    return Campaign("synthetic", CABLE, SETUPS, tuple(tests)), picked


# (params, setup, true tension ratio, true EI ratio, true positions (m), expected variables)
EXACT_CASES = {
    "tension+EI": ("tension,EI", "bare", 1.0317, 0.8123, None, [1.0317, 0.8123]),
    "one position": ("position", "one", 1.0, 1.0, [7.31], [7.31 / 7.0]),
    "two positions": ("position", "two", 1.0, 1.0, [6.4123, 12.4567], [6.4123 / 6.0, 12.4567 / 13.0]),
    "tension+EI+position": ("tension,EI,position", "one", 1.0317, 0.8123, [7.31], [1.0317, 0.8123, 7.31 / 7.0]),
    "tension+EI+two positions": ("tension,EI,position", "two", 1.0317, 0.8123, [6.4123, 12.4567],
                                 [1.0317, 0.8123, 6.4123 / 6.0, 12.4567 / 13.0]),
}
METHOD_CASES = [(name, "lsq") for name in EXACT_CASES] + [("tension+EI", "contour"), ("two positions", "contour")]


@pytest.fixture(params=METHOD_CASES, ids=[f"{m}-{n}" for n, m in METHOD_CASES])
def exact_case(request):
    name, method = request.param
    params, setup, h, ei, pos, truth = EXACT_CASES[name]
    campaign, picked = synthetic(setup, h, ei, pos)
    return campaign, picked, params, method, truth


def test_exact_data_give_the_truth(exact_case):
    campaign, picked, params, method, truth = exact_case
    result = identify(campaign, ["T1"], params, method=method, picked=picked)
    assert_recovers(result, truth)
    assert result.rms_after < 1e-8
    assert result.method == method


def test_several_tests_jointly_share_EI():
    """Tension per test, EI shared: three tests, exact data."""
    campaign, picked = synthetic("bare", 0.97, 1.21, tensions=(0.9e6, 1.2e6, 1.5e6), n_modes=6)
    result = identify(campaign, None, "tension,EI", picked=picked)
    assert result.names == ["tension_ratio[T1]", "tension_ratio[T2]", "tension_ratio[T3]", "EI_ratio"]
    assert_recovers(result, [0.97, 0.97, 0.97, 1.21])
    summary = result.summary()
    assert set(summary["parameters"]["tension_ratio"]) == {"T1", "T2", "T3"}
    assert summary["values"]["EI"] == pytest.approx(1.21 * CABLE.EI, rel=EXACT_RTOL)


def test_mirror_image_reported_as_alternative():
    """A single mass on a symmetric cable: x and l − x give the same frequencies;
    the one nearest the recorded position is reported, the other noted."""
    campaign, picked = synthetic("one", positions=[7.31])
    result = identify(campaign, ["T1"], "position", picked=picked)
    assert_recovers(result, [7.31 / 7.0])
    (mirror,) = result.alternatives
    assert mirror[0] * 7.0 == pytest.approx(CABLE.length - 7.31, rel=1e-6)
    assert any(n.kind == "equally_well" and "equally well" in str(n) for n in result.notes)


def test_mirror_tie_goes_to_end_As_half():
    """Recorded at midspan, truly at 10.5 m: 10.5 and l − 10.5 are equally near the
    record; the one in [0, l/2] is reported (docs/formats.md, identify's alternatives)."""
    campaign, picked = synthetic("mid", positions=[10.5])
    result = identify(campaign, ["T1"], "position", picked=picked)
    assert result.values[0] == pytest.approx(CABLE.length - 10.5, rel=1e-6)
    assert result.alternatives[0][0] * CABLE.length / 2 == pytest.approx(10.5, rel=1e-6)


def test_covariance_is_not_scaled_for_consistent_data():
    campaign, picked = synthetic("bare", 1.02, 0.9)
    result = identify(campaign, ["T1"], "tension,EI", picked=picked, tolerances=False)
    assert result.covariance_scale == 1.0
    assert result.chi2 < 1e-10
    # one standard deviation from the Jacobian: a tension to ~1e-4 with 5 mHz on 8 modes
    assert 1e-5 < result.uncertainty[0] < 1e-3
    # with the default tolerances of the length (0.2 %) and the mass per length (1 %) held fixed: H ∝ m l², so at
    # least √(0.4² + 1²) % on the tension ratio
    with_tolerances = identify(campaign, ["T1"], "tension,EI", picked=picked)
    assert with_tolerances.covariance_scale == 1.0
    floor = math.hypot(2 * 0.002, 0.01)
    assert floor <= with_tolerances.uncertainty[0] < floor + 1e-3
    assert -1 < result.correlation[0, 1] < 0  # more tension or more EI both raise the frequencies


def test_parameter_names_aliases_and_members():
    campaign, _ = synthetic("two")
    tests = list(campaign.tests)
    ps = parse_parameters(campaign, tests, "tension, bending_stiffness, attachment_position[W2], mass[W1]")
    assert [p.name for p in ps] == ["tension_ratio[T1]", "EI_ratio", "position_ratio[W2]", "mass_ratio[W1]"]
    assert ps[2].nominal == 13.0 and ps[2].index == 1
    ends = parse_parameters(campaign, tests, "end_stiffness")
    assert [p.name for p in ends] == ["end_fixity[AB]"] and ends[0].start == 1.0  # clamped
    ab = parse_parameters(campaign, tests, "end_stiffness[A],end_stiffness[B],length,EI_ratio")
    assert [p.name for p in ab] == ["end_fixity[A]", "end_fixity[B]", "length_ratio", "EI_ratio"]


def _end_and_length_campaign(fixity_a, length_ratio):
    k_a = math.inf if fixity_a == 1 else math.sqrt(CABLE.EI * TENSION) * fixity_a / (1 - fixity_a)
    f = batch_frequencies(CABLE, [], TENSION, N_MODES, end_a=k_a, length=CABLE.length * length_ratio)
    test = Test("T1", "bare", TENSION, tuple(f))
    campaign = Campaign("synthetic", CABLE, SETUPS, (test,))
    return campaign, {"T1": Measurement(test, np.arange(1, N_MODES + 1), f, SIGMA, "given")}, k_a


@pytest.mark.parametrize("params, fixity_a, length_ratio, truth", [
    ("end_stiffness[A]", 0.6, 1.0, 0.6),
    ("length", 1.0, 1.01, 1.01),
])
def test_end_stiffness_or_length_identified(params, fixity_a, length_ratio, truth):
    """A softened end A (fixity φ = k/(k + √(EI·H)) = 0.6), or a 1 % longer span, from exact data."""
    campaign, picked, k_a = _end_and_length_campaign(fixity_a, length_ratio)
    result = identify(campaign, ["T1"], params, picked=picked)
    assert_recovers(result, [truth])
    if params.startswith("end"):
        assert result.values[0] == pytest.approx(k_a, rel=1e-6)


def test_end_stiffness_and_length_are_not_separately_identifiable():
    """A softer end acts like a longer span: correlated beyond 0.995, and said so."""
    campaign, picked, _ = _end_and_length_campaign(0.6, 1.01)
    with pytest.warns(IdentifiabilityWarning, match=r"end_fixity\[A\].*length_ratio") as record:
        identify(campaign, ["T1"], "end_stiffness[A],length", picked=picked)
    assert set(record[0].message.parameters) == {"end_fixity[A]", "length_ratio"}


def test_tabulated_frequencies_weighted_by_their_rounding():
    test = Test("T1", "bare", TENSION, (7.24, 14.42, 21.77, 29.38, 36.75, 44.4))
    campaign = Campaign("t", CABLE, SETUPS, (test,))
    result = identify(campaign, None, "tension,EI")
    fit = result.test("T1")
    np.testing.assert_allclose(fit.uncertainty, 0.01 / math.sqrt(12))
    assert "0.01 Hz / sqrt 12" in fit.source


def test_picked_spectra_supply_the_weights():
    """Anything with modes, frequencies and uncertainty (spectra) replaces the table."""
    campaign, _ = synthetic("bare", 1.01, 0.95, n_modes=5)

    class Picked:
        modes = (1, 2, 3, 4, 5)
        frequencies = np.array(campaign.tests[0].frequencies)
        uncertainty = np.array([1e-3, 2e-3, 3e-3, 4e-3, 5e-3])

    result = identify(campaign, ["T1"], "tension,EI", picked={"T1": Picked()})
    assert result.test("T1").source == "spectra"
    np.testing.assert_allclose(result.test("T1").uncertainty, Picked.uncertainty)
    assert_recovers(result, [1.01, 0.95])


def test_summary_is_the_interface_json():
    campaign, picked = synthetic("one", 1.02, 0.9, [7.2])
    result = identify(campaign, ["T1"], "tension,EI,position", picked=picked)
    summary = json.loads(json.dumps(result.summary(), allow_nan=False))
    assert summary["method"] == "lsq"
    assert set(summary["parameters"]) == {"tension_ratio", "EI_ratio", "position_ratio"}
    assert set(summary["uncertainty"]) == set(summary["parameters"])
    assert summary["values"]["position"]["W1"] == pytest.approx(7.2, rel=1e-6)
    (t,) = summary["tests"]
    for key in ("name", "modes", "measured", "before", "after", "before_error", "after_error"):
        assert key in t
    assert len(t["after"]) == len(t["modes"]) == N_MODES
    assert summary["correlation"]["parameters"] == result.names


def test_tables_in_the_papers_form(tmp_path):
    from stcs_ident.report.identify_tables import format_result, parameters_table, write_csv

    campaign, picked = synthetic("bare", 1.02, 0.9, tensions=(1.0e6, 1.2e6), n_modes=6)
    result = identify(campaign, None, "tension,EI", picked=picked)
    df = result.to_dataframe()
    assert list(df.columns[:7]) == ["test", "mode", "measured_Hz", "before_Hz", "before_error_abs_percent",
                                    "corrected_Hz", "corrected_error_abs_percent"]
    assert len(df) == 12 and (df["before_error_abs_percent"] >= 0).all()
    np.testing.assert_allclose(df["corrected_error_abs_percent"], 0, atol=1e-8)
    md = format_result(result, "markdown")
    assert "| mode | measured (Hz) | before (Hz) | \\|δ\\| (%) |" in md  # pipes escaped inside cells
    assert "#### T2" in md
    text = format_result(result, "text")
    assert "tension_ratio[T1]" in text and "|δ*| (%)" in text
    path = tmp_path / "table.csv"
    write_csv(result, path)
    assert path.read_text().splitlines()[0].startswith("test,mode,measured_Hz")
    assert list(parameters_table(result)["parameter"]) == result.names


def test_corrected_campaign_carries_the_estimates():
    campaign, picked = synthetic("one", 1.02, 0.9, [7.2])
    result = identify(campaign, ["T1"], "tension,EI,position", picked=picked)
    fixed = corrected_campaign(campaign, result)
    assert fixed.test("T1").tension == pytest.approx(1.02 * TENSION, rel=1e-6)
    assert fixed.cable.EI == pytest.approx(0.9 * CABLE.EI, rel=1e-6)
    assert fixed.setup("one").attachments[0].position == pytest.approx(7.2, rel=1e-6)


def test_massless_attachment_position_is_not_identifiable():
    campaign, picked = synthetic("sensor", 1.02)
    with pytest.warns(IdentifiabilityWarning, match=r"position_ratio\[S1\]") as record:
        result = identify(campaign, ["T1"], "tension,position", picked=picked)
    assert record[0].message.parameters == ("position_ratio[S1]",)
    assert any("does not change any measured frequency" in str(n) for n in result.notes)
    assert math.isinf(result.uncertainty[1])


def test_tension_and_length_are_not_separately_identifiable():
    """f ≈ (n/2l)√(H/m): tension and length enter almost only as H/l²."""
    campaign, picked = synthetic("bare", 1.02)
    with pytest.warns(IdentifiabilityWarning, match=r"tension_ratio\[T1\].*length_ratio"):
        identify(campaign, ["T1"], "tension,length", picked=picked)


# ---------------------------------------------------------------- bad input


def _field_of(excinfo):
    return excinfo.value.field


def test_unknown_parameter_name():
    campaign, picked = synthetic()
    with pytest.raises(InputError, match="unknown parameter 'stiffnes'") as exc:
        identify(campaign, ["T1"], "tension,stiffnes", picked=picked)
    assert _field_of(exc) == "params"


def test_attachment_that_does_not_exist():
    campaign, picked = synthetic("one")
    with pytest.raises(InputError, match="no attachment 'W9'") as exc:
        identify(campaign, ["T1"], "position[W9]", picked=picked)
    assert _field_of(exc) == "params"


def test_fewer_measured_modes_than_free_parameters():
    campaign, picked = synthetic("two", n_modes=3)
    with pytest.raises(InputError, match="4 free parameters .* but only 3 measured frequencies") as exc:
        identify(campaign, ["T1"], "tension,EI,position", picked=picked)
    assert _field_of(exc) == "params"


def test_bounds_that_exclude_the_nominal():
    campaign, picked = synthetic()
    with pytest.raises(InputError, match=r"bounds \[1.1, 2\] exclude the nominal value 1") as exc:
        identify(campaign, ["T1"], "tension,EI", picked=picked, bounds={"EI": (1.1, 2.0)})
    assert _field_of(exc) == "bounds.EI_ratio"
    with pytest.raises(InputError, match="lower < upper") as exc:
        identify(campaign, ["T1"], "tension,EI", picked=picked, bounds={"tension[T1]": (1.2, 0.8)})
    assert _field_of(exc) == "bounds.tension_ratio[T1]"


def test_selected_test_without_frequencies_or_record():
    campaign, _ = synthetic()
    bare = Test("T0", "bare", TENSION)
    campaign = Campaign("c", CABLE, SETUPS, (bare, *campaign.tests))
    with pytest.raises(InputError, match="neither measured frequencies nor a record") as exc:
        identify(campaign, ["T0", "T1"], "tension,EI")
    assert _field_of(exc) == "test[T0].frequencies"
    # not selected by name: skipped and said so
    result = identify(campaign, None, "tension,EI")
    assert result.skipped == (("T0", "no measured frequencies and no record"),)
    assert any("skipped" in str(n) and "T0" in str(n) for n in result.notes)


def test_unknown_test_and_method():
    campaign, picked = synthetic()
    with pytest.raises(InputError, match="no test named 'T9'") as exc:
        identify(campaign, ["T9"], "tension,EI")
    assert _field_of(exc) == "test"
    with pytest.raises(InputError, match="must be one of lsq, contour") as exc:
        identify(campaign, ["T1"], "tension,EI", method="grid", picked=picked)
    assert _field_of(exc) == "method"


def test_contour_needs_exactly_two_parameters():
    campaign, picked = synthetic("one")
    with pytest.raises(InputError, match="exactly two parameters, got 3") as exc:
        identify(campaign, ["T1"], "tension,EI,position", method="contour", picked=picked)
    assert _field_of(exc) == "params"


def test_a_recorded_position_far_from_its_record_is_found_despite_stated_tensions_off():
    """A 50 kg damper recorded at 3 m of a 120 m stay sits at 12.6 m; two tests' stated tensions are 0.15 %
    and 1.5 % off. The scan's candidate positions are ranked after each test's best frequency factor:
    ranked with the stated tensions, the misfit on every mode drowned what the position changes, and the
    fit ended at a local minimum at 2.7 m (χ² 3578 for 30 frequencies)."""
    cable = Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=math.radians(30))
    setup = Setup("S", (Attachment("damper", 3.0, 50.0),))
    tests, picked = [], {}
    for i, (tension, off) in enumerate([(4.0e6, 0.0015), (4.6e6, -0.015)]):
        f = batch_frequencies(cable, setup.attachments, tension, 15, positions=[12.6])
        test = Test(f"T{i + 1}", "S", tension * (1 + off), tuple(f))
        tests.append(test)
        picked[test.name] = Measurement(test, np.arange(1, 16), f, np.full(15, 0.002), "given")
    result = identify(Campaign("stay", cable, (setup,), tuple(tests)), ["T1", "T2"], "tension,position",
                      picked=picked)
    # exact data: the fit's own tolerance, not noise
    np.testing.assert_allclose(result.values, [4.0e6, 4.6e6, 12.6], rtol=1e-6)


def test_a_column_without_effect_is_judged_per_relative_change_whatever_its_unit():
    """A stiffness in N/m changes the frequencies by 1e-5 of a σ per unit, a tension ratio by 1e5: by the
    columns alone the stiffness looked dead and lost its σ (a 100 kN/m support fitted exactly was reported
    without one). Per relative change of each variable (column × typical size) both matter."""
    from stcs_ident.identify.uncertainty import covariance

    rng = np.random.default_rng(3)
    J = rng.normal(size=(12, 2)) * np.array([1e5, 1e-6])
    cov, _ = covariance(J)
    assert np.isinf(cov[1, 1])  # without the sizes: judged by the raw column
    cov, _ = covariance(J, typical=np.array([1.0, 1e5]))
    assert np.all(np.isfinite(np.diag(cov)))
    np.testing.assert_allclose(np.diag(cov), np.diag(np.linalg.inv(J.T @ J)), rtol=1e-8)
    # A column dead at its size (a massless attachment's position: 8e-9 of a real one) stays dead.
    J[:, 1] = 8e-9 * rng.normal(size=12) * 1e5
    cov, _ = covariance(J, typical=np.array([1.0, 1.0]))
    assert np.isinf(cov[1, 1])
