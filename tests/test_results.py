"""Results of one shape, and the package's face.

Every step's result (forward, peaks, spectra, identify, diagnose, track) is a
:class:`~stcs_ident.core.result.Result`: settings, notes, ``summary()`` (plain
JSON data), ``tables()`` (named DataFrames), ``to_dataframe()``, a short
``repr`` and an HTML table for notebooks. ``import stcs_ident`` loads no
numerical library and exports the objects and the steps lazily.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import stcs_ident as si
from stcs_ident.core.result import Result
from tests.fuzz_inputs import BASE_TOML, _frequencies

CABLE = si.Cable(length=12.0, mass_per_length=5.0, EI=2.0e3)
TENSION = 2.0e5


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """A two-test campaign whose records hide a 3 kg mass at 4 m: the results of every step on it."""
    from stcs_ident.simulate import Effects, Impulse

    nominal = si.Campaign("shape", CABLE, (si.Setup("bare"),),
                          (si.Test("T1", "bare", TENSION), si.Test("T2", "bare", 1.2 * TENSION)))
    directory = si.simulate_campaign(nominal, tmp_path_factory.mktemp("shape") / "campaign", positions=[3.1, 7.3],
                                     duration=30.0, sampling_rate=100.0, impulses=[Impulse(time=0.5, position=2.2, magnitude=20.0)],
                                     snr_db=40.0, effects=Effects(extra_mass=(3.0, 4.0)), seed=2)
    campaign = si.load_campaign(directory)
    spectra = si.analyse_campaign(campaign)
    picked = {s.name: s for s in spectra}
    return {
        "campaign": campaign,
        "forward": si.compare_forward(campaign, picked={s.name: (s.modes, s.frequencies) for s in spectra}),
        "peaks": spectra[0].peaks,
        "spectra": spectra[0],
        "identify": si.identify(campaign, None, "tension,EI", picked=picked),
        "diagnose": si.diagnose(campaign, picked=picked, max_effects=1, workers=1,
                                effects=["tension", "bending_stiffness", "unmodeled_mass"]),
    }


@pytest.fixture(scope="module")
def tracked(tmp_path_factory):
    """``track`` on an archive of one hanger and four records."""
    from stcs_ident.simulate.archive import ArchiveOptions, simulate_archive

    root = tmp_path_factory.mktemp("tracked")
    (root / "campaign").mkdir()
    (root / "campaign" / "campaign.toml").write_text(
        BASE_TOML.replace('record = "records/T2.h5"\n', "").format(f=_frequencies()), encoding="utf-8")
    campaign = si.load_campaign(root / "campaign")
    simulate_archive({"C1": campaign}, root / "archive", options=ArchiveOptions(days=2 / 24, interval=1800), seed=4)
    return si.track(root / "archive", root / "out")


KINDS = ("forward", "peaks", "spectra", "identify", "diagnose", "track")


@pytest.fixture(params=KINDS)
def result(request, simulated):
    if request.param == "track":
        return request.getfixturevalue("tracked")
    return simulated[request.param]


def test_every_result_has_the_common_shape(result):
    assert isinstance(result, Result)
    assert isinstance(result.notes, tuple)
    result.settings  # noqa: B018 (every result has settings, None where its step has none)
    tables = result.tables()
    assert tables and all(isinstance(k, str) and isinstance(v, pd.DataFrame) for k, v in tables.items())
    assert result.main_table in tables
    assert isinstance(result.to_dataframe(), pd.DataFrame)
    json.dumps(result.summary())  # plain data: no array, no numpy integer


def test_a_repr_is_short_and_says_what_it_is(result):
    text = repr(result)
    lines = text.splitlines()
    assert lines[0].startswith(f"<{type(result).__name__}: ") and lines[0].endswith(">")
    assert len(lines) <= 2 and all(len(line) <= 250 for line in lines), text
    assert "array(" not in text  # not a dataclass dump


def test_the_notebook_shows_the_main_table_under_a_title(result):
    page = result._repr_html_()
    assert page.startswith(f"<p><b>{type(result).__name__}</b>: ")
    assert page.count("<table") == 1
    for column in result.tables()[result.main_table].columns:
        assert f"<th>{column}</th>" in page


def test_the_parameter_table_has_names_values_sigmas_units_and_nominals(simulated):
    result = simulated["identify"]
    table = result.tables()["parameters"]
    assert table["parameter"].tolist() == ["tension_ratio[T1]", "tension_ratio[T2]", "EI_ratio"]
    assert table["unit"].tolist() == ["N", "N", "N m^2"]
    np.testing.assert_array_equal(table["nominal"], [TENSION, 1.2 * TENSION, CABLE.EI])
    for name, by_kind in (("tension_ratio[T2]", "tension[T2]"), ("EI_ratio", "EI")):
        row = table[table["parameter"] == name].iloc[0]
        assert result.value(name) == result.value(by_kind) == (row["value"], row["uncertainty"])
        assert row["value"] == pytest.approx(row["variable"] * row["nominal"], rel=1e-12)  # a ratio to nominal
    with pytest.raises(KeyError, match="2 parameters"):
        result.value("tension")  # one per test: the member must be named
    with pytest.raises(KeyError, match="no parameter 'length'"):
        result.value("length")
    pd.testing.assert_frame_equal(result.tables()["frequencies"], result.to_dataframe())  # Table 9/10 unchanged


def test_the_diagnosis_keeps_the_spectra_it_was_given(simulated):
    d = simulated["diagnose"]
    assert [s.name for s in d.spectra] == ["T1", "T2"]
    assert d.selection.principal == "unmodeled_mass"
    assert set(d.tables()) == {"ranking", "frequencies", "gain", "nominal_comparison", "cause"}


def test_track_returns_a_result_whose_summary_is_the_json(tracked):
    summary = tracked.summary()
    assert set(summary) == {"archive", "cables"} and summary["cables"] == tracked.cables
    cable = summary["cables"]["C1"]
    assert cable["records"] == 4 and cable["processed"] + cable["failed"] == 4
    tables = tracked.tables()
    assert tables["cables"]["cable"].tolist() == ["C1"]
    assert len(tables["records"]) == 4 and tables["events"].columns.tolist()[:2] == ["cable", "start_time"]
    assert tracked.history("C1") is tracked.histories["C1"][1]


def test_import_loads_no_numerical_library():
    code = ("import sys, stcs_ident; "
            "print(sorted(m for m in ('numpy', 'scipy', 'pandas', 'matplotlib', 'h5py') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=Path(__file__).resolve().parents[1]).stdout
    assert out.strip() == "[]"


def test_the_face_exports_every_name_and_the_steps_stay_functions():
    import stcs_ident.diagnose.api
    import stcs_ident.identify.result
    import stcs_ident.track.events  # noqa: F401

    for name in si.__all__:
        assert getattr(si, name) is not None, name
        assert name in dir(si)
    assert si.identify.__module__ == "stcs_ident.identify.api"
    assert si.diagnose.__module__ == "stcs_ident.diagnose.api"
    assert si.track.__module__ == "stcs_ident.track.api"
    from stcs_ident import diagnose, identify, track

    assert callable(identify) and callable(diagnose) and callable(track)
    assert issubclass(si.CampaignError, si.InputError) and issubclass(si.InputError, ValueError)
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        si.nothing  # noqa: B018


# -- the columns of every table: a unit in each name, lists written alike ----------------------------------------

#: Columns that have no unit, each named for what it is: names, labels and flags; counts (``n_``); statistics of a
#: fit (χ², AICc, the prior's penalty, the MAC), which are numbers without a unit.
UNITLESS = {"test", "setup", "mode", "plane", "cable", "record", "record_id", "record_kind", "parameter", "kind",
            "member", "unit", "note", "method", "label", "tests", "reproduced", "worst_mode", "doubtful", "channels",
            "mac", "status", "reason", "failure", "modes", "planes", "version", "start_time", "alarm_time", "coefficient_reason",
            "state", "damper_state", "effects", "effect", "role", "rank", "cause", "parameters", "model", "source",
            "chi2", "reduced_chi2", "aicc", "delta_aicc", "prior_penalty", "relative_model_error", "n_modes",
            "n_parameters", "n_records", "n_processed", "n_failed", "n_events", "damper_n_events"}
#: Columns of a long table, whose ``unit`` column gives each row's unit.
LONG = {"value", "uncertainty", "nominal", "variable", "variable_uncertainty"}
#: The units a name may end with (SI; ``_ratio`` and ``_percent`` say a dimensionless number is a ratio or in %,
#: ``_z`` a normalised residual, ``_db`` decibels).
SUFFIXES = ("_Hz", "_N", "_m", "_kg", "_Nm2", "_Ns_per_m", "_m_per_s2", "_s", "_ns", "_bytes", "_degC", "_per_degC",
            "_ratio", "_ratio_uncertainty", "_ratio_sigma", "_percent", "_z", "_db")
#: A numpy array's repr in a cell: "[" then a value (a number, True/False, a quoted string) and a space.
NUMPY_REPR = re.compile(r"\[(?:True|False|-?\d[\d.e+-]*|'[^']*')\s")


def unit_problems(name: str, frame: pd.DataFrame) -> list[str]:
    """What is wrong with the columns of ``frame`` (the table called ``name``): no unit, or a numpy repr."""
    problems = []
    for column in frame.columns:
        base = re.sub(r"\[[^\]]*\]$", "", str(column))  # a per-channel column: amplitude_m_per_s2[A1]
        if not (base in UNITLESS or base.endswith(SUFFIXES) or (base in LONG and "unit" in frame.columns)):
            problems.append(f"{name}: column {column!r} has no unit")
        for cell in frame[column]:
            if isinstance(cell, str) and NUMPY_REPR.search(cell):
                problems.append(f"{name}: column {column!r} holds a numpy repr: {cell!r}")
    return problems


def test_unit_problems_finds_a_name_without_its_unit_and_a_numpy_repr():
    frame = pd.DataFrame({"frequency": [1.0], "doubtful": [str(np.array([False, True]))],
                          "frequency_Hz": [1.0], "parameters": ["ratio[T1] = 0.98"], "value": [2.0]})
    assert unit_problems("t", frame) == ["t: column 'frequency' has no unit",
                                         "t: column 'doubtful' holds a numpy repr: '[False  True]'",
                                         "t: column 'value' has no unit"]  # a long table's value needs its unit column
    assert unit_problems("t", frame.assign(unit="N").drop(columns=["frequency", "doubtful"])) == []


def test_every_column_of_every_table_carries_its_unit(result):
    problems = [p for name, frame in result.tables().items() for p in unit_problems(name, frame)]
    assert problems == []


def test_every_csv_file_carries_its_units_and_writes_lists_joined(simulated, tracked, tmp_path):
    from stcs_ident.report.diagnose import write_report as diagnosis_report
    from stcs_ident.report.identify_tables import write_tables
    from stcs_ident.report.spectra_tables import write_modes_csv
    from stcs_ident.report.track import write_report as track_report

    diagnosis_report(simulated["diagnose"], tmp_path / "diagnose")
    write_tables(simulated["identify"], tmp_path / "identify")
    write_modes_csv([simulated["spectra"]], tmp_path)
    (tmp_path / "track").mkdir()
    track_report(tracked, tmp_path / "track")
    written = sorted(tmp_path.rglob("*.csv"))
    assert {p.name for p in written} >= {"ranking.csv", "frequencies.csv", "gain.csv", "nominal_comparison.csv",
                                         "cause.csv", "parameters.csv", "modes.csv", "records.csv", "cables.csv",
                                         "events.csv"}
    problems = [p for path in written for p in unit_problems(str(path.relative_to(tmp_path)), pd.read_csv(path))]
    assert problems == []
    records = pd.read_csv(tmp_path / "track" / "records.csv")
    for column in ("modes", "planes", "frequencies_Hz", "frequency_sigma_Hz", "doubtful", "damping_ratio"):
        cells = [str(c).split(";") for c in records[column]]
        assert [len(c) for c in cells] == tracked.table["n_modes"].tolist(), column
    assert {f for c in records["doubtful"] for f in c.split(";")} <= {"True", "False"}
    back = [[float(f) for f in c.split(";")] for c in records["frequencies_Hz"]]
    assert back == [list(fs) for fs in tracked.table["frequencies_Hz"]]  # shortest repr: the same doubles
    modes = pd.read_csv(tmp_path / "modes.csv")
    assert modes["channels"].tolist() == [";".join(c) for c in simulated["spectra"].channels]


def test_the_tables_of_the_quick_tension_a_damper_and_references_carry_their_units(simulated):
    from stcs_ident.diagnose.tables import DAMPING_COLUMNS
    from stcs_ident.track.result import CABLE_COLUMNS, DAMPER_CABLE_COLUMNS, EVENT_COLUMNS
    from stcs_ident.track.store import ROW_COLUMNS

    campaign = simulated["campaign"]
    quick = si.quick_tension(CABLE.length, CABLE.mass_per_length, [8.1, 16.3, 24.6], EI=CABLE.EI)
    record = si.tension_from_record(Path(campaign.directory) / campaign.tests[0].record, CABLE.length,
                                    CABLE.mass_per_length, EI=CABLE.EI)
    damped = si.Campaign("damped", CABLE, (si.Setup("d", (si.Damper("D", 0.5, coefficient=2e3),)),),
                         (si.Test("T", "d", TENSION, frequencies=(8.1, 16.3), reference=(("paper", (8.0, 16.2)),)),))
    forward = si.compare_forward(damped)
    assert {"dsm_damping_ratio", "paper_Hz", "measured_Hz", "dsm_error_percent"} <= set(forward.to_dataframe())
    constants = {"damping": DAMPING_COLUMNS, "events": EVENT_COLUMNS, "cables": CABLE_COLUMNS + DAMPER_CABLE_COLUMNS,
                 "records.parquet": ROW_COLUMNS}
    tables = {**{f"quick {k}": v for k, v in quick.tables().items()},
              **{f"record {k}": v for k, v in record.tables().items()},
              **{f"forward {k}": v for k, v in forward.tables().items()},
              **{k: pd.DataFrame(columns=list(v)) for k, v in constants.items()}}
    assert len(tables["record peaks"]) > 0 and len(tables["forward reference_checks"]) == 1
    assert [p for name, frame in tables.items() for p in unit_problems(name, frame)] == []
