"""Issue 23, items 2, 4 and 5: one rule for times; no traceback for an output that cannot be written, a
Ctrl-C, a bad scheduler or a killed parent; an output never renamed over what is not a regular file."""

from __future__ import annotations

import errno
import importlib
import os
import signal
import socket
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import h5py
import pytest

from stcs_ident.cli.main import main
from stcs_ident.core import files
from stcs_ident.core.errors import InputError
from stcs_ident.core.times import check_instant, instant_problem
from stcs_ident.io.campaign import load_campaign
from stcs_ident.simulate.archive import ArchiveOptions, simulate_archive
from stcs_ident.track import execution
from stcs_ident.track.api import track
from tests.fuzz_inputs import BASE_TOML, _frequencies, write_base_campaign

# ---------------------------------------------------------------------------------------------------------
# Fixtures: a small campaign with one record, a small archive.


@pytest.fixture
def campaign(tmp_path):
    return write_base_campaign(tmp_path / "campaign")


def _archive(root: Path, days: float) -> Path:
    directory = root / "campaign"
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "campaign.toml").write_text(BASE_TOML.replace('record = "records/T2.h5"\n', "")
                                             .format(f=_frequencies()), encoding="utf-8")
    simulate_archive({"C1": load_campaign(directory)}, root / "archive",
                     options=ArchiveOptions(days=days, interval=3600), seed=1)
    return root / "archive"


@pytest.fixture
def archive(tmp_path):
    return _archive(tmp_path, 0.25)  # 6 hourly records: a track run of about a second


def _one_line(err: str) -> None:
    """Standard error is one line of the toolkit and no traceback."""
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if line.startswith("stcs-ident:")]
    assert len(lines) == 1, err


# ---------------------------------------------------------------------------------------------------------
# Item 2: one rule for times.

@pytest.mark.parametrize("text", ["2026-W10-2", "2026-063", "20260301T100000Z", "0001-01-01T00:00:00",
                                  "9999-12-31T23:59:59.999999999+00:00", "2300-01-01T00:00:00.123456789Z",
                                  "2026-02-30T10:00:00", "1677-09-21T23:59:59Z", "2262-04-11T00:00:00Z",
                                  "yesterday", ""])
def test_the_time_rule_refuses_what_the_table_cannot_hold(text):
    assert instant_problem(text) is not None
    with pytest.raises(InputError, match="start_time"):
        check_instant(text)


@pytest.mark.parametrize("text", ["2026-03-01T10:00:00.123456789+00:00", "2026-03-01T10:00:00Z", "2026-03-01",
                                  "2026-03-01 10:00", "1677-09-22T00:00:00Z", "2262-04-10T23:59:59.999999999Z"])
def test_the_time_rule_accepts_a_calendar_instant_in_range(text):
    assert instant_problem(text) is None


def test_a_record_with_a_bad_time_is_a_failed_row_with_its_reason_and_reruns_cleanly(archive, tmp_path):
    paths = sorted((archive / "C1" / "records").rglob("*.h5"))
    bad = {paths[0]: "2026-W10-2", paths[1]: "0001-01-01T00:00:00", paths[2]: "9999-12-31T23:59:59+00:00",
           paths[3]: "2300-01-01T00:00:00.123456789+00:00"}
    with h5py.File(paths[4], "a") as h5:  # a good time to the nanosecond, beside them
        h5.attrs["start_time"] = "2026-03-01T04:00:00.123456789+00:00"
    for path, text in bad.items():
        with h5py.File(path, "a") as h5:
            h5.attrs["start_time"] = text
    for _ in range(2):  # the rerun too: no traceback, the same rows
        table = track(archive, tmp_path / "out").table
        rows = table.set_index("record")
        for path, text in bad.items():
            row = rows.loc[path.relative_to(archive / "C1").as_posix()]
            assert row["status"] == "failed" and "start_time" in row["reason"] and text in row["reason"]
        ok = table[table["status"] == "ok"]
        assert len(ok) == 2 and ok["start_time"].notna().all()
        assert rows.loc[paths[4].relative_to(archive / "C1").as_posix(), "start_time"].nanosecond == 789


def test_the_record_format_start_time_option_follows_the_rule():
    from stcs_ident.io.records.options import option_problem

    assert option_problem("start_time", "2026-W10-2") is not None
    assert option_problem("start_time", "2300-01-01T00:00:00") is not None
    assert option_problem("start_time", "2026-03-01T00:00:00") is None


# ---------------------------------------------------------------------------------------------------------
# Item 5: never renamed over what is not a regular file.

