"""[[setup.damper]] in campaign.toml (issue 13): read, refused with the field named, written back, and
``forward`` reporting the damping ratio per mode."""

from __future__ import annotations

import json
import math

import pytest

from stcs_ident.cli.main import main
from stcs_ident.core.errors import CampaignError
from stcs_ident.core.model import Damper
from stcs_ident.io.campaign import campaign_to_toml, load_campaign
from tests.test_campaign_io import assert_one_line_naming, edited, write_campaign

D1 = """
  [[setup.damper]]
  name = "D1"
  position = 0.4
  coefficient = 2.0e4
"""
LOADED = "  mass = 8.3\n"


def _with(text: str) -> str:
    return edited(LOADED, LOADED + text)


def test_a_damper_is_read_among_the_attachments(tmp_path):
    campaign = load_campaign(write_campaign(tmp_path, _with(D1 + "  stiffness = 5.0e3\n  mass = 2.5\n")))
    setup = campaign.setup("loaded")
    assert [a.name for a in setup.attachments] == ["D1", "W1"]  # ordered by position
    damper = setup.attachments[0]
    assert isinstance(damper, Damper)
    assert (damper.position, damper.coefficient, damper.stiffness, damper.mass) == (0.4, 2.0e4, 5.0e3, 2.5)


def test_a_damper_round_trips_through_the_writer(tmp_path):
    campaign = load_campaign(write_campaign(tmp_path / "a", _with(D1)))
    again = load_campaign(write_campaign(tmp_path / "b", campaign_to_toml(campaign)))
    assert again.setups == campaign.setups


BAD = {
    "coefficient missing": (D1.replace("  coefficient = 2.0e4\n", ""), "setup[loaded].damper[D1].coefficient"),
    "coefficient zero": (D1.replace("2.0e4", "0.0"), "setup[loaded].damper[D1].coefficient"),
    "coefficient negative": (D1.replace("2.0e4", "-3.0"), "setup[loaded].damper[D1].coefficient"),
    "coefficient text": (D1.replace("2.0e4", '"big"'), "setup[loaded].damper[D1].coefficient"),
    "outside the span": (D1.replace("0.4", "20.0"), "setup[loaded].damper[D1].position"),
    "unknown key": (D1 + "  damping = 0.1\n", "setup[loaded].damper[D1]"),
    "name of an attachment": (D1.replace('"D1"', '"W1"'), "setup[loaded]"),
    "at an attachment's place": (D1.replace("0.4", "10.0"), "setup[loaded]"),
}


@pytest.mark.parametrize("case", BAD, ids=list(BAD))
def test_a_bad_damper_is_refused_naming_the_field(tmp_path, case):
    text, field = BAD[case]
    file = write_campaign(tmp_path, _with(text))
    with pytest.raises(CampaignError) as err:
        load_campaign(file)
    assert err.value.field.startswith(field), err.value.field
    assert_one_line_naming(err.value, file, err.value.field)


def test_forward_reports_the_damping_ratio_of_each_mode(tmp_path, capsys):
    file = write_campaign(tmp_path, _with(D1))
    out = tmp_path / "forward.json"
    assert main(["forward", str(file), "--json", str(out)]) == 0
    tests = {t["name"]: t for t in json.loads(out.read_text())["tests"]}
    assert "damping" not in tests["T1"]  # the bare setup: real modes, as before
    zeta = tests["T2"]["damping"]["dsm"]
    assert len(zeta) == len(tests["T2"]["modes"]) and all(0 < z < 0.4 / (2 * 20.0) for z in zeta)
    assert "DSM ζ %" in capsys.readouterr().out
    assert math.isfinite(sum(tests["T2"]["frequencies"]["dsm"]))
