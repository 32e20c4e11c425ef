"""Results of one shape, and the package's face.

Every step's result (forward, peaks, spectra, identify, diagnose, track) is a
:class:`~stcs_ident.core.result.Result`: settings, notes, ``summary()`` (plain
JSON data), ``tables()`` (named DataFrames), ``to_dataframe()``, a short
``repr`` and an HTML table for notebooks. ``import stcs_ident`` loads no
numerical library and exports the objects and the steps lazily.
"""

from __future__ import annotations

import json
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