def test_json_onto_a_fifo_is_written_as_a_stream(campaign, tmp_path, capsys):
    fifo = tmp_path / "result.fifo"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()), daemon=True)
    reader.start()
    assert main(["forward", str(campaign), "--json", str(fifo)]) == 0
    reader.join(timeout=30)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert got and got[0].lstrip().startswith("{") and '"campaign"' in got[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["campaign", "result.fifo"]  # no temporary left


@pytest.fixture
def null_device(tmp_path):
    """A character device that discards what is written: as root a null device made in ``tmp_path`` (a wrong
    writer run as root would replace the system's /dev/null, which this very test once did), otherwise
    /dev/null itself (which a user cannot replace: /dev is not theirs)."""
    if os.geteuid() != 0:
        return Path("/dev/null")
    path = tmp_path / "null"
    os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    return path


def test_json_onto_a_device_leaves_the_device(null_device, campaign, capsys):
    before = os.stat(null_device)
    assert main(["forward", str(campaign), "--json", str(null_device)]) == 0
    after = os.stat(null_device)
    assert stat.S_ISCHR(after.st_mode) and (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)


@pytest.mark.parametrize("argv", [["forward", "{c}"], ["spectra", "{c}"], ["identify", "{c}", "--test", "T1"],
                                  ["diagnose", "{c}", "--test", "T1"],
                                  ["tension", "--length", "19.715", "--mass", "16.6", "--frequencies", "7.24,14.42,21.77"]])
def test_every_command_writes_its_json_into_a_device_and_through_a_link(argv, null_device, campaign, tmp_path,
                                                                        capsys):
    argv = [a.format(c=campaign) for a in argv]
    before = os.stat(null_device)
    assert main([*argv, "--json", str(null_device)]) == 0
    after = os.stat(null_device)
    assert stat.S_ISCHR(after.st_mode) and (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)
    target, link = tmp_path / "real.json", tmp_path / "link.json"
    link.symlink_to(target)
    assert main([*argv, "--json", str(link)]) == 0
    assert link.is_symlink() and target.read_text().lstrip().startswith("{")


def test_every_writer_streams_into_a_device(null_device):
    import pandas as pd
    from matplotlib.figure import Figure

    files.write_atomic(null_device, "{}\n")
    files.write_csv(pd.DataFrame({"x": [1.0]}), null_device)
    files.write_figure(Figure(figsize=(1, 1)), null_device)
    assert stat.S_ISCHR(os.stat(null_device).st_mode)
    assert not list(null_device.parent.glob(f".{null_device.name}*"))  # no temporary left


def test_json_onto_a_symlink_is_written_through_it(campaign, tmp_path, capsys):
    target, link = tmp_path / "real.json", tmp_path / "link.json"
    target.write_text("old")
    link.symlink_to(target)
    assert main(["forward", str(campaign), "--json", str(link)]) == 0
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert '"campaign"' in target.read_text()
    dangling = tmp_path / "dangling.json"
    dangling.symlink_to(tmp_path / "new.json")
    files.write_atomic(dangling, "{}\n")
    assert dangling.is_symlink() and (tmp_path / "new.json").read_text() == "{}\n"


def test_track_json_onto_a_symlink_and_a_fifo(archive, tmp_path, capsys):
    target, link, fifo = tmp_path / "real.json", tmp_path / "link.json", tmp_path / "summary.fifo"
    link.symlink_to(target)
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()), daemon=True)
    reader.start()
    assert main(["track", str(archive), "--out", str(tmp_path / "o"), "--json", str(link)]) == 0
    assert main(["track", str(archive), "--out", str(tmp_path / "o"), "--json", str(fifo)]) == 0
    reader.join(timeout=30)
    assert link.is_symlink() and '"cables"' in target.read_text()
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and got and '"cables"' in got[0]


def test_a_symlinked_output_directory_stays_a_link(campaign, tmp_path, capsys):
    real, link = tmp_path / "real_dir", tmp_path / "link_dir"
    real.mkdir()
    link.symlink_to(real)
    assert main(["simulate", str(campaign), "--out", str(link)]) == 0
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert (real / "campaign.toml").is_file()


