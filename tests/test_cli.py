"""The command line, in process: output, JSON contract, exit codes."""

import json
import re
from pathlib import Path

import numpy as np
import pytest

from stcs_ident.cli.main import main

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
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exit_:  # a bad option, refused by argparse as the console script would exit
        code = exit_.code
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
    assert code == 2 and "option '--test'" in err and "T9" in err and "campaign.toml" in err


def test_bad_modes_exits_2(tmp_path, capsys):
    code, _, err = run(["forward", _write(tmp_path, GOOD), "--modes", "0"], capsys)
    assert code == 2 and "--modes" in err and len(err.splitlines()) == 1
    code, _, err = run(["forward", _write(tmp_path, GOOD), "--modes", str(10**8)], capsys)
    assert code == 2 and "at most 10000" in err and len(err.splitlines()) == 1


def test_missing_campaign_exits_2(tmp_path, capsys):
    code, _, err = run(["forward", tmp_path / "nowhere"], capsys)
    assert code == 2 and "nowhere" in err


def test_unwritable_json_leaves_nothing(tmp_path, capsys):
    code, _, err = run(["forward", _write(tmp_path, GOOD), "--json", tmp_path / "no" / "dir" / "x.json"], capsys)
    assert code == 2 and "x.json" in err


def _bad_cases():
    from tests.test_campaign_io import BAD

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


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """A short simulated han2020 campaign (two tests, hidden 5 kg mass at 7 m)."""
    out = tmp_path_factory.mktemp("sim") / "campaign"
    code = main(["simulate", str(HAN), "--out", str(out), "--test", "case1-L4", "--test", "case2-L5",
                 "--duration", "20", "--sampling-rate", "150", "--snr", "30", "--extra-mass", "5@7.0"])
    assert code == 0
    return out


def test_simulate_writes_a_nominal_campaign_with_records(simulated):
    from stcs_ident.io.campaign import load_campaign

    campaign = load_campaign(simulated)
    assert [t.name for t in campaign.tests] == ["case1-L4", "case2-L5"]
    assert all(t.record and (simulated / t.record).is_file() for t in campaign.tests)
    assert campaign.setup("case1").attachments == ()  # the hidden mass is not in the campaign
    truth = json.loads((simulated / "truth.json").read_text())
    assert truth["tests"][0]["effect_names"] == ["unmodeled_mass"]


def test_spectra_json_contract_and_plots(simulated, tmp_path, capsys):
    out_json, plots = tmp_path / "spectra.json", tmp_path / "plots"
    code, out, err = run(["spectra", simulated, "--json", out_json, "--plot", plots], capsys)
    assert code == 0, err
    assert "Test case1-L4" in out and "spectra: test case1-L4 (1 of 2)" in err
    data = json.loads(out_json.read_text())
    truth = {t["name"]: t for t in json.loads((simulated / "truth.json").read_text())["tests"]}
    for t in data["tests"]:
        assert set(t) >= {"name", "modes", "frequencies", "uncertainty", "channels"}
        assert len(t["modes"]) == len(t["frequencies"]) == len(t["uncertainty"]) == len(t["channels"])
        true = dict(zip(truth[t["name"]]["modes"], truth[t["name"]]["frequencies"]))
        for k, f, u in zip(t["modes"], t["frequencies"], t["uncertainty"]):
            assert abs(f - true[k]) < max(6 * u, 1e-3 * true[k])  # numbered right, within its uncertainty
        assert (plots / f"{t['name']}.png").stat().st_size > 10_000


def test_forward_uses_picked_frequencies(simulated, capsys):
    code, out, err = run(["forward", simulated, "--json", "-"], capsys)
    assert code == 0, err
    data = json.loads(out)
    t = data["tests"][0]
    assert t["measured"] is not None and len(t["measured"]) == len(t["modes"])


def test_simulate_refuses_a_non_empty_directory(simulated, capsys):
    code, _, err = run(["simulate", HAN, "--out", simulated], capsys)
    assert code == 2 and "--out" in err


@pytest.mark.parametrize("argv,field", [
    (["--params", "tension,colour"], "params"),
    (["--test", "case1-L1"], "test[case1-L1].frequencies"),
    (["--test", "case1-L4", "--params", "tension,EI,length,mass_per_length,end_stiffness,position"], "params"),
])
def test_identify_bad_input_exits_2(capsys, argv, field):
    code, _out, err = run(["identify", HAN, *argv], capsys)
    assert code == 2 and err.count("\n") == 1 and field in err and "campaign.toml" in err


