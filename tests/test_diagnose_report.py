"""The diagnosis report directory: report.md, the CSV tables and the PNG figures, written whole or not at all."""

from __future__ import annotations

import stat
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from stcs_ident.cli.main import main
from stcs_ident.core.errors import InputError
from stcs_ident.core.files import umask
from stcs_ident.core.model import Cable, Campaign, Setup, Test
from stcs_ident.diagnose import diagnose
from stcs_ident.diagnose.profile import cause_profile
from stcs_ident.forward import natural_frequencies
from stcs_ident.io.campaign import load_campaign
from stcs_ident.report import diagnose_figures as diagnosis_figures
from stcs_ident.report.diagnose import CSV_FILES, write_report
from tests.profile_marks import assert_marks_on_curves

ROOT = Path(__file__).resolve().parents[1]
HAN = ROOT / "campaigns" / "han2020"
#: Every measured test of han2020 (36 frequencies). With case 1 alone (12) no single effect beats the nominal
#: model once the ranking includes the model error these tables need; with all six, an unmodeled mass does.
HAN_TESTS = ["case1-L4", "case1-L5", "case2-L4", "case2-L5", "case3-L4", "case3-L5"]
PNG = b"\x89PNG\r\n\x1a\n"
#: Values written to CSV with pandas' default float format come back to the last bit.
EXACT = {"rtol": 1e-12, "atol": 0.0}

# A taut bare strand (f1 ≈ 3 Hz) for the simulated campaign with records.
CABLE = Cable(length=20.0, mass_per_length=10.0, EI=2000.0)
TENSION = 10.0 * (2 * 20.0 * 3.0) ** 2

pytestmark = pytest.mark.xdist_group("diagnose_report")  # with -n, on one worker: its module fixtures are made once


@pytest.fixture(scope="module")
def han_diagnosis():
    # The unmodeled mass alone stops at its largest mass (the cable's 327 kg: a failed hypothesis, no cause);
    # with a support beside it, both are sized well inside their bounds: 3.8 kg at 5.1 m, 52 kN/m at 3.2 m.
    return diagnose(load_campaign(HAN), HAN_TESTS, effects=["unmodeled_mass", "unmodeled_support"], max_effects=2)


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """A campaign with records whose true cable carries a 15 kg mass at 6 m: (diagnosis, spectra)."""
    pytest.importorskip("h5py")
    from stcs_ident.simulate.effects import Effects
    from stcs_ident.simulate.simulate import Impulse
    from stcs_ident.simulate.simulate_campaign import simulate_campaign
    from stcs_ident.spectra.pipeline import analyse_campaign

    nominal = Campaign("sim", CABLE, (Setup("bare"),),
                       (Test("T1", "bare", TENSION), Test("T2/b", "bare", 1.1 * TENSION)))
    out = simulate_campaign(nominal, tmp_path_factory.mktemp("sim") / "campaign", positions=[3.1, 7.3],
                            duration=60.0, sampling_rate=50.0, impulses=[Impulse(0.5, 2.74, 20.0)], snr_db=40.0,
                            effects=Effects(extra_mass=(15.0, 6.0)), seed=1)
    campaign = load_campaign(out)
    spectra = analyse_campaign(campaign)
    d = diagnose(campaign, picked={s.name: s for s in spectra}, max_effects=1,
                 effects=["tension", "bending_stiffness", "unmodeled_mass"])
    return d, spectra


def _is_png(path: Path) -> bool:
    return path.read_bytes()[:8] == PNG


def _listing(directory: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(directory.iterdir())}


