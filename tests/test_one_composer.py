"""One composer: each command's JSON is its step's ``summary()``, written by the command line's ``to_json``.

The command line adds nothing and leaves nothing out: the same inputs through the API give the same JSON
(keys and values), but for the wall-clock times (``seconds``), which no two runs share.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import stcs_ident as si
from stcs_ident.cli.common import to_json
from stcs_ident.cli.main import main
from stcs_ident.identify.quick_record import pick_unnumbered, unnumbered_summary
from stcs_ident.io.records.validation import UnknownPositions
from stcs_ident.io.test_record import RecordReading, open_record
from stcs_ident.spectra.pipeline import campaign_summary

ROOT = Path(__file__).resolve().parents[1]
HAN = ROOT / "campaigns" / "han2020"
HIDDEN = ROOT / "campaigns" / "hanger-hidden-mass"
TIMES = {"seconds", "elapsed"}


def _untimed(value):
    if isinstance(value, dict):
        return {k: _untimed(v) for k, v in value.items() if k not in TIMES}
    if isinstance(value, list):
        return [_untimed(v) for v in value]
    return value


def _cli_json(tmp_path, argv) -> dict:
    out = tmp_path / "out.json"
    assert main([*argv, "--json", str(out)]) == 0
    return _untimed(json.loads(out.read_text(encoding="utf-8")))


def _api_json(summary: dict) -> dict:
    return _untimed(json.loads(to_json(summary)))


def test_forward(tmp_path):
    api = si.compare_forward(si.load_campaign(HAN), ["case1-L4"]).summary()
    assert _cli_json(tmp_path, ["forward", str(HAN), "--test", "case1-L4"]) == _api_json(api)


def test_identify_carries_its_published_comparison(tmp_path):
    api = si.identify(si.load_campaign(HAN), ["case1-L4", "case1-L5"]).summary()
    assert api["published"]  # han2020 publishes an EI: the API's result holds the comparison, not the CLI
    assert _cli_json(tmp_path, ["identify", str(HAN), "--test", "case1-L4", "--test", "case1-L5"]) == _api_json(api)


def test_diagnose(tmp_path):
    api = si.diagnose(si.load_campaign(HAN), ["case1-L4"], effects="tension,bending_stiffness",
                      max_effects=1).summary()
    cli = _cli_json(tmp_path, ["diagnose", str(HAN), "--test", "case1-L4", "--effects", "tension,bending_stiffness",
                               "--max-effects", "1"])
    assert cli == _api_json(api)


def test_tension_from_frequencies(tmp_path):
    api = si.quick_tension(42.5, 52.1, [2.91, 5.83, 8.76], uncertainty=0.01 / 12**0.5,
                           uncertainty_source="rounding of the printed frequencies (0.01 Hz / sqrt 12)").summary()
    cli = _cli_json(tmp_path, ["tension", "--length", "42.5", "--mass", "52.1", "--frequencies", "2.91,5.83,8.76"])
    assert cli == _api_json(api)


def test_tension_and_spectra_of_a_record(tmp_path):
    record = HIDDEN / "records" / "T1.h5"
    api = si.tension_from_record(record, 8.0, 30.0, EI=2.0e5).summary()
    cli = _cli_json(tmp_path, ["tension", "--record", str(record), "--length", "8", "--mass", "30", "--EI", "2e5"])
    assert cli == _api_json(api)
    opened = open_record(str(record), RecordReading(positions=UnknownPositions()))  # as ``spectra FILE`` reads it
    api = unnumbered_summary(str(record), opened, pick_unnumbered(opened))
    assert _cli_json(tmp_path, ["spectra", str(record)]) == _api_json(api)


@pytest.mark.slow
def test_spectra_of_a_campaign(tmp_path):
    campaign = si.load_campaign(HIDDEN)
    api = campaign_summary(campaign.name, si.analyse_campaign(campaign), [])
    assert _cli_json(tmp_path, ["spectra", str(HIDDEN)]) == _api_json(api)


def test_track(tmp_path):
    from stcs_ident.simulate.archive import ArchiveOptions, simulate_archive
    from tests.test_track import _campaign

    simulate_archive({"C1": _campaign(tmp_path / "campaign")}, tmp_path / "archive",
                     options=ArchiveOptions(days=0.25, interval=1800), seed=5)
    cli = _cli_json(tmp_path, ["track", str(tmp_path / "archive"), "--out", str(tmp_path / "out-cli"), "--workers", "1"])
    api = _api_json(si.track(tmp_path / "archive", tmp_path / "out-api", workers=1).summary())
    # the one difference: where each run was told to write
    assert json.loads(json.dumps(cli).replace(str(tmp_path / "out-cli"), "OUT")) == \
        json.loads(json.dumps(api).replace(str(tmp_path / "out-api"), "OUT"))
