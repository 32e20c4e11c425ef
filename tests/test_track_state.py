"""track's table is a function of the archive and the campaigns: what a rerun does when the archive lives.

Each test changes a tiny archive (2 cables × 3 records of 10 s at 50 Hz, one
channel: about 0.1 s a record) between runs as a monitoring archive changes,
and checks the rerun's table against what a first run on the archive as it
now is gives (:func:`_clean`), and what the run says it did (``counts``).
"""

from __future__ import annotations

import importlib
import os
import shutil
import warnings
from pathlib import Path

import h5py
import pandas as pd
import pytest

from stcs_ident.cli.main import main
from stcs_ident.core.errors import TrackWarning
from stcs_ident.simulate.archive import ArchiveOptions, simulate_archive
from stcs_ident.track.api import track
from stcs_ident.track.archive import discover
from stcs_ident.track.store import OLD_NAMES, ROW_COLUMNS, append_part, cable_key
from tests.test_track import _campaign

#: Tiny records: 10 s at 50 Hz on one channel give the hanger's first modes and a tension in about 0.1 s.
TINY = ArchiveOptions(days=3 / 48, interval=1800, duration=10, sampling_rate=50, sensors=(0.3,))
#: The columns that say what a row is (its file's modification time aside: a copy of an archive has others).
COMPARED = [c for c in ROW_COLUMNS if c != "mtime_ns"] + ["tension_normalised_N", "tension_level_N"]
NOTHING = {"new": 0, "changed": 0, "stale": 0, "removed": 0, "retried": 0}


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    root = tmp_path_factory.mktemp("state")
    campaign = _campaign(root / "campaign")
    return simulate_archive({"C1": campaign, "C2": campaign}, root / "archive", options=TINY, seed=11)


@pytest.fixture
def archive(pristine, tmp_path):
    return Path(shutil.copytree(pristine, tmp_path / "archive"))


def records(archive: Path, cable: str) -> list[Path]:
    return sorted((archive / cable / "records").rglob("*.h5"))


def _clean(archive: Path, tmp_path: Path) -> pd.DataFrame:
    """The table of a first run on the archive as it is now."""
    out = tmp_path / f"clean-{len(list(tmp_path.glob('clean-*')))}"
    return track(archive, out).table


def assert_same_table(a: pd.DataFrame, b: pd.DataFrame) -> None:
    pd.testing.assert_frame_equal(a[COMPARED].reset_index(drop=True), b[COMPARED].reset_index(drop=True))


def test_a_record_changed_in_place_replaces_its_row(archive, tmp_path):
    out = tmp_path / "out"
    track(archive, out)
    path = records(archive, "C1")[1]
    with h5py.File(path, "r+") as h5:
        h5.attrs["temperature"] = 31.5  # a temperature fixed in the file
    result = track(archive, out)
    assert result.counts == {**NOTHING, "changed": 1, "unchanged": 5}
    rows = result.table[result.table["cable"] == "C1"]
    assert len(rows) == 3 and (rows["temperature_degC"] == 31.5).sum() == 1
    assert_same_table(result.table, _clean(archive, tmp_path))


def test_a_truncated_copy_later_completed_leaves_no_failed_row(archive, tmp_path):
    out = tmp_path / "out"
    path = records(archive, "C1")[0]
    whole = path.read_bytes()
    path.write_bytes(whole[:3000])  # still being copied
    first = track(archive, out).table
    assert (first["status"] == "failed").sum() == 1
    path.write_bytes(whole)
    result = track(archive, out)
    assert result.counts == {**NOTHING, "changed": 1, "unchanged": 5}
    assert (result.table["status"] == "ok").all() and len(result.table) == 6
    assert_same_table(result.table, _clean(archive, tmp_path))


