"""Nothing silently wrong: plausibility before fitting, bounds as failures, the bare cable (issue 22, items 3, 4, 6)."""

from __future__ import annotations

import json
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from stcs_ident.cli.main import main
from stcs_ident.core.errors import BoundError, CampaignError, InputError
from stcs_ident.core.model import Cable, Campaign, Setup, Test
from stcs_ident.forward import batch_frequencies
from stcs_ident.identify import identify
from stcs_ident.identify.plausibility import BAND, check_plausibility
from stcs_ident.identify.problem import gather_measurements
from stcs_ident.io.campaign import campaign_to_toml, load_campaign

ROOT = Path(__file__).resolve().parents[1]
HAN = ROOT / "campaigns" / "han2020"
HIDDEN = ROOT / "campaigns" / "hanger-hidden-mass"


def run(argv, capsys):
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exit_:
        code = exit_.code
    out, err = capsys.readouterr()
    return code, out, err


def han_with(tmp_path: Path, *, tension_factor: float = 1.0, mass_factor: float = 1.0) -> Path:
    """han2020 written to ``tmp_path`` with every tension and the mass per length scaled (a unit slip)."""
    text = (HAN / "campaign.toml").read_text()
    text = re.sub(r"^tension = (\S+)", lambda m: f"tension = {float(m.group(1)) * tension_factor!r}", text,
                  flags=re.MULTILINE)
    text = re.sub(r"^mass_per_length = (\S+)", lambda m: f"mass_per_length = {float(m.group(1)) * mass_factor!r}",
                  text, flags=re.MULTILINE)
    out = tmp_path / "slip"
    out.mkdir()
    (out / "campaign.toml").write_text(text)
    return out