def test_report_holds_the_cause_the_gain_and_the_tables(tmp_path, han_diagnosis):
    d = han_diagnosis
    out = write_report(d, tmp_path / "report")
    assert out == tmp_path / "report"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]  # no temporary left behind
    files = {p.name for p in out.iterdir()}
    assert files == {"report.md", "residuals.png", "profile.png", *CSV_FILES}
    mode = 0o666 & ~umask()  # every file, figures included, as a plain open() would make it
    assert {p.name: stat.S_IMODE(p.stat().st_mode) for p in out.iterdir()} == dict.fromkeys(files, mode)

    text = (out / "report.md").read_text(encoding="utf-8")
    assert text.count(d.cause_text()) == 1  # said once: the named cause's section does not repeat it
    assert "The nominal χ² is 2.462e+05: rejected." in text  # the selection's gate, said in the ranking's key
    assert d.settings.max_effects == 2 and d.summary()["settings"]["tension_model"] == "uniform"
    g = d.summary()["gain"]
    for key in ("rms_error_nominal", "rms_error_baseline", "rms_error_corrected", "cv_rms_error_corrected"):
        assert f"{g[key]:.3f} %" in text
    assert "Model error dominates the measurement uncertainty" in text  # table rounding vs a 0.3 % model error
    assert "How to read this" in text and "99.9 % quantile" in text
    for png in ("residuals.png", "profile.png"):
        assert f"]({png})" in text and _is_png(out / png)

    ranking = pd.read_csv(out / "ranking.csv")
    assert len(ranking) == len(d.fits) and ranking["rank"].tolist() == list(range(1, len(d.fits) + 1))
    # table rounding against a model error of a few 0.1 %: every hypothesis carries its ε, the best the smallest
    fitted = ranking["effects"] != "unmodeled_mass"  # the failed hypothesis has no ε
    assert d.selection.model_error and (ranking.loc[fitted, "relative_model_error"] > 1e-3).all()
    assert ranking["relative_model_error"].iloc[0] < ranking.loc[ranking["effects"] == "nominal",
                                                                   "relative_model_error"].iloc[0]
    assert ranking["delta_aicc"].iloc[0] == 0.0 and ranking["delta_aicc"].dropna().is_monotonic_increasing
    failed = ranking["failure"].fillna("") != ""  # a failed fit: its reason, no figures (not χ² inf, ε 0)
    assert ranking.loc[failed, "effects"].tolist() == ["unmodeled_mass"]
    assert ranking.loc[failed, ["chi2", "relative_model_error", "delta_aicc"]].isna().all(axis=None)
    assert "stopped at a bound" in ranking.loc[failed, "failure"].iloc[0]
    assert "| inf |" not in text and "- unmodeled_mass: the fit stopped at a bound" in text
    assert ranking.loc[ranking["cause"], "effects"].tolist() == ["unmodeled_mass + unmodeled_support"]
    failed = ranking.loc[~fitted]
    assert len(failed) == 1 and not failed["cause"].iloc[0]  # at its bound: failed, never the cause

    freq = pd.read_csv(out / "frequencies.csv")
    assert len(freq) == 36 and freq["test"].unique().tolist() == HAN_TESTS
    np.testing.assert_allclose(freq["measured_Hz"], d.measured, **EXACT)
    np.testing.assert_allclose(freq["corrected_Hz"], d.corrected.predicted, **EXACT)
    np.testing.assert_allclose(freq["baseline_Hz"], d.baseline.predicted, **EXACT)
    np.testing.assert_allclose(freq["nominal_error_percent"],
                               (freq["nominal_Hz"] - freq["measured_Hz"]) / freq["measured_Hz"] * 100, rtol=1e-12)
    assert (freq["uncertainty_Hz"] > 0).all()

    gain = pd.read_csv(out / "gain.csv")
    assert gain["model"].tolist() == ["nominal", "baseline", "corrected"]
    np.testing.assert_allclose(gain["rms_error_percent"], [g["rms_error_nominal"], g["rms_error_baseline"],
                                                     g["rms_error_corrected"]], **EXACT)

    comparison = pd.read_csv(out / "nominal_comparison.csv")
    assert len(comparison) == 36
    np.testing.assert_allclose(comparison["measured_Hz"], d.measured, **EXACT)
    np.testing.assert_allclose(comparison["dsm_Hz"], d.nominal.predicted, rtol=1e-12)  # the same nominal model
    assert {"taut_string_error_percent", "beam_pinned_error_percent", "dsm_error_percent"} <= set(comparison.columns)

    cause = pd.read_csv(out / "cause.csv")
    assert cause.columns.tolist() == ["effect", "role", "parameter", "value", "uncertainty", "unit"]
    assert cause["parameter"].tolist() == ["mass", "position", "stiffness", "position"]
    assert cause["unit"].tolist() == ["kg", "m", "N/m", "m"]
    assert cause["role"].tolist() == ["cause"] * 4
    values, _ = d.parameters(d.corrected)
    np.testing.assert_allclose(cause["value"], [values["unmodeled_mass"]["mass"], values["unmodeled_mass"]["position"],
                                                values["unmodeled_support"]["stiffness"],
                                                values["unmodeled_support"]["position"]], **EXACT)