def test_an_edited_campaign_makes_its_cable_stale(archive, tmp_path):
    out = tmp_path / "out"
    before = track(archive, out).table
    toml = archive / "C1" / "campaign.toml"
    toml.write_text(toml.read_text().replace("EI = 200000.0", "EI = 100000.0").replace("mass_per_length = 30.0",
                                                                                   "mass_per_length = 31.5"))
    result = track(archive, out)
    assert result.counts == {**NOTHING, "stale": 3, "unchanged": 3}
    after = result.table
    c1 = after["cable"] == "C1"
    # 5 % more mass: the tension of the same frequencies is about 5 % higher (EI is a small correction here).
    before_c1 = before.loc[before["cable"] == "C1", "tension_N"].to_numpy()
    assert (after.loc[c1, "tension_N"].to_numpy() > 1.03 * before_c1).all()
    assert result.summary()["cables"]["C1"]["EI"] == 1.0e5
    assert_same_table(after, _clean(archive, tmp_path))
    # A comment changes nothing that shapes a row: the cable stays current.
    toml.write_text("# corrected on site\n" + toml.read_text())
    assert track(archive, out).counts == {**NOTHING, "unchanged": 6}


def test_a_deleted_record_leaves_the_table(archive, tmp_path):
    out = tmp_path / "out"
    track(archive, out)
    records(archive, "C2")[2].unlink()
    result = track(archive, out)
    assert result.counts == {**NOTHING, "removed": 1, "unchanged": 5}
    assert result.summary()["cables"]["C2"]["records"] == 2
    assert_same_table(result.table, _clean(archive, tmp_path))
    assert track(archive, out).counts == {**NOTHING, "unchanged": 5}  # removed once
    shutil.rmtree(archive / "C2")  # a whole cable gone
    result = track(archive, out)
    assert result.counts == {**NOTHING, "removed": 2, "unchanged": 3} and set(result.table["cable"]) == {"C1"}


def test_a_first_run_hashes_each_record_in_its_worker_and_a_copy_is_still_found(archive, tmp_path, monkeypatch):
    """No current row can be of a new file's content unless one is of its size: the plan leaves such files to
    the workers, which read them anyway; a file of a current row's size (a copy, say) is hashed by the plan
    and its row reused, as before."""
    from stcs_ident.track import archive as archive_module
    from stcs_ident.track import state

    planned = []
    monkeypatch.setattr(state, "content_id", lambda path: planned.append(path) or archive_module.content_id(path))
    out = tmp_path / "out"
    table = track(archive, out, workers=2).table
    assert planned == []
    paths = {(r.cable, r.record): archive / r.cable / r.record for r in table.itertuples()}
    assert [archive_module.content_id(paths[(r.cable, r.record)]) for r in table.itertuples()] == \
        list(table["record_id"]) and len(table) == 6
    copy, original = archive / "C1" / "records" / "copy-of-first.h5", records(archive, "C1")[0]
    shutil.copy(original, copy)
    result = track(archive, out)
    assert planned == [copy]
    assert result.counts == {**NOTHING, "new": 1, "unchanged": 6}
    rows = result.table.set_index("record")
    assert rows.loc["records/copy-of-first.h5", "record_id"] == \
        rows.loc[original.relative_to(archive / "C1").as_posix(), "record_id"]
    assert_same_table(result.table, _clean(archive, tmp_path))


def test_the_same_record_in_two_cables_keeps_a_row_in_each(archive, tmp_path):
    out = tmp_path / "out"
    shutil.copy(records(archive, "C1")[0], archive / "C2" / "records" / "0-from-C1.h5")
    tables = [track(archive, out, batch=1).table for _ in range(3)]  # parts of one record: one per cable
    for table in tables:
        assert len(table) == 7 and (table["cable"] == "C2").sum() == 4
    assert_same_table(tables[0], tables[1])
    assert_same_table(tables[1], tables[2])
    names = [p.name for p in (out / "parts").iterdir()]
    assert len(names) == len(set(names)) == 2  # one part per cable once compacted


def test_a_rerun_of_one_cable_keeps_the_others_in_the_table_and_the_report(archive, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["track", str(archive), "--out", str(out)]) == 0
    whole = pd.read_parquet(out / "records.parquet")
    cables = (out / "cables.csv").read_text()
    with h5py.File(records(archive, "C1")[0], "r+") as h5:
        h5.attrs["temperature"] = 2.0
    capsys.readouterr()
    assert main(["track", str(archive), "--out", str(out), "--cable", "C1"]) == 0
    assert "track: 0 new, 1 changed, 0 stale, 0 removed, 0 retried, 2 unchanged" in capsys.readouterr().err
    table = pd.read_parquet(out / "records.parquet")
    c2 = table[table["cable"] == "C2"].reset_index(drop=True)
    assert c2[["tension_normalised_N", "tension_level_N"]].notna().all().all()
    assert_same_table(c2, whole[whole["cable"] == "C2"])
    now = pd.read_csv(out / "cables.csv")
    assert list(now["cable"]) == ["C1", "C2"]
    # (a NaN cell, a thermal coefficient not fitted yet, equal to itself)
    pd.testing.assert_series_equal(now.iloc[1], pd.read_csv(pd.io.common.StringIO(cables)).iloc[1])
    report = (out / "report.md").read_text()
    assert "| C2 | 3 | 3 | 0 |" in report and "[C2](C2.png)" in report


