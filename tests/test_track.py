"""track: an archive of simulated monitoring records into tension histories, with a hidden lasting change.

The archive: three hangers (8 m, 400 kN) × three days of 60-s ambient records
every hour, daily temperature cycles (±6 °C, −0.05 %/°C), 0.1 %
record-to-record scatter, and a 1.5 % tension loss on C2 from 2026-03-02
12:00. Records are made by the simulator, analysed blind by spectra and
identify, the history by the CUSUM of track.events.
"""

from __future__ import annotations

import json
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from stcs_ident.cli.main import main
from stcs_ident.io.campaign import load_campaign
from stcs_ident.simulate.archive import ArchiveOptions, TensionChange, simulate_archive
from stcs_ident.track.api import track
from stcs_ident.track.events import analyse_history
from tests.fuzz_inputs import BASE_TOML, _frequencies

CHANGE = TensionChange("C2", "2026-03-02T12:00:00+00:00", -0.015)


def _campaign(directory: Path):
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "campaign.toml").write_text(BASE_TOML.replace('record = "records/T2.h5"\n', "")
                                             .format(f=_frequencies()), encoding="utf-8")
    return load_campaign(directory)


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    root = tmp_path_factory.mktemp("track")
    campaign = _campaign(root / "campaign")
    simulate_archive({name: campaign for name in ("C1", "C2", "C3")}, root / "archive",
                     options=ArchiveOptions(days=3, interval=3600), change=CHANGE, seed=3)
    return root / "archive"


@pytest.fixture(scope="module")
def tracked(archive):
    out = archive.parent / "out"
    return track(archive, out, workers=2).summary(), out


@pytest.mark.slow
@pytest.mark.xdist_group("track_archive")  # with -n, on one worker: the archive is tracked once
def test_the_hidden_tension_loss_is_found_on_its_cable_only(archive, tracked):
    summary, out = tracked
    truth = json.loads((archive / "truth.json").read_text())
    for name, cable in summary["cables"].items():
        assert cable["records"] == 72 and cable["processed"] == 72 and cable["failed"] == 0
        assert len(cable["events"]) == (name == "C2"), (name, cable["events"])
    event = summary["cables"]["C2"]["events"][0]
    times = [r["start_time"] for r in truth["cables"]["C2"]["records"]]
    found, true = times.index(event["start_time"]), times.index(CHANGE.time)
    assert abs(found - true) <= 3  # the acceptance: within 3 records of its start
    assert abs(event["change"] - CHANGE.change) <= 0.003  # the acceptance: 0.3 % absolute
    assert abs(event["change"] - CHANGE.change) <= 3 * event["uncertainty"]  # and within its 3σ
    # The temperature normalisation recovers the simulated coefficient (−5e-4 per °C; 1σ about 5e-5 here).
    for cable in summary["cables"].values():
        assert abs(cable["thermal_coefficient"] - ArchiveOptions().thermal_coefficient) < 2e-4
    # Each record's tension against the truth: its 1σ covers the identification's error, not the scatter.
    table = pd.read_parquet(out / "records.parquet")
    true_tension = {(n, r["record"]): r["tension"] for n, c in truth["cables"].items() for r in c["records"]}
    z = np.array([(row.tension_N - true_tension[(row.cable, row.record)]) / row.tension_sigma_N
                  for row in table.itertuples()])
    assert 0.55 <= np.mean(np.abs(z) <= 1) <= 0.85 and np.mean(np.abs(z) <= 3) >= 0.97, np.percentile(np.abs(z), 68)


@pytest.mark.slow
@pytest.mark.xdist_group("track_archive")
def test_a_dask_local_cluster_gives_the_same_rows(archive, tracked, tmp_path):
    """C2's records (the cable with the hidden change) through Dask: each cable's rows and history are computed
    from its own records alone, so one cable checks the transport, the batches (5 of 16 records on 2 workers:
    submitted, refilled, finishing out of order) and the events as the whole archive did, in a third of the time;
    and the cable selection gives that cable's rows and summary of the whole run."""
    distributed = pytest.importorskip("distributed")
    _, out = tracked
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        summary = track(archive, tmp_path / "dask", cables=["C2"], scheduler=cluster.scheduler_address).summary()
    local = pd.read_parquet(out / "records.parquet")
    local = local[local["cable"] == "C2"].reset_index(drop=True)
    dask = pd.read_parquet(tmp_path / "dask" / "records.parquet")
    assert len(dask) == 72
    columns = ["cable", "record", "record_id", "start_time", "status", "modes", "frequencies_Hz", "frequency_sigma_Hz",
               "tension_N", "tension_sigma_N", "temperature_degC", "tension_normalised_N", "tension_level_N"]
    pd.testing.assert_frame_equal(local[columns], dask[columns], check_exact=True)  # every row, to the last bit
    assert summary["cables"] == {"C2": tracked[0]["cables"]["C2"]}  # and so the same event


