"""Damping where users look (issue 25, point 3).

- ``spectra``: each mode's damping ratio with its 1σ in the text table, the JSON, ``to_dataframe()`` and
  modes.csv, the same numbers everywhere; NaN shown as missing (``-``, ``null``).
- ``diagnose`` of a damped cable: a table per test of the measured ratio ± 1σ, the nominal and the chosen
  model's ratio and z of each, in the text, the report, damping.csv, the JSON and damping.png; the model's
  ratio checked against the complex modes of :func:`~stcs_ident.forward.damped.complex_modes` (−Re s/|s|)
  plus the cable's own ratio computed here. A cable without a damper: no table, no figure.

The records are tests/diagnose_cases.py's (30 dB, one blow), simulated once per run (tests/conftest.py); the
damped hanger's are those of test_diagnose_dampers.py's healthy hanger.
"""

from __future__ import annotations

import json
import math
import re
import warnings
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from stcs_ident.diagnose import diagnose
from stcs_ident.diagnose.tables import damping_table
from stcs_ident.forward.damped import complex_modes
from stcs_ident.identify.problem import DAMPING_SPREAD
from stcs_ident.report.diagnose import CSV_FILES, diagnosis_text, write_report
from stcs_ident.report.diagnose_figures import plot_damping
from stcs_ident.report.spectra_tables import damping_cell, modes_table, spectra_text, write_modes_csv
from tests.test_diagnose_dampers import _campaign

#: The damping table's JSON keys, aligned with the test's modes.
DAMPING_KEYS = {"measured", "uncertainty", "sigma", "nominal", "corrected", "nominal_z", "corrected_z"}


@pytest.fixture
def damped(bench_records):
    """(campaign, spectra by test) of the healthy damped hanger (the damper at mode 1's optimum)."""
    return bench_records("hanger", None, seed=3, nominal=_campaign("hanger", with_damper=True))


def _diagnosis(campaign, picked, effects):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a numbering note of the simulated record is reported, not an error
        return diagnose(campaign, picked=picked, effects=effects, max_effects=1, workers=1)