def test_identify_han2020_case1(tmp_path, capsys):
    out_json = tmp_path / "identify.json"
    code, _out, err = run(["identify", HAN, "--test", "case1-L4", "--test", "case1-L5", "--json", out_json], capsys)
    assert code == 0, err
    data = json.loads(out_json.read_text())
    assert data["method"] == "lsq"
    assert set(data["parameters"]["tension_ratio"]) == {"case1-L4", "case1-L5"}
    assert "EI_ratio" in data["parameters"] and "EI_ratio" in data["uncertainty"]
    for t in data["tests"]:
        rms_after = np.sqrt(np.mean(np.square(t["after_error"])))
        assert rms_after < 0.45  # below the paper's own correction (0.45 %, 0.41 %)


def test_identify_states_the_published_value_beside_ours(capsys):
    """han2020 ships the paper's reported EI ratio (1.01–1.02 of its own ~93.9 kN m²);
    identify prints ours beside it, with its uncertainty."""
    code, out, err = run(["identify", HAN, "--test", "case1-L4", "--test", "case1-L5", "--json", "-"], capsys)
    assert code == 0, err
    [item] = json.loads(out)["published"]
    assert item["parameter"] == "EI_ratio" and item["published"] == [1.01, 1.02]
    assert item["uncertainty_in_basis"] > 0 and "this identification" in item["statement"]
    code, out, _ = run(["identify", HAN, "--test", "case1-L4", "--test", "case1-L5"], capsys)
    assert "Published beside ours: EI_ratio: published 1.01–1.02" in out


@pytest.mark.parametrize("table,field", [
    ('[[published]]\nparameter = "EI_ratio"\nlow = 1.2\nhigh = 1.1\n', "published[EI_ratio].high"),
    ('[[published]]\nparameter = "EI_ratio"\nlow = 1.0\ncolour = 1\n', "published[#1].colour"),
    ('[[published]]\nlow = 1.0\n', "published[#1].parameter"),
])
def test_bad_published_table_exits_2(tmp_path, capsys, table, field):
    code, _, err = run(["forward", _write(tmp_path, GOOD + table)], capsys)
    assert code == 2 and field in err and "campaign.toml" in err


def test_version_help_and_examples(capsys):
    from stcs_ident import __version__
    from stcs_ident.cli.main import EXAMPLES, build_parser

    with pytest.raises(SystemExit) as out:
        main(["--version"])
    assert out.value.code == 0 and capsys.readouterr().out.strip() == f"stcs-ident {__version__}"
    parser = build_parser()
    text = parser.format_help()
    assert text.splitlines()[0].startswith("stcs-ident: cable force")  # what the tool is, before the usage
    sub = parser._subparsers._group_actions[0].choices
    assert set(EXAMPLES) == set(sub)
    for command, example in EXAMPLES.items():
        assert example in text and example in sub[command].format_help()
        args = parser.parse_args(example.split()[1:])  # every example is a valid command line
        assert args.command == command


def test_debug_before_the_command_shows_the_traceback(tmp_path, capsys):
    assert main(["--debug", "forward", str(tmp_path / "missing")]) == 2
    assert "Traceback" in capsys.readouterr().err


def test_simulate_writes_field_conditions(tmp_path):
    h5py = pytest.importorskip("h5py")
    out = tmp_path / "field"
    code = main(["simulate", str(HAN), "--out", str(out), "--test", "case1-L4", "--duration", "20", "--ambient", "5",
                 "--lowpass", "2", "--drift", "5e-5@60", "--pink-noise", "0.01", "--hum", "50:0.02,0.01",
                 "--dc-offset", "0.1", "--float32"])
    assert code == 0
    truth = json.loads((out / "truth.json").read_text())["tests"][0]
    assert set(truth["field"]) >= {"ambient_lowpass", "drift", "pink_noise", "hum", "dc_offsets", "float32"}
    assert len(truth["time_averaged_frequencies"]) == len(truth["frequencies"])  # the truth under drift
    with h5py.File(out / "records" / "case1-L4.h5") as f:
        assert f["acceleration"].dtype == np.float32