def test_report_shows_the_spectra_of_tests_with_records(tmp_path, simulated):
    d, spectra = simulated
    out = write_report(d, tmp_path / "report", spectra=spectra)
    text = (out / "report.md").read_text(encoding="utf-8")
    for name, file in (("T1", "spectra_T1.png"), ("T2/b", "spectra_T2_b.png")):  # '/' is no file-name character
        assert _is_png(out / file) and f"![Spectra of {name}]({file})" in text
    assert "record T1.h5" in text
    freq = pd.read_csv(out / "frequencies.csv")
    np.testing.assert_allclose(freq["measured_Hz"], np.concatenate([s.frequencies for s in spectra]), **EXACT)
    comparison = pd.read_csv(out / "nominal_comparison.csv")  # measured = picked, the stated table absent
    np.testing.assert_allclose(comparison["measured_Hz"].dropna(), d.measured, **EXACT)
    cause = pd.read_csv(out / "cause.csv")
    assert cause["effect"].unique().tolist() == ["unmodeled_mass"]
    # the mass was put at 6 m: the profile figure marks it (on a symmetric setup, in [0, l/2])
    assert cause.loc[cause["parameter"] == "position", "value"].item() == pytest.approx(6.0, abs=0.05)
    assert _is_png(out / "profile.png")


def test_the_nominal_model_accepted_names_no_cause(tmp_path):
    # frequencies of the nominal model printed to 0.01 Hz: the misfit is the rounding the uncertainty stands for
    tests = tuple(Test(name, "bare", h, frequencies=tuple(round(float(f), 2)
                                                          for f in natural_frequencies(CABLE, (), h, 6)),
                       modes=(1, 2, 3, 4, 5, 6)) for name, h in (("T1", TENSION), ("T2", 1.2 * TENSION)))
    d = diagnose(Campaign("rounded", CABLE, (Setup("bare"),), tests), max_effects=1, effects=["bending_stiffness"])
    assert d.selection.explained
    out = write_report(d, tmp_path / "report")
    assert not (out / "profile.png").exists() and _is_png(out / "residuals.png")
    assert pd.read_csv(out / "cause.csv").empty
    text = (out / "report.md").read_text(encoding="utf-8")
    assert d.selection.statement in text and "Model error dominates" not in text


def test_an_existing_report_is_replaced_as_a_whole(tmp_path, han_diagnosis):
    out = tmp_path / "report"
    out.mkdir()
    (out / "report.md").write_text("# an older report")
    (out / "stale.csv").write_text("old")
    (out / "sub").mkdir()
    write_report(han_diagnosis, out)
    assert not (out / "stale.csv").exists() and not (out / "sub").exists()
    assert (out / "report.md").read_text(encoding="utf-8").startswith("# Diagnosis of han2020")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]
    empty = tmp_path / "empty"
    empty.mkdir()
    write_report(han_diagnosis, empty)
    assert (empty / "report.md").exists()