def test_a_failed_row_is_retried_when_its_cause_is_gone(archive, tmp_path):
    """As a Dask worker that could not see a relative path left it: a failed row of a good record."""
    out = tmp_path / "out"
    track(archive, out)
    good = track(archive, out).table
    spec = track(archive, out).specs[0]
    row = good[good["cable"] == "C1"].iloc[0].to_dict()
    row.update(status="failed", reason="cannot read: file not found", tension_N=float("nan"), n_modes=0, modes=[],
               frequencies_Hz=[], frequency_sigma_Hz=[], version=spec.version)
    append_part(out, [{k: row[k] for k in ROW_COLUMNS}])  # the latest row of that path: failed
    result = track(archive, out)
    assert result.counts == {**NOTHING, "retried": 1, "unchanged": 5}
    assert_same_table(result.table, good)
    assert track(archive, out).counts == {**NOTHING, "unchanged": 6}


def test_a_relative_archive_path_reaches_the_workers_whole(archive, tmp_path, monkeypatch):
    monkeypatch.chdir(archive.parent)
    spec = discover("archive")[0]
    assert Path(spec.directory).is_absolute() and Path(spec.directory) == archive / "C1"


def test_a_relative_archive_path_on_dask_workers_started_elsewhere(archive, tmp_path, monkeypatch):
    """The issue's case: workers whose working directory is not the caller's got relative paths (every row
    "failed: file not found"), and the failed rows were never retried."""
    distributed = pytest.importorskip("distributed")
    first = track(archive, tmp_path / "local").table
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        monkeypatch.chdir(archive.parent)  # after the workers started: their directory is another
        result = track("archive", tmp_path / "dask", scheduler=cluster.scheduler_address)
    assert (result.table["status"] == "ok").all()
    assert_same_table(result.table, first)