@pytest.fixture
def small(tmp_path):
    campaign = _campaign(tmp_path / "campaign")
    simulate_archive({"C1": campaign}, tmp_path / "archive", options=ArchiveOptions(days=0.5, interval=1800), seed=5)
    return tmp_path / "archive"


@pytest.mark.slow
def test_a_run_killed_midway_and_restarted_ends_with_the_same_table(small, tmp_path):
    whole = tmp_path / "whole"
    track(small, whole, batch=2, workers=2)  # the reference table (local processes give the same rows)
    out = tmp_path / "killed"
    # -P: the child imports the installed package, as this process does (from a checkout's root, the current
    # directory first on its path would give it the source tree, without the compiled kernels: rows 1e-13 apart)
    command = [sys.executable, "-P", "-c", ("import sys; from stcs_ident.track.api import track; "
               f"track({str(small)!r}, {str(out)!r}, batch=2)")]
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    while child.poll() is None and len(list((out / "parts").glob("*.parquet"))) < 3:
        time.sleep(0.01)
    child.send_signal(signal.SIGKILL)
    child.wait()
    finished = len(list((out / "parts").glob("*.parquet")))
    assert 0 < finished < 12  # killed midway: some batches done, not all
    track(small, out, batch=2)
    a, b = pd.read_parquet(whole / "records.parquet"), pd.read_parquet(out / "records.parquet")
    pd.testing.assert_frame_equal(a.drop(columns=["mtime_ns"]), b.drop(columns=["mtime_ns"]))
    assert not [p for p in out.rglob("*") if ".stcs~" in p.name]  # the killed run's temporaries are gone


def test_a_rerun_processes_only_new_records_known_by_content(small, tmp_path):
    out = tmp_path / "out"
    calls = []
    track(small, out, workers=2, progress=lambda done, total: calls.append(total))
    assert calls[-1] == 24
    records = small / "C1" / "records"
    day = next(records.iterdir())
    first = min(day.glob("*.h5"))
    shutil.copy(first, records / "renamed-copy.h5")  # the same content under another name: a row, not processed
    calls.clear()
    result = track(small, out, progress=lambda done, total: calls.append(total))
    assert calls == [] and result.summary()["cables"]["C1"]["records"] == 25
    assert result.counts == {"new": 1, "changed": 0, "stale": 0, "removed": 0, "retried": 0, "unchanged": 24}
    (records / "renamed-copy.h5").unlink()


def test_unreadable_records_are_rows_with_their_reason_and_the_rest_go_on(small, tmp_path):
    import h5py

    records = small / "C1" / "records" / "bad"
    records.mkdir()
    good = min((small / "C1" / "records").rglob("*.h5"))
    (records / "truncated.h5").write_bytes(good.read_bytes()[:5000])
    (records / "text.h5").write_text("time,a\n0,1\n")
    shutil.copy(good, records / "nan.h5")
    shutil.copy(good, records / "no-time.h5")
    with h5py.File(records / "nan.h5", "r+") as h5:
        h5["acceleration"][10, 1] = np.nan
        h5.attrs["temperature"] = 3.0  # another content than the good record's
    with h5py.File(records / "no-time.h5", "r+") as h5:
        del h5.attrs["start_time"]
    summary = track(small, tmp_path / "out").summary()
    cable = summary["cables"]["C1"]
    assert cable["records"] == 28 and cable["processed"] == 24 and cable["failed"] == 4
    reasons = {f["record"]: f["reason"] for f in cable["failures"]}
    assert "not an HDF5 file" in reasons["records/bad/text.h5"]
    assert "cannot read" in reasons["records/bad/truncated.h5"]
    assert "NaN at sample 10" in reasons["records/bad/nan.h5"]
    assert "start_time" in reasons["records/bad/no-time.h5"]