def test_a_directory_that_is_not_a_report_is_not_replaced(tmp_path, han_diagnosis):
    out = tmp_path / "data"
    out.mkdir()
    (out / "measurements.csv").write_text("precious")
    with pytest.raises(InputError, match="without report.md") as caught:
        write_report(han_diagnosis, out)
    assert caught.value.field == "out_dir"
    assert _listing(out) == {"measurements.csv": b"precious"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data"]


@pytest.mark.parametrize("existing", [True, False])
def test_a_failure_midway_leaves_the_old_report_and_no_temporary(tmp_path, han_diagnosis, monkeypatch, existing):
    out = tmp_path / "report"
    if existing:
        write_report(han_diagnosis, out)
        before = _listing(out)

    def broken(*args, **kwargs):
        raise RuntimeError("figure failed")

    monkeypatch.setattr(diagnosis_figures, "plot_profile", broken)  # after the CSVs and most figures
    with pytest.raises(RuntimeError, match="figure failed"):
        write_report(han_diagnosis, out)
    if existing:
        assert _listing(out) == before
        assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]
    else:
        assert list(tmp_path.iterdir()) == []


def test_a_file_at_the_output_path_is_refused(tmp_path, han_diagnosis):
    target = tmp_path / "report"
    target.write_text("mine")
    with pytest.raises(InputError, match="not a directory") as caught:
        write_report(han_diagnosis, target)
    assert caught.value.field == "out_dir" and caught.value.file == str(target)
    assert target.read_text() == "mine" and sorted(p.name for p in tmp_path.iterdir()) == ["report"]


def test_figures_return_what_they_drew(han_diagnosis):
    d = han_diagnosis
    drawn = diagnosis_figures.plot_residuals(d)
    assert len(drawn["axes"]) == len(d.measurements)
    assert set(drawn["lines"]) == {"nominal", "baseline", "corrected"}
    first = drawn["lines"]["nominal"][0].get_ydata()
    m = d.measurements[0]
    np.testing.assert_allclose(first, (d.per_test(d.nominal)[0] - m.frequencies) / m.frequencies * 100, rtol=1e-12)
    drawn = diagnosis_figures.plot_profiles(d)
    assert set(drawn["panels"]) == {"unmodeled_mass", "unmodeled_support"} and drawn["unscanned"] == []
    assert_marks_on_curves(d, drawn)
    with pytest.raises(ValueError, match="not an unmodeled attachment"):
        cause_profile(d, "end_restraint")  # not in the cause


def test_cli_writes_the_report(tmp_path, capsys):
    out = tmp_path / "rep"
    argv = ["diagnose", str(HAN), "--test", "case1-L4", "--test", "case1-L5", "--max-effects", "1"]
    assert main([*argv, "--out", str(out)]) == 0
    assert f"report: {out / 'report.md'}" in capsys.readouterr().out
    assert (out / "report.md").exists() and all((out / f).exists() for f in CSV_FILES)
    target = tmp_path / "file"
    target.write_text("mine")
    assert main([*argv, "--out", str(target)]) == 2
    assert "--out" in capsys.readouterr().err and target.read_text() == "mine"


def test_the_principal_effect_the_sentence_and_the_removal_costs_agree(han_diagnosis):
    """han2020: the mass alone stops at its bound (its removal cost is not known), the support alone is fitted:
    the principal is the effect whose removal cost is known and largest, the sentence leads with it, and the
    unknown cost is said with its reason, never as infinite."""
    d = han_diagnosis
    sel = d.selection
    known = {e: c for e, c in sel.removal_cost.items() if e not in sel.removal_unknown}
    assert sel.principal == max(known, key=known.get) == "unmodeled_mass"
    assert sel.removal_unknown == {"unmodeled_support": "unmodeled_mass failed (the fit stopped at a bound)"}
    text = d.cause_text()
    assert text.startswith("An unmodeled mass") and "principal effect: unmodeled_mass" in text
    assert d.summary()["cause"]["removal_cost"]["unmodeled_support"] is None  # not known: null, not inf
    from stcs_ident.report.diagnose import removal_sentence

    sentence = removal_sentence(sel)
    assert "unmodeled_support not known: unmodeled_mass failed" in sentence
    assert sentence.endswith("Principal effect: unmodeled_mass (the largest known).")
    # the ranking's first fitted hypothesis is the one named
    assert d.ranked[0].effects == sel.fitted