def test_parts_written_before_the_names_carried_units_are_resumed_on(archive, tmp_path):
    out = tmp_path / "out"
    first = track(archive, out).table
    parts = sorted((out / "parts").iterdir())
    old = {new: name for name, new in OLD_NAMES.items()}
    for part in parts:  # every part as a run before the renaming wrote it: the same rows, the old names
        frame = pd.read_parquet(part)
        assert set(old) <= set(frame.columns)
        frame.rename(columns=old).to_parquet(part, index=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no part reported unreadable
        result = track(archive, out)
    assert result.counts == {**NOTHING, "unchanged": 6}  # nothing processed again
    assert_same_table(result.table, first)
    assert set(OLD_NAMES).isdisjoint(pd.read_parquet(out / "records.parquet").columns)


@pytest.mark.parametrize("damage", ["truncated", "zero-byte", "other columns"])
def test_a_damaged_part_is_reported_and_its_records_processed_again(archive, tmp_path, damage):
    out = tmp_path / "out"
    first = track(archive, out).table
    part = min((out / "parts").iterdir())
    if damage == "truncated":
        part.write_bytes(part.read_bytes()[:200])
    elif damage == "zero-byte":
        part.write_bytes(b"")
    else:
        pd.DataFrame({"x": [1.0]}).to_parquet(part)
    with pytest.warns(TrackWarning, match="cannot be read") as caught:
        result = track(archive, out)
    assert len(caught) == 1
    assert result.counts["new"] == 3 and result.counts["unchanged"] == 3
    assert_same_table(result.table, first)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # reported once: the part rebuilt, the damaged one gone
        assert track(archive, out).counts == {**NOTHING, "unchanged": 6}


def test_files_in_parts_that_are_not_ours_are_ignored(archive, tmp_path):
    out = tmp_path / "out"
    first = track(archive, out).table
    pd.DataFrame({"cable": ["C1"], "record": ["junk"]}).to_parquet(out / "parts" / "junk.parquet")
    (out / "parts" / "notes.txt").write_text("mine")
    (out / "parts" / "0123-4567.parquet").write_bytes(b"")  # an old name
    result = track(archive, out)
    assert result.counts == {**NOTHING, "unchanged": 6}
    assert_same_table(result.table, first)
    assert (out / "parts" / "junk.parquet").exists() and (out / "parts" / "notes.txt").exists()


def test_a_cable_without_records_has_its_row_and_section(archive, tmp_path, capsys):
    for path in records(archive, "C2"):
        path.unlink()
    shutil.rmtree(archive / "C1" / "records")
    out = tmp_path / "out"
    assert main(["track", str(archive), "--out", str(out)]) == 0
    cables = pd.read_csv(out / "cables.csv").set_index("cable")
    assert list(cables.index) == ["C1", "C2"] and (cables["n_records"] == 0).all()
    report = (out / "report.md").read_text()
    assert "| C1 | 0 | 0 | 0 |" in report and "| C2 | 0 | 0 | 0 |" in report
    assert (out / "C1.png").exists() and (out / "C2.png").exists()
    assert "C2: 0 of 0 records with a tension" in capsys.readouterr().out


def test_a_dangling_link_and_a_folder_named_like_a_record_are_not_records(archive, tmp_path):
    where = archive / "C1" / "records"
    os.symlink(where / "gone.h5", where / "dangling.h5")
    (where / "folder.h5").mkdir()
    shutil.copy(records(archive, "C1")[0], where / "folder.h5" / "inside.h5")
    result = track(archive, tmp_path / "out")
    assert result.summary()["cables"]["C1"]["records"] == 4
    assert "records/folder.h5/inside.h5" in set(result.table["record"])


# Reruns as a property: whatever happens to the archive and the output between runs, the rerun's table is that
# of a first run on the archive as it then is.

hypothesis = pytest.importorskip("hypothesis")
st = hypothesis.strategies

#: An operation on the archive or the output: (kind, cable, which record / value).
OPERATIONS = st.tuples(st.sampled_from(["add", "remove", "modify", "copy", "campaign", "corrupt", "kill"]),
                       st.sampled_from(["C1", "C2"]), st.integers(0, 7))


class Killed(BaseException):
    """The run stopped dead after writing a part (kill -9 between a part and the table)."""


@pytest.fixture(scope="module")
def pool(tmp_path_factory):
    """Records of distinct contents to add to the archive."""
    root = tmp_path_factory.mktemp("pool")
    options = ArchiveOptions(days=4 / 48, interval=1800, duration=10, sampling_rate=50, sensors=(0.3,))
    arch = simulate_archive({"P": _campaign(root / "campaign")}, root / "archive", options=options, seed=23)
    return records(arch, "P")


def _apply(operation, archive: Path, out: Path, pool: list[Path], step: int) -> None:
    kind, cable, k = operation
    mine = records(archive, cable)
    other = records(archive, "C2" if cable == "C1" else "C1")
    if kind == "add":
        shutil.copy(pool[k % len(pool)], archive / cable / "records" / f"added-{step}.h5")
    elif kind == "remove" and mine:
        mine[k % len(mine)].unlink()
    elif kind == "modify" and mine:
        with h5py.File(mine[k % len(mine)], "r+") as h5:
            h5.attrs["temperature"] = 10.0 + k + 0.5 * step  # another content each time
    elif kind == "copy" and other:
        shutil.copy(other[k % len(other)], archive / cable / "records" / f"copied-{step}.h5")
    elif kind == "campaign":
        toml = archive / cable / "campaign.toml"
        text = toml.read_text()
        toml.write_text(text.replace("mass_per_length = 30.0", "mass_per_length = 31.5") if "= 30.0" in text
                        else text.replace("mass_per_length = 31.5", "mass_per_length = 30.0"))
    elif kind == "corrupt":
        parts = sorted((out / "parts").glob("*.parquet")) if out.exists() else []
        if parts:
            part = parts[k % len(parts)]
            part.write_bytes(part.read_bytes()[: 50 * k])  # truncated, or empty for k = 0
    elif kind == "kill":
        api = importlib.import_module("stcs_ident.track.api")  # the module (stcs_ident.track is also a function)

        def killed(out_, rows):
            append_part(out_, rows)
            raise Killed
        with h5py.File(mine[0], "r+") if mine else _nothing() as h5:  # something to do for the killed run
            if h5 is not None:
                h5.attrs["temperature"] = 40.0 + step
        original = api.append_part
        api.append_part = killed
        try:
            track(archive, out, batch=1)
        except Killed:
            pass
        finally:
            api.append_part = original


class _nothing:
    def __enter__(self):
        return None

    def __exit__(self, *exc):
        return False


@pytest.mark.slow
def test_reruns_after_any_sequence_of_changes_give_the_table_of_a_first_run(pristine, pool, tmp_path_factory):
    """Random sequences of archive operations (add, remove, modify, copy into another cable, edit a campaign,
    corrupt a part, kill a run after a part), each followed by a rerun: the last table is that of a first run
    on the final archive (every column that says what a row is)."""

    @hypothesis.settings(max_examples=15, deadline=None, database=None, derandomize=True,
                         suppress_health_check=[hypothesis.HealthCheck.too_slow])
    @hypothesis.given(st.lists(OPERATIONS, min_size=1, max_size=5))
    def check(operations):
        root = tmp_path_factory.mktemp("run")
        archive = Path(shutil.copytree(pristine, root / "archive"))
        out = root / "out"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TrackWarning)  # the corrupted parts: reported, and rebuilt
            track(archive, out)
            for step, operation in enumerate(operations):
                _apply(operation, archive, out, pool, step)
                rerun = track(archive, out, batch=2)
            assert rerun.counts["unchanged"] + rerun.counts["new"] + rerun.counts["changed"] + \
                rerun.counts["stale"] + rerun.counts["retried"] == len(rerun.table)
            assert not rerun.table.duplicated(["cable", "record"]).any()
            assert_same_table(rerun.table, track(archive, root / "clean").table)
            assert track(archive, out).counts["unchanged"] == len(rerun.table)  # and the next rerun has nothing to do
        shutil.rmtree(root)

    check()


