"""Every output goes through one writer: whole or not at all, on disk before the rename, with the
permissions a plain open() would give (from the umask), figures included."""

import os
import stat

import pandas as pd
import pytest

from stcs_ident.core import files


@pytest.fixture
def umask_027():
    old = os.umask(0o027)
    yield 0o640
    os.umask(old)


def _mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def test_text_csv_and_figures_get_the_mode_of_the_umask(tmp_path, umask_027):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(2, 2))
    fig.subplots().plot([0, 1], [1, 0])
    files.write_atomic(tmp_path / "a.json", "{}\n")
    files.write_csv(pd.DataFrame({"x": [1.5, 2.0]}), tmp_path / "t.csv", index=False)
    files.write_figure(fig, tmp_path / "f.png")
    assert (tmp_path / "a.json").read_text() == "{}\n"
    assert (tmp_path / "t.csv").read_text() == "x\n1.5\n2.0\n"
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert {p.name: _mode(p) for p in tmp_path.iterdir()} == {"a.json": umask_027, "t.csv": umask_027,
                                                               "f.png": umask_027}


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError, match="midway"), files.atomic_file(target) as stream:
        stream.write("new, half")
        raise RuntimeError("midway")
    assert target.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_the_report_files_get_the_mode_of_the_umask(tmp_path, umask_027):
    from matplotlib.figure import Figure

    from stcs_ident.report.identify_tables import write_csv
    from stcs_ident.report.plots import save_figure

    class Result:  # only what write_csv reads
        def to_dataframe(self):
            return pd.DataFrame({"mode": [1], "measured_Hz": [1.0]})

    write_csv(Result(), tmp_path / "table.csv")
    save_figure(Figure(figsize=(1, 1)), tmp_path / "fig.png")
    assert _mode(tmp_path / "table.csv") == _mode(tmp_path / "fig.png") == umask_027


def _dead_pid() -> int:
    import subprocess
    import sys

    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_later_write_removes_what_killed_runs_left_and_nothing_else(tmp_path):
    """A run killed outright cannot remove its temporary files; the next one writing there does, when their
    process is gone. A live process's (this one's), another host's and the user's own hidden files stay."""
    host = files._host()
    dead = _dead_pid()
    stale_file = tmp_path / f".out.json.stcs~{host}~{dead}~abc123"
    stale_dir = tmp_path / f".report.stcs~{host}~{dead}~xyz.tmp"
    stale_file.write_text("half")
    stale_dir.mkdir()
    (stale_dir / "report.md").write_text("half")
    kept = [tmp_path / f".out.json.stcs~{host}~{os.getpid()}~live", tmp_path / f".x.stcs~otherhost~{dead}~q",
            tmp_path / ".hidden", tmp_path / f".out.json.{dead}.tmp"]
    for path in kept:
        path.write_text("keep")
    files.write_atomic(tmp_path / "out.json", "{}\n")
    assert not stale_file.exists() and not stale_dir.exists()
    assert all(path.exists() for path in kept)
    assert (tmp_path / "out.json").read_text() == "{}\n"


@pytest.mark.slow
def test_simulate_killed_at_any_moment_leaves_nothing_half_written(tmp_path):
    """`simulate --out` killed (SIGKILL) at several moments: its output is absent or complete, never half;
    the hidden temporaries it leaves are removed by the next run, which completes the same output."""
    import json
    import signal
    import subprocess
    import sys
    import time

    from tests.fuzz_inputs import BASE_TOML, _frequencies

    campaign = tmp_path / "c"
    campaign.mkdir()
    (campaign / "campaign.toml").write_text(BASE_TOML.replace('record = "records/T2.h5"\n', "")
                                            .format(f=_frequencies()), encoding="utf-8")
    out = tmp_path / "sim"
    command = [sys.executable, "-c", "import sys; from stcs_ident.cli.main import main; sys.exit(main(sys.argv[1:]))",
               "simulate", str(campaign), "--out", str(out), "--duration", "20", "--overwrite"]
    assert subprocess.run(command, check=False, capture_output=True).returncode == 0
    expected = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    truth = json.loads((out / "truth.json").read_text())
    left = 0
    for delay in (0.0, 0.02, 0.05, 0.1, 0.2, 0.4):  # after its temporary output appears: during the writing
        child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        while child.poll() is None and not any(".stcs~" in p.name for p in tmp_path.iterdir()):
            time.sleep(0.002)
        time.sleep(delay)
        child.send_signal(signal.SIGKILL)
        child.wait()
        assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == expected  # old or new, whole
        assert json.loads((out / "truth.json").read_text()) == truth  # seeded: the same either way
        left += sum(".stcs~" in p.name for p in tmp_path.iterdir())
    assert subprocess.run(command, check=False, capture_output=True).returncode == 0
    assert [p.name for p in tmp_path.iterdir() if ".stcs~" in p.name] == []
    assert left > 0  # some kill did land mid-write: the test saw what it is about


def test_an_old_output_moved_aside_by_a_killed_run_is_put_back(tmp_path):
    """Killed between moving the old report aside and renaming the new one in: the next run restores it."""
    aside = tmp_path / f".report.stcs~{files._host()}~{_dead_pid()}~k3.old"
    (aside / "previous").mkdir(parents=True)
    (aside / "previous" / "report.md").write_text("the old report")
    files.write_atomic(tmp_path / "other.json", "{}\n")
    assert (tmp_path / "report" / "report.md").read_text() == "the old report"
    assert not aside.exists()