def test_a_cable_whose_every_record_failed_gets_its_report_with_the_reasons(tmp_path, capsys):
    """No traceback and no lost report when nothing of a cable could be processed: its figure says so and
    report.md lists every failure."""
    campaign = _campaign(tmp_path / "campaign")
    arch = simulate_archive({"C1": campaign, "C2": campaign}, tmp_path / "archive",
                            options=ArchiveOptions(days=1 / 24, interval=1800), seed=3)
    broken = sorted((arch / "C2" / "records").rglob("*.h5"))
    for i, path in enumerate(broken):
        path.write_text(f"not a record {i}\n", encoding="utf-8")  # distinct contents: one failed row each
    assert main(["track", str(arch), "--out", str(tmp_path / "out")]) == 0
    out = tmp_path / "out"
    assert {"report.md", "C1.png", "C2.png", "cables.csv"} <= {p.name for p in out.iterdir()}
    report = (out / "report.md").read_text(encoding="utf-8")
    assert report.count("not an HDF5 file") == len(broken) >= 2
    cables = pd.read_csv(out / "cables.csv").set_index("cable")
    assert cables.loc["C2", "n_failed"] == len(broken) and cables.loc["C1", "n_failed"] == 0
    assert f"C2: 0 of {len(broken)} records with a tension, {len(broken)} failed" in capsys.readouterr().out


def test_the_cli_tracks_an_archive_it_simulated(tmp_path, capsys):
    campaign = tmp_path / "campaign"
    _campaign(campaign)
    arch = tmp_path / "arch"
    assert main(["simulate", str(campaign), "--out", str(arch), "--archive", "0.25", "--cables", "2",
                 "--interval", "1800"]) == 0
    assert main(["track", str(arch), "--out", str(tmp_path / "h"), "--json", str(tmp_path / "s.json"),
                 "--workers", "2"]) == 0  # on 2 local processes (the rows are those of one)
    summary = json.loads((tmp_path / "s.json").read_text())
    assert set(summary["cables"]) == {"C1", "C2"} and summary["cables"]["C1"]["processed"] == 12
    assert {p.name for p in (tmp_path / "h").iterdir()} >= {"records.parquet", "report.md", "C1.png", "C2.png",
                                                             "events.csv", "cables.csv"}
    capsys.readouterr()
    assert main(["track", str(arch), "--out", str(arch / "C1")]) == 2  # an output over the inputs
    assert "option '--out'" in capsys.readouterr().err
    from stcs_ident.cli.main import build_parser
    from stcs_ident.cli.track import ARCHIVE_EXAMPLE

    args = build_parser().parse_args(ARCHIVE_EXAMPLE.split()[1:])  # the help's example is a valid command line
    assert args.archive == 3 and args.cables == 3 and args.tension_change.startswith("C2,")
    assert main(["simulate", str(campaign), "--out", str(tmp_path / "x"), "--archive", "1",
                 "--tension-change", "C9,2026-03-01T00:00:00,-0.01"]) == 2
    assert "option '--tension-change'" in capsys.readouterr().err


def test_healthy_histories_raise_at_most_one_false_event_per_cable_month():
    """Thirty cable-months of 10-minute tensions (daily cycles of ±6 °C at −0.05 %/°C, a weather drift the
    tension does not follow, 0.2 % scatter): the issue's bound is 1 false event per cable-month."""
    rng = np.random.default_rng(7)
    events = 0
    for _ in range(30):
        n = 4320
        hours = np.arange(n) / 6.0
        weather = np.cumsum(rng.standard_normal(n)) * 0.05
        theta = 12 - 6 * np.cos(2 * np.pi * (hours - 5) / 24) + weather
        tension = 4e5 * (1 - 5e-4 * (theta - weather - 12)) * (1 + 0.002 * rng.standard_normal(n))
        events += len(analyse_history(tension, theta, 4e5).events)
    assert events <= 30, events  # measured: 0 (benchmarks/track.py gives the rate over more months)


