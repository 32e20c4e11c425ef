"""A triaxial record, from HDF5 with its directions and from CSV with the campaign's channel table, through
`simulate`, `spectra`, `identify`, `diagnose` and `track` on the command line (issue: both planes)."""

from __future__ import annotations

import csv
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from stcs_ident.cli.main import main
from stcs_ident.io.records import read_record

pytestmark = pytest.mark.slow  # four commands on simulated records: about 30 s

#: A stay of moderate sag (λ² about 1.1: its in-plane mode 1 is 3 % above the out-of-plane one), short records
#: at a low rate to keep the test quick; two tensions so that identify can fit tension and EI.
CAMPAIGN = """\
[campaign]
name = "triaxial-stay"

[cable]
length = 120.0
mass_per_length = 60.0
EI = 2.0e5
EA = 1.2e9
inclination = 25.0
boundary = "clamped"

[[setup]]
name = "bare"

[[test]]
name = "T1"
setup = "bare"
tension = 2.0e6

[[test]]
name = "T2"
setup = "bare"
tension = 2.4e6
"""


def cli(argv, capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """The campaign's tests simulated with a triaxial sensor at two positions (in, out, axial at each)."""
    root = tmp_path_factory.mktemp("e2e")
    (root / "nominal").mkdir()
    (root / "nominal" / "campaign.toml").write_text(CAMPAIGN)
    out = root / "sim"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        code = main(["simulate", str(root / "nominal"), "--out", str(out), "--triaxial", "--sensors", "0.23,0.41",
                     "--ambient", "10", "--impulses", "0", "--duration", "300", "--sampling-rate", "20",
                     "--seed", "3"])
    assert code == 0
    return out


def test_the_simulated_records_carry_their_directions(simulated):
    record = read_record(simulated / "records" / "T1.h5")
    assert record.directions == ("in", "out", "axial") * 2
    truth = json.loads((simulated / "truth.json").read_text())["tests"][0]
    assert truth["frequencies_in"][0] > truth["frequencies_out"][0]  # the sag term lifts in-plane mode 1


def test_spectra_numbers_each_plane_against_its_family(simulated, tmp_path, capsys):
    code, _, err = cli(["spectra", simulated, "--json", tmp_path / "s.json"], capsys)
    assert code == 0, err
    truth = {t["name"]: t for t in json.loads((simulated / "truth.json").read_text())["tests"]}
    for test in json.loads((tmp_path / "s.json").read_text())["tests"]:
        true = truth[test["name"]]
        planes = test["planes"]
        assert {"in", "out"} <= set(planes)
        assert len(test["mac"]) == len(test["modes"])
        for mode, plane, f, sigma in zip(test["modes"], planes, test["frequencies"], test["uncertainty"]):
            family = true["frequencies_in"] if plane == "in" else true["frequencies_out"]
            # 5σ: a single record's error is a draw of its 1σ (coverage is tested elsewhere over many); a
            # number given to the wrong family or plane would be off by a mode spacing or the sag split (3 %)
            assert abs(f - family[mode - 1]) <= 5 * sigma, (test["name"], plane, mode, f, family[mode - 1], sigma)


def test_identify_and_diagnose_use_both_planes(simulated, tmp_path, capsys):
    code, _, err = cli(["identify", simulated, "--json", tmp_path / "i.json"], capsys)
    assert code == 0, err
    result = json.loads((tmp_path / "i.json").read_text())
    truth = {t["name"]: t for t in json.loads((simulated / "truth.json").read_text())["tests"]}
    planes = [p for test in result["tests"] for p in test["planes"]]
    assert "out" in planes and "in" in planes
    for name, ratio in result["parameters"]["tension_ratio"].items():
        sigma = result["uncertainty"]["tension_ratio"][name]
        true = truth[name]["tension"] / truth[name]["stated_tension"]  # 1: simulated at the stated tension
        # within 3σ (one draw of the stated uncertainty), and the σ small enough to mean something (the
        # default tolerances of the nominal cable dominate it: about 1 %)
        assert abs(ratio - true) <= 3 * sigma and sigma < 0.03, (name, ratio, sigma)
    code, _, err = cli(["diagnose", simulated, "--json", tmp_path / "d.json"], capsys)
    assert code == 0, err
    diagnosis = json.loads((tmp_path / "d.json").read_text())
    assert "out" in json.dumps(diagnosis)


def _as_csv(record, path: Path, start: str) -> None:
    """The record as a logger's CSV: a date-time column and one column per channel, no positions or
    directions."""
    t0 = np.datetime64(start.replace("+00:00", ""), "ms")
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["time", *record.channel_names])
        for k, row in enumerate(record.acceleration):
            stamp = t0 + np.timedelta64(round(1000 * k / record.sampling_rate), "ms")
            writer.writerow([f"{stamp}+00:00", *(f"{v:.9g}" for v in row)])


def test_track_reads_a_triaxial_archive_of_csv_files_with_the_channel_table(simulated, tmp_path, capsys):
    record = read_record(simulated / "records" / "T1.h5")
    cable = tmp_path / "archive" / "stay-1"
    (cable / "records").mkdir(parents=True)
    table = "\n".join(f'{name} = {{ position = {x}, direction = "{d}" }}'
                      for name, x, d in zip(record.channel_names, record.channel_positions, record.directions))
    campaign = CAMPAIGN.split("[[test]]")[0]
    campaign += (f'[record_format]\ntime_column = "time"\nsampling_rate = {record.sampling_rate}\n\n'
                 f'[channels]\n{table}\n\n[[test]]\nname = "reference"\nsetup = "bare"\ntension = 2.0e6\n')
    (cable / "campaign.toml").write_text(campaign)
    for hour in range(2):  # the same record at two hours: two slots of the archive
        _as_csv(record, cable / "records" / f"2026-03-01T{hour:02d}.csv", f"2026-03-01T{hour:02d}:00:00+00:00")
    out = tmp_path / "track"
    code, _, err = cli(["track", tmp_path / "archive", "--out", out], capsys)
    assert code == 0, err
    with open(out / "records.csv") as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == 2, rows
    assert all("out" in row["planes"] and "in" in row["planes"] for row in rows), rows[0]
    tensions = np.array([float(row["tension_N"]) for row in rows])
    # The simulated tension is T1's stated 2.0 MN; 1 %: far above the σ of one record (about 0.1 %)
    assert np.all(np.abs(tensions / 2.0e6 - 1) < 0.01), tensions