# ---- plausibility -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("command", ["identify", "diagnose"])
def test_tension_in_kN_is_refused_with_the_hint(tmp_path, capsys, command):
    campaign = han_with(tmp_path, tension_factor=1e-3)  # 1248.7 for 1.2487 MN
    out_json = tmp_path / "out.json"
    code, out, err = run([command, campaign, "--json", out_json], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and out == ""
    assert "field 'test[" in err and "].tension'" in err
    assert "kN?" in err and "--no-plausibility-check" in err
    assert not out_json.exists()


def test_mass_per_length_in_g_per_m_is_refused_with_the_hint(tmp_path, capsys):
    campaign = han_with(tmp_path, mass_factor=1e3)
    code, out, err = run(["identify", campaign, "--test", "case1-L4"], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and out == ""
    assert "cable.mass_per_length in g/m?" in err


def test_the_override_fits(tmp_path, capsys):
    campaign = han_with(tmp_path, tension_factor=1e-3)
    code, out, _err = run(["identify", campaign, "--test", "case1-L4", "--no-plausibility-check"], capsys)
    # the case: fitted as asked (a tension ratio near 1.9, EI about 8 × nominal), not refused
    assert code == 0 and "Identification (lsq)" in out
    result = identify(load_campaign(campaign), ["case1-L4"], check_plausibility=False)
    assert result.value("EI_ratio")[0] > 2  # what the slip does to a fit nobody stopped


def test_plausibility_api_names_the_field():
    campaign = load_campaign(HAN)
    slipped = replace(campaign, tests=tuple(replace(t, tension=t.tension / 1e3) if t.name == "case2-L5" else t
                                            for t in campaign.tests))
    measurements, _ = gather_measurements(slipped)
    with pytest.raises(InputError) as info:
        check_plausibility(slipped, measurements)
    assert info.value.field == "test[case2-L5].tension"
    assert "1 of" not in info.value.message  # one test off: no count of several
    assert "kN?" in info.value.message
    assert "g/m" not in info.value.message  # the other tests are fine: not the cable's mass


def test_shipped_campaigns_are_not_refused():
    for directory in (HAN, HIDDEN):
        campaign = load_campaign(directory)
        measurements, _ = gather_measurements(campaign)
        check_plausibility(campaign, measurements)  # raises if refused


def test_forward_warns_but_exits_0(tmp_path, capsys):
    code, out, err = run(["forward", han_with(tmp_path, tension_factor=1e-3)], capsys)
    assert code == 0 and "warning" in err and "kN?" in err
    assert "case1-L4" in out  # the comparison is still printed
    code, _out, err = run(["forward", HAN], capsys)
    assert code == 0 and "implausibly" not in err


# ---- bounds are failures: the tube -------------------------------------------------------------------------

TUBE = Cable(length=2.0, mass_per_length=1.0, EI=90.0)  # ξ = l √(T/EI) from 9 (2 kN) to 19 (8 kN)
TRUE_TENSIONS = np.linspace(2000.0, 8000.0, 7)
#: True / stated tension: beyond the default upper bound 2 of a tension ratio.
OFF = 2.5


def tube_campaign(bounds=()) -> Campaign:
    """A tensioned tube, one mode per test (mode 1, noise-free), stated tensions OFF times too low."""
    tests = []
    for i, T in enumerate(TRUE_TENSIONS):
        f1 = float(np.asarray(batch_frequencies(TUBE, (), T, 1)).ravel()[0])
        tests.append(Test(f"T{i + 1}", "tube", T / OFF, (round(f1, 3),), (1,), uncertainty=(0.005,)))
    return Campaign("tube", TUBE, (Setup("tube"),), tuple(tests), bounds=bounds)


def test_tube_nominal_is_outside_the_band():
    campaign = tube_campaign()
    measurements, _ = gather_measurements(campaign)
    assert OFF ** 0.5 > BAND  # the premise: the stated tensions are implausible as well
    with pytest.raises(InputError):
        check_plausibility(campaign, measurements)


def test_tube_fit_at_the_bound_fails_naming_it():
    with pytest.raises(BoundError) as info:
        identify(tube_campaign(), check_plausibility=False)
    result = info.value.result
    assert result.status == "failed"
    assert result.failure.kind == "fit_at_bound" and result.failure.parameters[0].startswith("tension_ratio[")
    assert dict(result.failure.data)["side"] == "upper" and dict(result.failure.data)["bound"] == 2.0
    assert np.all(np.isnan(result.uncertainty))  # never a value with a σ at a bound
    assert len(result.to_dataframe()) == len(TRUE_TENSIONS)  # the before/after table stays printable
    summary = result.summary()
    assert summary["status"] == "failed" and summary["failure"]["side"] == "upper"
    assert all(v is None for v in summary["uncertainty"]["tension_ratio"].values())
    assert any(n.kind == "EI_held" for n in result.notes)  # one mode per test: EI held, said so


def test_tube_cli_exit_1_and_json_says_failed(tmp_path, capsys):
    directory = tmp_path / "tube"
    directory.mkdir()
    (directory / "campaign.toml").write_text(campaign_to_toml(tube_campaign()))
    out_json = tmp_path / "r.json"
    code, out, err = run(["identify", directory, "--no-plausibility-check", "--json", out_json], capsys)
    assert code == 1 and len(err.strip().splitlines()) == 1 and "upper bound" in err
    assert out == ""  # no table of estimates for a failed fit
    data = json.loads(out_json.read_text())
    assert data["status"] == "failed" and data["failure"]["parameter"].startswith("tension_ratio[")
    assert data["failure"]["bound"] == 2.0


def test_tube_with_wider_campaign_bounds_succeeds(tmp_path):
    campaign = tube_campaign(bounds=(("tension", (0.2, 5.0)),))
    directory = tmp_path / "tube"
    directory.mkdir()
    (directory / "campaign.toml").write_text(campaign_to_toml(campaign))
    loaded = load_campaign(directory)
    assert loaded.bounds == (("tension", (0.2, 5.0)),)  # written and read back
    result = identify(loaded, check_plausibility=False)
    assert result.ok and result.summary()["status"] == "ok"
    for name, T in zip((t.name for t in loaded.tests), TRUE_TENSIONS):
        value, sigma = result.value(f"tension[{name}]")
        # the frequencies are rounded to 1 mHz (σ stated 5 mHz): the tension within 3σ, σ from the fit
        assert abs(value - T) <= 3 * sigma + 1e-9 * T
    # the keyword still wins over the campaign's bounds
    with pytest.raises(BoundError):
        identify(loaded, check_plausibility=False, bounds={"tension": (0.5, 2.0)})


@pytest.mark.parametrize("table, field", [
    ("foo = [1.0, 2.0]", "bounds.foo"),
    ("tension = [2.0, 1.0]", "bounds.tension"),
    ("tension = 2.0", "bounds.tension"),
    ("tension = [-1.0, 2.0]", "bounds.tension"),
])
def test_bad_campaign_bounds_are_refused_naming_the_field(tmp_path, table, field):
    text = (HAN / "campaign.toml").read_text() + f"\n[bounds]\n{table}\n"
    (tmp_path / "campaign.toml").write_text(text)
    with pytest.raises(CampaignError) as info:
        load_campaign(tmp_path)
    assert info.value.field == field


# ---- the bare cable ------------------------------------------------------------------------------------------

BARE = Cable(length=20.0, mass_per_length=10.0, EI=0.0)
TRUE_EI = 2000.0  # N m²: ξ = l √(T/EI) ≈ 140 at 100 kN, string-like but measurable with 6 modes at 1 mHz
SIGMA = 0.001  # Hz


def bare_campaign(rng) -> Campaign:
    tests = []
    for i, T in enumerate((1.0e5, 1.5e5)):
        f = np.asarray(batch_frequencies(BARE, (), T, 6, EI=TRUE_EI)).ravel()
        f = f + rng.normal(0.0, SIGMA, f.shape)
        tests.append(Test(f"T{i + 1}", "bare", T, tuple(float(x) for x in f), tuple(range(1, 7)),
                          uncertainty=(SIGMA,) * 6))
    return Campaign("bare", BARE, (Setup("bare"),), tuple(tests))


def test_bare_cable_identify_default_frees_EI_in_N_m2():
    result = identify(bare_campaign(np.random.default_rng(3)))
    assert result.names == ["tension_ratio[T1]", "tension_ratio[T2]", "EI"]
    value, sigma = result.value("EI")
    assert result.parameter_table().set_index("parameter").loc["EI", "unit"] == "N m^2"
    assert abs(value - TRUE_EI) <= 3 * sigma  # seeded noise of the stated size: within 3σ


def test_bare_cable_diagnose_says_EI_is_absolute():
    from stcs_ident.diagnose import diagnose
    from stcs_ident.report.diagnose import diagnosis_text

    d = diagnose(bare_campaign(np.random.default_rng(4)), effects="bending_stiffness", workers=1)
    assert any(n.kind == "EI_absolute" for n in d.notes)
    text = diagnosis_text(d)
    assert "absolute" in text and "baseline (tension, EI)" not in text


@pytest.mark.parametrize("method", ["lsq", "contour"])
def test_both_methods_fail_at_a_campaign_bound(method):
    import warnings

    # han2020's case1-L4 wants EI about 0.5 × nominal: campaign bounds [0.9, 1.1] exclude it
    campaign = replace(load_campaign(HAN), bounds=(("EI", (0.9, 1.1)),))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the fit at the bound also warns that EI is not identifiable there
        with pytest.raises(BoundError) as info:
            identify(campaign, ["case1-L4"], "tension,EI", method=method)
    failure = info.value.result.failure
    assert failure.parameters == ("EI_ratio",) and dict(failure.data)["side"] == "lower"
    assert "EI_ratio = 0.9 is its lower bound" in str(info.value)


def test_a_diagnosis_hypothesis_at_a_bound_failed_and_is_not_the_cause():
    from stcs_ident.diagnose.fitting import fit_hypothesis
    from stcs_ident.identify.bounds import FAILURE_HEAD

    campaign = replace(load_campaign(HAN), bounds=(("EI", (0.9, 1.1)),))
    measurements, _ = gather_measurements(campaign, ["case1-L4"])
    fit = fit_hypothesis(campaign, measurements, ("bending_stiffness",))
    assert fit.failure is not None and fit.failure.startswith(FAILURE_HEAD)
    assert "EI" in fit.failure and "lower bound" in fit.failure
    assert fit.result is None and fit.aicc == float("inf")  # ranked last, never chosen (selection.select)


def test_campaign_bounds_built_in_python_are_checked_too():
    campaign = load_campaign(HAN)
    with pytest.raises(InputError) as info:  # a kind no parameter has
        identify(replace(campaign, bounds=(("tensoin", (0.2, 5.0)),)), ["case1-L4"], "tension,EI")
    assert info.value.field == "bounds.tensoin"
    with pytest.raises(InputError) as info:  # bounds that exclude the nominal value
        identify(replace(campaign, bounds=(("EI", (2.0, 5.0)),)), ["case1-L4"], "tension,EI")
    assert info.value.field == "bounds.EI_ratio"
    with pytest.raises(InputError) as info:  # not increasing: refused when the campaign is built
        replace(campaign, bounds=(("EI", (5.0, 2.0)),))
    assert info.value.field == "bounds.EI"
