"""The command line, in process: output, JSON contract, exit codes."""

import json
from pathlib import Path

import pytest

from stcs_ident.cli import main

ROOT = Path(__file__).resolve().parents[1]
HAN = ROOT / "campaigns" / "han2020"

GOOD = """
[campaign]
name = "t"
[cable]
length = 20.0
mass_per_length = 10.0
EI = 1.0e4
[[setup]]
name = "s"
[[test]]
name = "T1"
setup = "s"
tension = 1.0e5
frequencies = [2.5, 5.0]
"""


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_forward_han2020_table_and_json(tmp_path, capsys):
    out_json = tmp_path / "forward.json"
    code, out, err = run(["forward", HAN, "--json", out_json], capsys)
    assert code == 0, err
    assert "Test case1-L4" in out and "DSM" in out
    assert "does NOT reproduce 'paper_dsm'" in out  # the EI discrepancy is stated
    data = json.loads(out_json.read_text())
    assert data["campaign"] == "han2020"
    assert len(data["tests"]) == 15
    t = next(t for t in data["tests"] if t["name"] == "case1-L4")
    assert t["setup"] == "case1" and t["tension"] == 1248700.0
    assert t["modes"] == [1, 2, 3, 4, 5, 6]
    assert set(t["frequencies"]) >= {"dsm", "taut_string", "beam_pinned"}
    assert len(t["frequencies"]["dsm"]) == 6
    assert t["measured"][0] == 7.24
    assert next(t for t in data["tests"] if t["name"] == "case1-L1")["measured"] is None


def test_forward_json_to_stdout_and_options(capsys):
    code, out, _ = run(["forward", HAN / "campaign.toml", "--test", "case2-L4", "--modes", "8",
                        "--tension-model", "none", "--json", "-"], capsys)
    assert code == 0
    data = json.loads(out)
    [t] = data["tests"]
    assert t["modes"] == list(range(1, 9))
    assert t["measured"][6] is None  # mode 7 was not measured


def _write(tmp_path, text):
    (tmp_path / "campaign.toml").write_text(text)
    return tmp_path


@pytest.mark.parametrize("text,field", [
    (GOOD.replace("length = 20.0\n", ""), "cable.length"),
    (GOOD.replace("length = 20.0", 'length = "abc"'), "cable.length"),
    (GOOD.replace("EI = 1.0e4", "EI = 1.0e4\ncolour = 3"), "cable.colour"),
    (GOOD.replace("tension = 1.0e5", "tension = -1.0"), "test[T1].tension"),
    (GOOD.replace('setup = "s"', 'setup = "x"'), "test[T1].setup"),
    (GOOD + '[[setup]]\nname = "s"\n', "setup[s].name"),
])
def test_bad_campaign_exits_2_with_one_line(tmp_path, capsys, text, field):
    directory = _write(tmp_path, text)
    out_json = tmp_path / "out.json"
    code, out, err = run(["forward", directory, "--json", out_json], capsys)
    assert code == 2
    assert err.count("\n") == 1
    assert str(directory / "campaign.toml") in err and field in err
    assert not out_json.exists() and out == ""


def test_unknown_test_exits_2(tmp_path, capsys):
    code, _, err = run(["forward", _write(tmp_path, GOOD), "--test", "T9"], capsys)
    assert code == 2 and "field 'test'" in err and "T9" in err and "campaign.toml" in err


def test_bad_modes_exits_2(tmp_path, capsys):
    code, _, err = run(["forward", _write(tmp_path, GOOD), "--modes", "0"], capsys)
    assert code == 2 and "--modes" in err


def test_missing_campaign_exits_2(tmp_path, capsys):
    code, _, err = run(["forward", tmp_path / "nowhere"], capsys)
    assert code == 2 and "nowhere" in err


def test_unwritable_json_leaves_nothing(tmp_path, capsys):
    code, _, err = run(["forward", _write(tmp_path, GOOD), "--json", tmp_path / "no" / "dir" / "x.json"], capsys)
    assert code == 2 and "x.json" in err


def _bad_cases():
    from test_campaign_io import BAD

    return BAD


@pytest.mark.parametrize("name", list(_bad_cases()))
def test_every_bad_campaign_exits_2_through_the_cli(tmp_path, capsys, name):
    """Every bad input of the loader's tests, through the command line: exit 2,
    one line naming the file and the field, nothing written."""
    text, field = _bad_cases()[name]
    directory = _write(tmp_path, text)
    out_json = tmp_path / "out.json"
    code, out, err = run(["forward", directory, "--json", out_json], capsys)
    assert code == 2
    assert err.count("\n") == 1 and str(directory / "campaign.toml") in err
    assert f"'{field}'" in err
    assert not out_json.exists() and out == ""


@pytest.mark.parametrize("content", ["not TOML {{{ ]]]\n", b"\xff\xfe\x00\x81"])
def test_unreadable_or_non_toml_exits_2(tmp_path, capsys, content):
    file = tmp_path / "campaign.toml"
    file.write_bytes(content if isinstance(content, bytes) else content.encode())
    code, _, err = run(["forward", file], capsys)
    assert code == 2 and err.count("\n") == 1 and str(file) in err


def test_reference_column_of_wrong_length_exits_2(tmp_path, capsys):
    text = GOOD + "  [test.reference]\n  paper = [2.4]\n"
    code, _, err = run(["forward", _write(tmp_path, text)], capsys)
    assert code == 2 and "test[T1].reference.paper" in err