@pytest.mark.parametrize("args,field", [
    (["--hum", "50:abc"], "--hum"),
    (["--drift", "big"], "--drift"),
    (["--lowpass", "2"], "--lowpass"),  # without --ambient there is no loading to colour
    (["--ambient", "5", "--lowpass", "-1"], "--lowpass"),
])
def test_simulate_refuses_bad_field_options_naming_them(tmp_path, capsys, args, field):
    out = tmp_path / "bad"
    assert main(["simulate", str(HAN), "--out", str(out), "--test", "case1-L4", "--duration", "20", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"option '{field}'" in err[0]
    assert not out.exists()


@pytest.mark.parametrize("args,field", [
    (["--end-stiffness", "a,b"], "--end-stiffness"),
    (["--end-stiffness", "1e5"], "--end-stiffness"),
    (["--extra-mass", "abc@1"], "--extra-mass"),
    (["--extra-spring", "1e4@far"], "--extra-spring"),
    (["--move", "W1"], "--move"),
    (["--tension-ratio", "x"], "--tension-ratio"),
])
def test_simulate_refuses_bad_hidden_effect_options_naming_them(tmp_path, capsys, args, field):
    out = tmp_path / "bad"
    assert main(["simulate", str(HAN), "--out", str(out), "--test", "case1-L4", "--duration", "5", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"option '{field}'" in err[0], err
    assert not out.exists()


def test_spectra_writes_the_picked_modes_as_csv(simulated, tmp_path, capsys):
    pd = pytest.importorskip("pandas")
    plots = tmp_path / "plots"
    code, out, err = run(["spectra", simulated, "--json", "-", "--plot", plots], capsys)
    assert code == 0, err
    data = json.loads(out)
    table = pd.read_csv(plots / "modes.csv")
    assert list(table["test"].unique()) == [t["name"] for t in data["tests"]]
    for t in data["tests"]:
        rows = table[table["test"] == t["name"]]
        assert rows["mode"].tolist() == t["modes"] and (rows["record_kind"] == t["kind"]).all()
        assert rows["frequency_Hz"].tolist() == t["frequencies"]  # the same numbers, at full precision
        assert rows["uncertainty_Hz"].tolist() == t["uncertainty"]
        assert rows["channels"].tolist() == [";".join(c) for c in t["channels"]]


def test_identify_writes_its_tables_as_csv(tmp_path, capsys):
    pd = pytest.importorskip("pandas")
    plots = tmp_path / "figures"
    code, out, err = run(["identify", HAN, "--test", "case1-L4", "--json", "-", "--plot", plots], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert {p.name for p in plots.iterdir()} >= {"errors.png", "parameters.csv", "frequencies.csv"}
    parameters = pd.read_csv(plots / "parameters.csv").set_index("parameter")
    # written with 6 significant digits ("%.6g", as the before/after table): agreement to 5e-6 relative
    assert parameters.loc["EI_ratio", "variable"] == pytest.approx(data["parameters"]["EI_ratio"], rel=5e-6)
    assert parameters.loc["EI_ratio", "variable_uncertainty"] == pytest.approx(data["uncertainty"]["EI_ratio"],
                                                                               rel=5e-6)
    assert parameters.loc["tension_ratio[case1-L4]", "variable"] == pytest.approx(
        data["parameters"]["tension_ratio"]["case1-L4"], rel=5e-6)
    frequencies = pd.read_csv(plots / "frequencies.csv")
    [t] = data["tests"]
    assert frequencies["mode"].tolist() == t["modes"]
    assert frequencies["corrected_Hz"].to_numpy() == pytest.approx(t["after"], rel=5e-6)


def test_track_writes_its_records_as_csv_beside_the_parquet_table(tmp_path, capsys):
    pd = pytest.importorskip("pandas")
    arch, out = tmp_path / "arch", tmp_path / "histories"
    code, _, err = run(["simulate", _write(tmp_path, GOOD), "--out", arch, "--archive", "0.05", "--interval", "1800",
                        "--duration", "30"], capsys)
    assert code == 0, err
    code, stdout, err = run(["track", arch, "--out", out], capsys)
    assert code == 0, err
    parquet, csv = pd.read_parquet(out / "records.parquet"), pd.read_csv(out / "records.csv")
    assert list(csv.columns) == list(parquet.columns) and len(csv) == len(parquet) == 2  # 72 min every 30 min
    assert csv["tension_N"].tolist() == parquet["tension_N"].tolist()  # floats written at full precision
    assert csv["frequencies_Hz"].tolist() == [";".join(str(float(f)) for f in fs) for fs in parquet["frequencies_Hz"]]
    # every list alike: the doubtful flags too (they were a numpy repr, "[False False ...]"), as pandas writes a bool
    assert csv["doubtful"].tolist() == [";".join(str(bool(d)) for d in ds) for ds in parquet["doubtful"]]
    assert [[float(f) for f in cell.split(";")] for cell in csv["frequencies_Hz"]] == \
        [list(fs) for fs in parquet["frequencies_Hz"]]  # read back to the same doubles
    assert pd.to_datetime(csv["start_time"]).tolist() == parquet["start_time"].tolist()
    assert "of 2 records with a tension" in stdout
    # an hour of records is no monitoring yet: stdout says so, not "no lasting change" (issue 37)
    assert "not monitoring yet" in stdout and "no lasting change" not in stdout


def test_diagnose_workers_caps_the_processes(tmp_path, capsys, monkeypatch):
    import importlib

    from stcs_ident.core.errors import ComputationError

    # The subpackage, where the command takes the step from (``stcs_ident.diagnose`` is the face's function).
    package = importlib.import_module("stcs_ident.diagnose")

    given = {}

    def stop(*args, **options):
        given.update(options)
        raise ComputationError("stopped here")

    monkeypatch.setattr(package, "diagnose", stop)
    code, _, err = run(["diagnose", _write(tmp_path, GOOD), "--workers", "1"], capsys)
    assert code == 1 and "stopped here" in err and given["workers"] == 1
    code, _, err = run(["diagnose", tmp_path, "--workers", "0"], capsys)
    assert code == 2 and "--workers" in err and "1 … 1024" in err


def test_diagnose_help_states_the_default_number_of_processes(capsys):
    from stcs_ident.diagnose.api import MAX_WORKERS

    with pytest.raises(SystemExit):
        main(["diagnose", "--help"])
    assert f"at most {MAX_WORKERS}" in " ".join(capsys.readouterr().out.split())


def test_progress_off_a_terminal_is_a_line_per_step_with_the_time_left(capsys):
    from stcs_ident.cli.common import step_progress
    from stcs_ident.core.formatting import counted

    progress = step_progress("diagnose", "hypothesis")
    progress(1, 4, "tension")
    progress(4, 4, "tension + length")
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("diagnose: hypothesis 1 of 4 (tension), ") and lines[0].endswith(" s left")
    assert lines[1].startswith("diagnose: hypothesis 4 of 4 (tension + length), ") and "about 0 s left" in lines[1]
    assert [counted(n, "test") for n in (0, 1, 2)] == ["0 tests", "1 test", "2 tests"]
    assert counted(1, "hypothesis", "hypotheses") == "1 hypothesis" and counted(3, "hypothesis", "hypotheses")[2:] == \
        "hypotheses"


def test_counts_in_the_diagnosis_agree_with_their_nouns(tmp_path, capsys):
    text = GOOD.replace("frequencies = [2.5, 5.0]", "frequencies = [2.5, 5.0, 7.5, 10.0, 12.5, 15.0]")
    out = tmp_path / "report"
    code, stdout, err = run(["diagnose", _write(tmp_path, text), "--effects", "tension,bending_stiffness",
                             "--max-effects", "1", "--workers", "1", "--out", out], capsys)
    assert code == 0, err
    assert stdout.startswith("Diagnosis of t: 1 test, 6 measured frequencies\n")
    assert "1 test, 6 measured frequencies, 4 hypotheses fitted" in (out / "report.md").read_text()
    assert "diagnose: hypothesis 4 of 4 (tension + bending_stiffness)" in err


def test_progress_on_a_terminal_is_a_bar_with_the_time_left(capsys, monkeypatch):
    import sys

    from stcs_ident.cli.common import step_progress

    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    progress = step_progress("diagnose", "hypothesis")
    for k in range(1, 5):
        progress(k, 4, "tension")
    err = capsys.readouterr().err
    assert "diagnose: 100%" in err and "4/4" in err and "tension" in err
    assert re.search(r"\[\d\d:\d\d<\d\d:\d\d", err)  # elapsed<left, as track shows it
    assert "hypothesis 1 of 4" not in err  # a bar, not lines


def test_diagnose_refuses_a_non_empty_out_directory_before_any_work(tmp_path, capsys, monkeypatch):
    import importlib

    def fail(*args, **options):
        raise AssertionError("the diagnosis ran before the output was checked")

    monkeypatch.setattr(importlib.import_module("stcs_ident.diagnose"), "diagnose", fail)
    out = tmp_path / "not-a-report"
    out.mkdir()
    (out / "notes.txt").write_text("mine", encoding="utf-8")
    code, _, err = run(["diagnose", _write(tmp_path, GOOD), "--out", str(out)], capsys)
    assert code == 2 and "'--out'" in err and "not a report" in err and len(err.strip().splitlines()) == 1
    assert (out / "notes.txt").read_text(encoding="utf-8") == "mine"