def test_an_output_that_is_a_directory_or_a_socket_is_refused_before_any_work(campaign, tmp_path, capsys):
    assert main(["forward", str(campaign), "--json", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    _one_line(err)
    assert "--json" in err and "is a directory" in err
    server = socket.socket(socket.AF_UNIX)
    path = tmp_path / "s.sock"
    server.bind(str(path))
    try:
        with pytest.raises(InputError, match="socket"):
            files.write_atomic(path, "x")
        assert stat.S_ISSOCK(os.lstat(path).st_mode)
    finally:
        server.close()


# ---------------------------------------------------------------------------------------------------------
# Item 4: every OS error on an output is one line naming the path.

def _full_disk(monkeypatch):
    def no_space(path):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(files, "_fsync", no_space)


@pytest.mark.parametrize("command, option, name", [
    (["forward", "{c}"], "--json", "result.json"),
    (["spectra", "{c}", "--plot"], None, "plots"),
    (["identify", "{c}", "--test", "T1", "--plot"], None, "plots"),
    (["diagnose", "{c}", "--test", "T1", "--out"], None, "report"),
    (["simulate", "{c}", "--out"], None, "simulated"),
])
def test_a_full_disk_is_one_line_naming_the_path(command, option, name, campaign, tmp_path, monkeypatch, capsys):
    _full_disk(monkeypatch)
    out = tmp_path / name
    argv = [a.format(c=campaign) for a in command] + ([option] if option else []) + [str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    _one_line(err)
    assert "No space left on device" in err and str(out) in err
    assert not [p for p in tmp_path.rglob(".*stcs~*")]  # no temporary left behind


def test_track_on_a_full_disk_is_one_line(archive, tmp_path, monkeypatch, capsys):
    _full_disk(monkeypatch)
    out = tmp_path / "out"
    assert main(["track", str(archive), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    _one_line(err)
    assert "No space left on device" in err and str(out) in err


def test_a_read_only_output_is_refused_before_any_work(campaign, tmp_path, monkeypatch, capsys):
    # Root ignores permissions, so the system's answer is simulated: the output's directory is not writable.
    locked = tmp_path / "locked"
    locked.mkdir()
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda p, mode, **k: False if Path(p) == locked else real_access(p, mode, **k))
    analysed = []
    # Patched where the spectra command looks it up: patching only cli.common's name would, when cli.spectra is
    # first imported during this test, bind the stub into cli.spectra for the rest of the process (every later
    # `spectra` in this worker then picked nothing: test_refusals' link tests failed under -n 2, in that order).
    monkeypatch.setattr(importlib.import_module("stcs_ident.cli.spectra"), "picked_spectra",
                        lambda *a: analysed.append(1) or [])
    for argv, option in ((["spectra", str(campaign), "--plot", str(locked / "plots")], "--plot"),
                         (["forward", str(campaign), "--json", str(locked / "r.json")], "--json"),
                         (["simulate", str(campaign), "--out", str(locked / "sim")], "--out")):
        assert main(argv) == 2
        err = capsys.readouterr().err
        _one_line(err)
        assert option in err and "not writable" in err
    assert not analysed


def test_an_output_whose_directory_is_gone_is_one_error_naming_it(tmp_path):
    gone = tmp_path / "gone" / "result.json"
    with pytest.raises(files.OutputError, match="cannot write") as caught:
        files.write_atomic(gone, "{}\n")
    assert caught.value.file == str(gone)


def test_a_read_only_track_output_is_refused_before_any_record(archive, tmp_path, monkeypatch, capsys):
    # Root ignores permissions, so the system's answer is simulated.
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda p, mode, **k: False if Path(p) == tmp_path else real_access(p, mode, **k))
    hashed = []
    monkeypatch.setattr(sys.modules["stcs_ident.track.api"], "content_id", lambda path: hashed.append(path) or "x")
    assert main(["track", str(archive), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    _one_line(err)
    assert "--out" in err and "not writable" in err and not hashed


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a read-only directory")
def test_a_really_read_only_directory_is_one_line(campaign, tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        assert main(["forward", str(campaign), "--json", str(locked / "r.json")]) == 2
        _one_line(capsys.readouterr().err)
    finally:
        locked.chmod(0o700)


def test_a_read_only_file_system_during_the_rename_is_one_line(campaign, tmp_path, monkeypatch, capsys):
    def read_only(src, dst):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(src), None, str(dst))
    monkeypatch.setattr(files.os, "replace", read_only)
    target = tmp_path / "r.json"
    assert main(["forward", str(campaign), "--json", str(target)]) == 2
    err = capsys.readouterr().err
    _one_line(err)
    assert "Read-only file system" in err and str(target) in err
    assert not list(tmp_path.glob(".r.json*"))


# ---------------------------------------------------------------------------------------------------------
# Item 4: the scheduler.

def test_a_malformed_scheduler_is_refused_at_once(archive, tmp_path, capsys):
    import stcs_ident.cli.track  # noqa: F401  (imported before the clock starts: the check is what is timed)

    started = time.perf_counter()
    assert main(["track", str(archive), "--out", str(tmp_path / "o"), "--scheduler", "notaurl"]) == 2
    elapsed = time.perf_counter() - started
    err = capsys.readouterr().err
    _one_line(err)
    assert "--scheduler" in err and "notaurl" in err
    assert elapsed < 1.0  # "at once": no connection tried (before: a 20 s hang)
    assert not (tmp_path / "o").exists()  # before any work


@pytest.mark.parametrize("address, parsed", [("tcp://10.0.0.5:8786", ("tcp", "10.0.0.5", 8786)),
                                             ("host-1.example:8786", ("tcp", "host-1.example", 8786)),
                                             ("tls://[::1]:8786", ("tls", "::1", 8786))])
def test_a_scheduler_address_is_read(address, parsed):
    assert execution.check_scheduler(address) == parsed


@pytest.mark.parametrize("address", ["notaurl", "tcp://host", "tcp://host:0", "tcp://host:65536", "http://h:80",
                                     "tcp://:8786", "tcp://host:8786/x", ""])
def test_a_malformed_scheduler_address_is_refused(address):
    with pytest.raises(InputError, match="--scheduler"):
        execution.check_scheduler(address)


def test_nothing_listening_is_refused_at_once(archive, tmp_path, capsys):
    with socket.create_server(("127.0.0.1", 0)) as server:
        port = server.getsockname()[1]  # a port that was free, closed now: nothing listens there
    assert main(["track", str(archive), "--out", str(tmp_path / "o"), "--scheduler", f"127.0.0.1:{port}"]) == 2
    err = capsys.readouterr().err
    _one_line(err)
    assert "cannot reach" in err and not (tmp_path / "o").exists()


@pytest.mark.parametrize("greeting", [b"", b"SSH-2.0-OpenSSH_9.6\r\n"])
def test_a_service_that_is_not_dask_is_refused_within_the_timeout(greeting, archive, tmp_path, monkeypatch,
                                                                  capsys):
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    held = []

    def serve():
        while True:
            try:
                conn, _ = server.accept()
            except OSError:
                return
            held.append(conn)
            conn.sendall(greeting)

    threading.Thread(target=serve, daemon=True).start()
    monkeypatch.setattr(execution, "CONNECT_TIMEOUT", 1.0)
    try:
        started = time.perf_counter()
        status = main(["track", str(archive), "--out", str(tmp_path / "o"), "--scheduler", f"tcp://127.0.0.1:{port}"])
        elapsed = time.perf_counter() - started
    finally:
        server.close()
        for conn in held:
            conn.close()
    assert status == 2
    err = capsys.readouterr().err
    _one_line(err)
    assert "--scheduler" in err
    assert elapsed < 5.0  # the 1 s timeout, and the import of the command (before: no end)


# ---------------------------------------------------------------------------------------------------------
# Item 4: Ctrl-C and a killed parent (subprocesses).

def _command(*args) -> list[str]:
    """The command in a child Python with Ctrl-C as a terminal gives it: a process started in the background by
    a non-interactive shell (``nohup``, ``cmd &``, some CI runners) inherits SIGINT ignored, and the command
    rightly keeps an ignored SIGINT ignored; these tests are about what a pressed Ctrl-C does."""
    start = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
             "from stcs_ident.cli.main import main; sys.exit(main())")
    return [sys.executable, "-P", "-c", start, *args]  # -P: the installed package, not a checkout's source tree


@pytest.fixture
def sigint_default():
    """Python's own SIGINT handler in this process for the test (see :func:`_command`), the former one after."""
    former = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, former)


def _children(pid: int) -> set[int]:
    """Every live descendant of ``pid`` (Linux /proc)."""
    out, todo = set(), [pid]
    while todo:
        parent = todo.pop()
        for task in Path(f"/proc/{parent}/task").glob("*"):
            try:
                kids = (task / "children").read_text().split()
            except OSError:
                continue
            for kid in map(int, kids):
                if kid not in out:
                    out.add(kid)
                    todo.append(kid)
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _wait_for_parts(out: Path, process, timeout: float = 60) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if (out / "parts").is_dir() and any(p.name.endswith(".parquet") and not p.name.startswith(".")
                                            for p in (out / "parts").iterdir()):
            return
        assert process.poll() is None, "track ended before the signal"
        time.sleep(0.05)
    raise AssertionError("no part written in time")


@pytest.fixture(scope="module")
def long_archive(tmp_path_factory):
    return _archive(tmp_path_factory.mktemp("long"), 3)  # 72 records, 5 batches: a few seconds on 2 workers


@pytest.mark.slow  # 5-40 s on two shared cores: the run, the Ctrl-C, the rerun that finishes the archive
@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux /proc")
@pytest.mark.parametrize("workers", ["1", "2"])
def test_ctrl_c_stops_with_one_line_and_keeps_the_parts(workers, long_archive, tmp_path):
    out = tmp_path / "out"
    process = subprocess.Popen(_command("track", str(long_archive), "--out", str(out), "--workers", workers),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_parts(out, process)
    children = _children(process.pid)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    _one_line(err)  # beside the progress lines ("track: 16 of 72 records, ...")
    assert "interrupted" in err
    parts = [p for p in (out / "parts").iterdir() if not p.name.startswith(".")]
    assert parts  # the work already written is kept
    time.sleep(0.5)
    assert not [pid for pid in children if _alive(pid)]
    if workers == "1":  # the rerun that finishes the archive from the parts kept: once (most of the test's time)
        return
    rerun = subprocess.run(_command("track", str(long_archive), "--out", str(out)), capture_output=True, text=True,
                           check=False,
                           timeout=300)
    assert rerun.returncode == 0 and "72 of 72 records with a tension" in rerun.stdout


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux /proc")
def test_killing_the_parent_leaves_no_worker(long_archive, tmp_path):
    out = tmp_path / "out"
    process = subprocess.Popen(_command("track", str(long_archive), "--out", str(out), "--workers", "2"),
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _wait_for_parts(out, process)
    children = _children(process.pid)
    assert len(children) >= 2  # the two workers (and the executor's helpers)
    process.kill()
    process.wait()
    deadline = time.monotonic() + 5  # "within a few seconds": the watcher checks every 0.5 s
    while time.monotonic() < deadline and [pid for pid in children if _alive(pid)]:
        time.sleep(0.1)
    assert not [pid for pid in children if _alive(pid)]


# ---------------------------------------------------------------------------------------------------------
# Control characters in names never reach the terminal raw.

def test_control_characters_in_a_test_name_are_escaped(campaign, capsys):
    toml = campaign / "campaign.toml"
    toml.write_text(toml.read_text().replace('name = "T1"', 'name = "T1\\u001b[31mred"'), encoding="utf-8")
    status = main(["forward", str(campaign)])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert "\x1b" not in out + err and "\\x1b[31mred" in out


@pytest.fixture(scope="module")
def dask_scheduler():
    """The address of a local Dask cluster (one worker process) running in a subprocess."""
    pytest.importorskip("distributed")
    code = ("import sys, time\nfrom distributed import LocalCluster\nif __name__ == '__main__':\n"
            "    c = LocalCluster(n_workers=1, threads_per_worker=2, processes=True, dashboard_address=None)\n"
            "    print(c.scheduler_address, flush=True)\n    sys.stdin.read()\n")
    cluster = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, text=True)
    address = cluster.stdout.readline().strip()
    yield address
    cluster.stdin.close()  # the cluster ends when its input does
    try:
        cluster.wait(timeout=30)
    except subprocess.TimeoutExpired:
        cluster.kill()
        cluster.wait()
    cluster.stdout.close()


@pytest.mark.slow
def test_ctrl_c_on_dask_stops_with_one_line_and_keeps_the_parts(dask_scheduler, long_archive, tmp_path):
    assert dask_scheduler.startswith("tcp://")
    out = tmp_path / "out"
    process = subprocess.Popen(_command("track", str(long_archive), "--out", str(out), "--scheduler", dask_scheduler),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for_parts(out, process, timeout=120)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    _one_line(err)
    assert "interrupted" in err
    assert [p for p in (out / "parts").iterdir() if not p.name.startswith(".")]


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_ctrl_c_lost_in_a_finaliser_is_still_said(campaign, monkeypatch, capsys, sigint_default):
    import stcs_ident.cli.forward

    class Finalised:
        def __del__(self):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.2)  # the handler runs here, inside __del__: Python prints its KeyboardInterrupt as ignored

    def run(args):
        Finalised()
        return 0

    monkeypatch.setattr(stcs_ident.cli.forward, "run", run)
    assert main(["forward", str(campaign)]) == 130
    _one_line(capsys.readouterr().err)


def test_json_on_standard_output_stays_valid_json_whatever_the_names(campaign, capsys):
    import json

    toml = campaign / "campaign.toml"
    toml.write_text(toml.read_text().replace('name = "T1"', 'name = "T1\\u001b\\u007f"'), encoding="utf-8")
    assert main(["forward", str(campaign), "--json", "-"]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out
    assert json.loads(out)["tests"][0]["name"] == "T1\x1b\x7f"
