"""Record readers behind one interface (stcs_ident.io.records): chosen by suffix or content, one registry.

The three built-in formats give the same record for the same data; an unknown
format is refused in one line naming the file; and a toy format (``.npz``)
registered here, with one call, is read by ``spectra`` through a campaign and
by ``track`` through its archive, as the built-in ones are.
"""

from __future__ import annotations

import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from stcs_ident.core.errors import InputError
from stcs_ident.core.record import Record
from stcs_ident.io.campaign import campaign_to_toml, load_campaign
from stcs_ident.io.records import RecordReader, read_record, reader_for, readers, record_suffixes, register, unregister
from stcs_ident.io.records.base import file_head
from stcs_ident.io.records.hdf5 import write_record
from stcs_ident.io.records.sep005 import write_sep005
from stcs_ident.io.records.validation import validated_record
from stcs_ident.simulate.archive import ArchiveOptions, simulate_archive
from stcs_ident.simulate.simulate import Impulse
from stcs_ident.simulate.simulate_campaign import simulate_campaign
from stcs_ident.spectra.pipeline import analyse_test
from stcs_ident.track.api import track
from stcs_ident.track.archive import discover, record_paths
from tests.fuzz_inputs import BASE_TOML, _frequencies

FS = 200.0  # Hz
NAMES = ("A1", "A2", "A3")
POSITIONS = (2.0, 5.5, 9.0)  # m from end A
START = "2026-03-01T10:00:00+00:00"
#: Written as text, a sample comes back to within a unit in the last place (pandas' fast float parser), and the
#: sampling rate from the time column's mean step to within a few: far below anything the analysis resolves.
TEXT_RTOL = 1e-13


def _record(n: int = 2000, seed: int = 0) -> Record:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    acceleration = np.column_stack([np.sin(2 * np.pi * (1.3 + j) * t) + 0.1 * rng.standard_normal(n)
                                    for j in range(len(NAMES))])
    return Record(acceleration, FS, NAMES, np.array(POSITIONS), start_time=START)