def test_the_size_of_a_change_comes_with_an_honest_one_sigma():
    """300 histories of 432 10-minute tensions (daily cycles, 0.2 % scatter, the cable lagging the air by an
    hour in half of them) with a 1.5 % loss at record 300: the loss is found within 3 records in nearly all,
    and |error| <= 1σ of its size in about 68 %, <= 3σ in at least 98 % (measured: 70 % and 100 %; under a
    weather drift the tension does not follow, 54 % and 98 %: benchmarks/track.py's conditions)."""
    rng = np.random.default_rng(5)
    z = []
    for k in range(300):
        hours = np.arange(432) / 6.0
        air = 12 - 6 * np.cos(2 * np.pi * (hours - 5) / 24)
        cable = 12 - 6 * np.cos(2 * np.pi * (hours - 5 - (k % 2)) / 24)
        tension = 4e5 * (1 - 5e-4 * (cable - 12)) * (1 + 0.002 * rng.standard_normal(hours.size))
        tension[300:] *= 1 - 0.015
        found = [e for e in analyse_history(tension, air, 4e5).events if abs(e.index - 300) <= 3]
        z += [(e.change + 0.015) / e.uncertainty for e in found[:1]]
    z = np.abs(np.array(z))
    assert len(z) >= 0.9 * 300
    assert 0.6 <= np.mean(z <= 1) <= 0.8 and np.mean(z <= 3) >= 0.98, (np.mean(z <= 1), np.mean(z <= 3))


def test_a_healthy_one_day_archive_reports_no_change_but_not_enough_history(tmp_path):
    """The issue's case end to end: two healthy cables, one day of hourly records, through spectra, identify and
    the history. A day of records only sets the level, the thermal coefficient and the scatter: no lasting change
    may be reported (before, C2 reported +0.37 %), and each cable says it has not enough history yet."""
    campaign = _campaign(tmp_path / "campaign")
    simulate_archive({"C1": campaign, "C2": campaign}, tmp_path / "archive",
                     options=ArchiveOptions(days=1, interval=3600), seed=7)
    summary = track(tmp_path / "archive", tmp_path / "out", workers=2).summary()
    for name in ("C1", "C2"):
        cable = summary["cables"][name]
        assert cable["processed"] == 24
        assert cable["events"] == []
        assert cable["state"] == "not enough history yet"


def test_a_one_day_archive_with_a_step_says_it_is_not_monitoring_yet_and_keeps_the_thermal_coefficient(
        tmp_path, capsys):
    """Issue 37 end to end: a day of hourly records with a 2 % step at noon and the simulator's daily cycle
    (−0.05 %/°C). The command's line says the cable is not monitoring yet, the rule and how many records it
    still needs (as report.md and the JSON do), not "no lasting change"; the thermal coefficient is fitted beside
    the step, within 0.05 %/°C of the truth (before: −0.254 %/°C, the step taken for a thermal effect)."""
    from stcs_ident.track.events import MIN_MONITORED, MONITORING_RULE

    campaign = _campaign(tmp_path / "campaign")
    options = ArchiveOptions(days=1, interval=3600)
    simulate_archive({"C1": campaign}, tmp_path / "archive", options=options,
                     change=TensionChange("C1", "2026-03-01T12:00:00+00:00", -0.02), seed=7)
    capsys.readouterr()
    assert main(["track", str(tmp_path / "archive"), "--out", str(tmp_path / "out"),
                 "--json", str(tmp_path / "s.json")]) == 0
    stdout = capsys.readouterr().out
    cable = json.loads((tmp_path / "s.json").read_text())["cables"]["C1"]
    needed = options.n_records + MIN_MONITORED - cable["processed"]  # the whole first day is the training window
    assert cable["processed"] == options.n_records and cable["records_needed"] == needed == MIN_MONITORED
    note = f"not monitoring yet: {MONITORING_RULE}: {needed} more records"
    assert cable["state_note"] == note and cable["state"] == "not enough history yet" and cable["events"] == []
    assert f"C1: 24 of 24 records with a tension, 0 failed; {note}" in stdout and "no lasting change" not in stdout
    assert f"| {note} |" in (tmp_path / "out" / "report.md").read_text()
    # the issue's bound; the identified tensions' own scatter (0.1 % simulated) is in it too
    assert abs(cable["thermal_coefficient"] - options.thermal_coefficient) <= 5e-4, cable["thermal_coefficient"]