def _text_rows(text: str, test: str) -> list[str]:
    """The rows of ``test``'s table in the spectra text (from its header line to the first line not a mode's)."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(f"Test {test} ")) + 2
    rows = []
    for line in lines[start:]:
        if not re.match(r"\s*(?:in|out)?\s+\d+[? ] ", line):
            return rows
        rows.append(line)
    return rows


# --- spectra -------------------------------------------------------------------------------------------------

def test_spectra_damping_uncertainty_agrees_across_text_json_dataframe_and_csv(damped, tmp_path):
    _, picked = damped
    results = list(picked.values())
    csv = pd.read_csv(write_modes_csv(results, tmp_path))
    text = spectra_text("c", results, [])
    for r in results:
        frame = r.to_dataframe()
        sigma = np.asarray(r.damping_uncertainty, float)
        assert np.isfinite(sigma).all() and (sigma > 0).all()  # a damped impulse record: every ratio fitted
        assert frame["damping_ratio_uncertainty"].tolist() == sigma.tolist()
        summary = json.loads(json.dumps(r.summary()))
        assert summary["damping_uncertainty"] == sigma.tolist()  # aligned with modes, exact through JSON
        assert len(summary["damping_uncertainty"]) == len(summary["modes"])
        mine = csv[csv["test"] == r.name]
        # the CSV holds the shortest repr of each float, which reads back to the same double
        assert mine["damping_ratio_uncertainty"].tolist() == sigma.tolist()
        assert mine["damping_ratio"].tolist() == r.damping.tolist()
        rows = _text_rows(text, r.name)
        assert len(rows) == len(r.modes)
        for row, z, s in zip(rows, r.damping, sigma):
            value, sig = re.search(r"(\d+\.\d{3}) ± (\d+\.\d{3})", row).groups()
            assert (value, sig) == (f"{100 * z:.3f}", f"{100 * s:.3f}")  # the same numbers, rounded to 1e-5
    assert "damping % ± 1σ" in text


def test_spectra_damping_nan_is_missing_everywhere_and_the_column_stays_aligned(damped, tmp_path):
    _, picked = damped
    r = next(iter(picked.values()))
    zeta = r.damping.copy()
    sigma = np.asarray(r.damping_uncertainty, float).copy()
    zeta[0], sigma[0] = np.nan, np.nan  # no ratio: a mode fitted on its ambient peak
    sigma[1] = np.nan  # a ratio without its 1σ
    r = replace(r, damping=zeta, damping_uncertainty=sigma)
    summary = json.loads(json.dumps(r.summary()))
    assert summary["damping"][0] is None and summary["damping_uncertainty"][:2] == [None, None]
    assert summary["damping_uncertainty"][2:] == sigma[2:].tolist()
    assert np.isnan(r.to_dataframe()["damping_ratio_uncertainty"].to_numpy()[:2]).all()
    rows = _text_rows(spectra_text("c", [r], []), r.name)
    assert rows[0].split()[3] == "-" and "±" not in rows[0]
    assert rows[1].split()[3] == f"{100 * zeta[1]:.3f}" and "±" not in rows[1]
    # the MAC and channels start at one column in every row, the ± at one column where shown
    assert len({row.index(" A1") for row in rows}) == 1
    assert len({row.index("±") for row in rows if "±" in row}) == 1
    assert damping_cell(0.005, 0.0001) == " 0.500 ± 0.010 "
    assert len(damping_cell(0.005, math.nan)) == len(damping_cell(math.nan, math.nan)) == len(damping_cell(0.5, 0.1))
    none = replace(r, damping_uncertainty=None)  # spectra made before the 1σ was kept
    assert none.summary()["damping_uncertainty"] == [None] * len(r.modes)
    assert np.isnan(modes_table([none])["damping_ratio_uncertainty"]).all()


# --- diagnose ------------------------------------------------------------------------------------------------

def test_diagnose_damping_table_against_the_complex_modes(damped, tmp_path):
    campaign, picked = damped
    d = _diagnosis(campaign, picked, ["damper_coefficient"])
    summary = json.loads(json.dumps(d.summary()))
    measured, sigma, model = [], [], []
    for m, entry in zip(d.measurements, summary["tests"]):
        z = entry["damping"]
        assert set(z) == DAMPING_KEYS and all(len(v) == len(entry["modes"]) for v in z.values())
        ts = picked[m.name]
        assert z["measured"] == ts.damping.tolist() and z["uncertainty"] == ts.damping_uncertainty.tolist()
        atts = campaign.setup(m.test.setup).attachments
        modes = complex_modes(campaign.cable, atts, m.test.tension, int(max(entry["modes"])))
        model.append(modes.damping[np.array(entry["modes"]) - 1])  # the dampers' ratios, −Re(s)/|s|
        measured.append(ts.damping)
        sigma.append(np.hypot(ts.damping_uncertainty, DAMPING_SPREAD))
    measured, sigma, model = map(np.concatenate, (measured, sigma, model))
    # the cable's own ratio, one for all modes: the weighted mean of what the dampers leave (≥ 0)
    own = max(0.0, float(np.sum((measured - model) / sigma**2) / np.sum(sigma**-2)))
    assert own > 0.002  # the records' own damping is 0.5 % of critical, partly beside the damper's
    nominal = np.concatenate([e["damping"]["nominal"] for e in summary["tests"]])
    # the fit's complex modes are followed from the undamped roots without the count's certificate; they agree
    # with the certified ones to about 1e-8 in damping ratio (docs/dampers.md), far below any 1σ here (1e-4)
    np.testing.assert_allclose(nominal, model + own, rtol=0, atol=1e-7)
    z = np.concatenate([e["damping"]["nominal_z"] for e in summary["tests"]])
    np.testing.assert_allclose(z, (measured - nominal) / sigma, rtol=1e-12)
    # Σz² is the damping ratios' share of the nominal model's χ² (the rest: the frequencies' terms)
    n = d.measured.size
    assert float(np.sum(z**2)) == pytest.approx(d.nominal.chi2 - float(np.sum(d.nominal.terms[:n])), rel=1e-9)
    corrected = np.concatenate([e["damping"]["corrected"] for e in summary["tests"]])
    assert np.sum(d.corrected.terms[n:]) == pytest.approx(np.sum(((measured - corrected) / sigma) ** 2), rel=1e-9)

    table = damping_table(d)
    assert len(table) == measured.size and table["measured_damping_ratio"].tolist() == measured.tolist()
    text = diagnosis_text(d)
    assert "Damping ratios (%)" in text
    for row in table.itertuples():
        assert (f"{100 * row.measured_damping_ratio:.3f} ± {100 * row.damping_ratio_uncertainty:.3f}      "
                f"{100 * row.nominal_damping_ratio:.3f}  "
                f"{row.nominal_z:+.2f}") in text
    out = write_report(d, tmp_path / "report")
    csv = pd.read_csv(out / "damping.csv")
    assert csv["nominal_z"].tolist() == table["nominal_z"].tolist()  # shortest repr: the same doubles
    report = (out / "report.md").read_text()
    assert "## Damping ratios, measured and modelled" in report and "![Damping ratios per mode](damping.png)" in report
    assert f"| {100 * table['measured_damping_ratio'][0]:.3f} ± {100 * table['damping_ratio_uncertainty'][0]:.3f} |" in report
    assert (out / "damping.png").stat().st_size > 0


def test_the_damping_figure_draws_the_table(damped):
    campaign, picked = damped
    table = damping_table(_diagnosis(campaign, picked, ["damper_coefficient"]))
    drawn = plot_damping(table)
    tests = list(dict.fromkeys(table["test"]))
    assert len(drawn["axes"]) == len(tests)
    for i, test in enumerate(tests):
        rows = table[table["test"] == test]
        points, _caps, (bars,) = drawn["measured"][i].lines
        np.testing.assert_array_equal(points.get_ydata(), 100 * rows["measured_damping_ratio"].to_numpy())
        segments = bars.get_segments()  # one vertical bar per mode: ζ ± 1σ
        np.testing.assert_allclose([s[1, 1] - s[0, 1] for s in segments],
                                   200 * rows["damping_ratio_uncertainty"].to_numpy())
        np.testing.assert_array_equal(drawn["lines"]["nominal"][i].get_ydata(),
                                      100 * rows["nominal_damping_ratio"].to_numpy())


def test_an_undamped_cable_has_no_damping_table_nor_figure(bench_records, tmp_path):
    campaign, picked = bench_records("hanger", None, seed=0)
    assert any(np.isfinite(ts.damping).any() for ts in picked.values())  # ratios measured, but no damper
    d = _diagnosis(campaign, picked, ["tension"])
    summary = d.summary()
    assert all("damping" not in t for t in summary["tests"])
    assert "damping" not in d.tables() and damping_table(d).empty
    assert "Damping ratios" not in diagnosis_text(d)
    out = write_report(d, tmp_path / "report")
    files = {p.name for p in out.iterdir()}
    assert files == {"report.md", "residuals.png", *CSV_FILES, *(f"spectra_{n}.png" for n in picked)}
    assert "amping ratio" not in (out / "report.md").read_text()