def test_every_cable_is_in_the_report_whatever_its_state(archive, tmp_path, capsys):
    """One good record (C1), all failed (C2), no record yet (C3): each its row in cables.csv, its line in
    report.md, its figure."""
    for path in records(archive, "C1")[1:]:
        path.unlink()
    for i, path in enumerate(records(archive, "C2")):
        path.write_text(f"not a record {i}\n")
    shutil.copytree(archive / "C2", archive / "C3", ignore=shutil.ignore_patterns("records"))
    out = tmp_path / "out"
    assert main(["track", str(archive), "--out", str(out)]) == 0
    cables = pd.read_csv(out / "cables.csv").set_index("cable")
    assert list(cables.index) == ["C1", "C2", "C3"]
    assert cables[["n_records", "n_processed", "n_failed"]].to_dict("index") == {
        "C1": {"n_records": 1, "n_processed": 1, "n_failed": 0},
        "C2": {"n_records": 3, "n_processed": 0, "n_failed": 3},
        "C3": {"n_records": 0, "n_processed": 0, "n_failed": 0}}
    report = (out / "report.md").read_text()
    for line in ("| C1 | 1 | 1 | 0 |", "| C2 | 3 | 0 | 3 |", "| C3 | 0 | 0 | 0 |", "[C3](C3.png)"):
        assert line in report
    assert {"C1.png", "C2.png", "C3.png"} <= {p.name for p in out.iterdir()}


def test_the_cli_says_what_a_rerun_did_and_warns_once_of_a_damaged_part(archive, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["track", str(archive), "--out", str(out)]) == 0
    assert "track: 6 new, 0 changed, 0 stale, 0 removed, 0 retried, 0 unchanged" in capsys.readouterr().err
    next((out / "parts").glob(cable_key("C1") + "-*")).write_bytes(b"PAR1")  # C1's rows lost
    records(archive, "C2")[0].unlink()
    assert main(["track", str(archive), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert err.count("stcs-ident: warning:") == 1 and "cannot be read" in err and "Traceback" not in err
    assert "track: 3 new, 0 changed, 0 stale, 1 removed, 0 retried, 2 unchanged" in err
    assert main(["track", str(archive), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning" not in err and "track: 0 new, 0 changed, 0 stale, 0 removed, 0 retried, 5 unchanged" in err