def _write_csv(record: Record, path: Path) -> Path:
    """A CSV as a data logger writes it: a time column in s, one column per channel (every digit kept)."""
    time = np.arange(record.n_samples) / record.sampling_rate
    lines = [",".join(("time", *record.channel_names))]
    lines += [",".join(repr(float(x)) for x in (t, *row)) for t, row in zip(time, record.acceleration)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _write(record: Record, path: Path) -> Path:
    """``record`` in the format of ``path``'s suffix."""
    {".h5": write_record, ".csv": _write_csv, ".json": write_sep005, ".npz": _write_npz}[path.suffix](record, path)
    return path


# ---------------------------------------------------------------- a toy format, registered from here alone


class NpzReader(RecordReader):
    """A toy format: the contract's datasets as the arrays of a NumPy ``.npz`` (a zip file)."""

    name = "npz-toy"
    suffixes = (".npz",)

    def can_open(self, path) -> bool:
        return file_head(path)[:4] == b"PK\x03\x04"

    def read(self, path, *, positions=None) -> Record:
        with np.load(path) as data:
            start_time = str(data["start_time"]) if "start_time" in data else None
            return validated_record(data["acceleration"], float(data["sampling_rate"]), list(data["channel_name"]),
                                    data["channel_position"], unit="m/s^2", start_time=start_time, source=str(path))


def _write_npz(record: Record, path: Path) -> None:
    extra = {} if record.start_time is None else {"start_time": record.start_time}
    np.savez(path, acceleration=record.acceleration, sampling_rate=record.sampling_rate,
             channel_name=np.array(record.channel_names), channel_position=record.channel_positions, **extra)


@pytest.fixture
def npz():
    """The toy reader, registered for the test (and removed after it)."""
    reader = register(NpzReader())
    yield reader
    unregister(reader.name)


# ---------------------------------------------------------------- the registry


def test_the_built_in_readers_are_registered_with_their_suffixes():
    assert [r.name for r in readers()] == ["hdf5", "csv", "sep005", "matlab", "tdms", "uff", "toa5", "lvm"]
    assert record_suffixes() == (".h5", ".hdf5", ".csv", ".txt", ".json", ".mat", ".tdms", ".uff", ".unv", ".dat",
                                 ".lvm")


@pytest.mark.parametrize(("name", "reader"), [("r.h5", "hdf5"), ("r.HDF5", "hdf5"), ("r.csv", "csv"),
                                              ("r.txt", "csv"), ("r.json", "sep005"), ("r.mat", "matlab"),
                                              ("r.tdms", "tdms"), ("r.UFF", "uff"), ("r.unv", "uff"),
                                              ("r.dat", "toa5"), ("r.LVM", "lvm")])
def test_the_suffix_picks_the_reader_without_opening_the_file(tmp_path, name, reader):
    assert reader_for(tmp_path / name).name == reader  # the file does not exist: the suffix alone decided


@pytest.mark.parametrize(("suffix", "reader"), [(".h5", "hdf5"), (".csv", "csv"), (".json", "sep005")])
def test_the_content_picks_the_reader_when_the_suffix_says_nothing(tmp_path, suffix, reader):
    record = _record()
    path = _write(record, tmp_path / f"r{suffix}").rename(tmp_path / "r.dat")
    assert reader_for(path).name == reader
    back = read_record(path, positions=dict(zip(NAMES, POSITIONS)))
    np.testing.assert_allclose(back.acceleration, record.acceleration, rtol=TEXT_RTOL, atol=0)
    assert back.source == str(path)


def test_an_unknown_format_is_refused_in_one_line_naming_the_file(tmp_path):
    path = tmp_path / "r.xyz"
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(InputError) as excinfo:
        read_record(path)
    text = str(excinfo.value)
    assert "\n" not in text and text.startswith(f"{path}: not a record format")
    assert excinfo.value.field is None and excinfo.value.file == str(path)
    assert all(r.name in text for r in readers())  # and says which formats there are
    with pytest.raises(InputError, match="file not found") as excinfo:
        read_record(tmp_path / "missing.xyz")
    assert excinfo.value.file == str(tmp_path / "missing.xyz")


def test_each_format_keeps_its_own_refusals(tmp_path):
    """The registry only dispatches: a format's own checks and messages are those of its reader."""
    text = tmp_path / "r.h5"
    text.write_text("time,a\n0,1\n")
    with pytest.raises(InputError, match="not an HDF5 file"):
        read_record(text)
    with pytest.raises(InputError, match=r"no position for channel 'A1'.*\[test.channels\]") as excinfo:
        read_record(_write_csv(_record(), tmp_path / "r.csv"))
    assert excinfo.value.field == "channel_position" and excinfo.value.file == str(tmp_path / "r.csv")
    (tmp_path / "bad.json").write_text('{"data": [1, 2]}')
    with pytest.raises(InputError, match="must be a JSON list") as excinfo:
        read_record(tmp_path / "bad.json")
    assert excinfo.value.file == str(tmp_path / "bad.json")


def test_register_refuses_a_second_reader_of_a_name_and_a_bad_suffix(npz):
    with pytest.raises(ValueError, match="registered already"):
        register(NpzReader())
    bad = NpzReader()
    bad.name, bad.suffixes = "other", ("npz",)
    with pytest.raises(TypeError, match="suffixes"):
        register(bad)
    assert [r.name for r in readers()][-1] == "npz-toy" and len(readers()) == 9


# ---------------------------------------------------------------- one record, every format


@pytest.mark.parametrize("suffix", [".h5", ".csv", ".json", ".npz"])
def test_every_format_gives_the_same_record(tmp_path, npz, suffix):
    record = _record()
    back = read_record(_write(record, tmp_path / f"r{suffix}"), positions=dict(zip(NAMES, POSITIONS)))
    exact = suffix != ".csv"  # binary, or JSON's shortest round-tripping repr: bit for bit
    np.testing.assert_allclose(back.acceleration, record.acceleration, rtol=0 if exact else TEXT_RTOL, atol=0)
    np.testing.assert_allclose(back.sampling_rate, FS, rtol=0 if exact else TEXT_RTOL)
    assert back.channel_names == NAMES and back.dropped == ()
    np.testing.assert_array_equal(back.channel_positions, POSITIONS)
    assert back.start_time == (None if suffix == ".csv" else START)  # a CSV's time column is in seconds


# ---------------------------------------------------------------- through a campaign and an archive


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """The fuzzer's hanger with its test T2 recorded (HDF5) by the simulator: blows, 20 s at 256 Hz."""
    root = tmp_path_factory.mktemp("readers")
    (root / "nominal").mkdir()
    (root / "nominal" / "campaign.toml").write_text(BASE_TOML.format(f=_frequencies()), encoding="utf-8")
    nominal = load_campaign(root / "nominal")
    return simulate_campaign(nominal, root / "sim", positions=[1.9, 4.1, 5.7], duration=20.0, sampling_rate=256.0,
                             tests=["T2"], impulses=[Impulse(0.5, 1.3, 5.0), Impulse(9.0, 6.2, 5.0)], snr_db=40.0,
                             seed=4)


@pytest.mark.parametrize("suffix", [".csv", ".json", ".npz"])
def test_spectra_reads_a_test_s_record_in_any_registered_format(simulated, tmp_path, npz, suffix):
    """The campaign names the record; spectra (and so identify and diagnose, which ask it) reads it through
    the registry. A CSV takes its positions from the test's [test.channels]."""
    campaign = load_campaign(simulated)
    test = campaign.test("T2")
    reference = analyse_test(campaign, test)
    record = read_record(Path(simulated) / test.record)
    (tmp_path / "records").mkdir()
    _write(record, tmp_path / "records" / f"T2{suffix}")
    channels = tuple(zip(record.channel_names, record.channel_positions)) if suffix == ".csv" else ()
    other = replace(campaign, tests=(replace(test, record=f"records/T2{suffix}", channels=channels),))
    (tmp_path / "campaign.toml").write_text(campaign_to_toml(other), encoding="utf-8")
    loaded = load_campaign(tmp_path)
    assert loaded.test("T2").channels == channels
    spectra = analyse_test(loaded, loaded.test("T2"))
    assert reference.modes and spectra.modes == reference.modes
    # The same samples (to TEXT_RTOL for CSV) give the same peaks: a relative 1e-10 would be 1e-9 Hz.
    np.testing.assert_allclose(spectra.frequencies, reference.frequencies, rtol=0 if suffix != ".csv" else 1e-10)


def test_track_globs_and_reads_a_registered_format(tmp_path, npz):
    """A record of the archive rewritten as the toy format is found by its suffix and gives the same row."""
    root = tmp_path / "nominal"
    root.mkdir()
    (root / "campaign.toml").write_text(BASE_TOML.replace('record = "records/T2.h5"\n', "")
                                        .format(f=_frequencies()), encoding="utf-8")
    archive = simulate_archive({"C1": load_campaign(root)}, tmp_path / "archive",
                               options=ArchiveOptions(days=2 / 24, interval=3600, duration=30.0), seed=5)
    (spec,) = discover(archive)
    first, second = record_paths(spec)
    before = track(archive, tmp_path / "out-h5").summary()
    toy = second.with_suffix(".npz")
    _write_npz(read_record(second), toy)
    shutil.move(second, tmp_path / "put-aside.h5")
    assert record_paths(spec) == [first, toy]
    after = track(archive, tmp_path / "out-npz").summary()
    assert after["cables"]["C1"]["processed"] == before["cables"]["C1"]["processed"] == 2
    from stcs_ident.track.store import processed_table

    h5_rows, npz_rows = processed_table(tmp_path / "out-h5"), processed_table(tmp_path / "out-npz")
    assert list(npz_rows["record"]) == [first.relative_to(archive / "C1").as_posix(),
                                        toy.relative_to(archive / "C1").as_posix()]
    assert list(npz_rows["status"]) == ["ok", "ok"] and np.all(npz_rows["tension_N"] > 0)
    np.testing.assert_array_equal(npz_rows["tension_N"], h5_rows["tension_N"])  # the same samples: the same tension


def test_the_command_line_identifies_from_a_csv_record_as_from_its_hdf5(simulated, tmp_path, capsys):
    """`identify` (through spectra) gives the same tension from the record written as CSV."""
    import json

    from stcs_ident.cli.main import main

    campaign = load_campaign(simulated)
    test = campaign.test("T2")
    record = read_record(Path(simulated) / test.record)
    (tmp_path / "records").mkdir()
    _write_csv(record, tmp_path / "records" / "T2.csv")
    csv_test = replace(test, record="records/T2.csv", channels=tuple(zip(record.channel_names,
                                                                         record.channel_positions)))
    (tmp_path / "campaign.toml").write_text(campaign_to_toml(replace(campaign, tests=(csv_test,))), encoding="utf-8")
    results = {}
    for name, directory in (("h5", simulated), ("csv", tmp_path)):
        assert main(["identify", str(directory), "--test", "T2", "--params", "tension",
                     "--json", str(tmp_path / f"{name}.json")]) == 0
        results[name] = json.loads((tmp_path / f"{name}.json").read_text())
    capsys.readouterr()
    ratio = {name: r["parameters"]["tension_ratio"]["T2"] for name, r in results.items()}
    # Samples equal to TEXT_RTOL give peaks equal to about 1e-10 relative, and the tension with them.
    np.testing.assert_allclose(ratio["csv"], ratio["h5"], rtol=1e-9)
    assert results["csv"]["tests"][0]["modes"] == results["h5"]["tests"][0]["modes"]
