"""Records from data loggers: one simulated record written in every format a logger writes gives, through
``spectra``, the same frequencies as the same record in HDF5; each reader's refusals name the file and the fix.

The formats: CSV with a time column rounded to 7 significant digits, ``;`` separators, decimal commas and a
units row; CSV with date-times; MATLAB .mat v5 (a 1x1 ``fs``, a cell array of channel names) and v7.3 (HDF5 in
MATLAB's layout, the channel names from the campaign); TDMS (npTDMS, in g); UFF dataset 58 (pyuff, binary).
Every writer here keeps the samples at full precision (float64 binary, or text printed with ``repr``), so the
picked frequencies can be compared to 1e-9 relative: only the arithmetic of reading may differ (a unit
scale, a decimal comma parsed), a few units in the last place of a sample.
"""

from __future__ import annotations

import gc
import time
import warnings
from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
import scipy.io
from nptdms import ChannelObject, TdmsWriter

from stcs_ident.core.errors import CampaignError, InputError
from stcs_ident.core.record import STANDARD_GRAVITY, Record
from stcs_ident.io.campaign import campaign_to_toml, load_campaign
from stcs_ident.io.records import read_record
from stcs_ident.io.test_record import record_reading
from stcs_ident.simulate.simulate import Impulse
from stcs_ident.simulate.simulate_campaign import simulate_campaign
from stcs_ident.spectra.pipeline import analyse_test
from tests.fuzz_inputs import BASE_TOML, _frequencies

START = "2026-03-01T10:00:00+00:00"
#: The same samples read back from another format give peaks within this (relative): a sample differs from
#: the HDF5 one by a few units in the last place at most (unit scale, decimal comma), i.e. 1e-15 relative.
RTOL = 1e-9


# ---------------------------------------------------------------- writers, as the loggers write their files


def _csv_rounded(record: Record, path: Path) -> dict:
    """';'-separated, decimal commas, a units row, the time printed to 7 significant digits (0.00390625 s
    becomes 0,003906250); the samples with every digit (repr)."""
    lines = [";".join(("time", *record.channel_names)), ";".join(("s", *["m/s²"] * record.n_channels))]
    for t, row in zip(record.time, record.acceleration):
        lines.append(";".join([f"{t:.7g}".replace(".", ","), *(repr(float(x)).replace(".", ",") for x in row)]))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return {"separator": ";", "decimal": ",", "skip_rows": [1], "sampling_rate": record.sampling_rate,
            "start_time": START}


def _csv_datetimes(record: Record, path: Path, start: str = START) -> dict:
    """A date-time column to the nanosecond (ISO 8601), every digit of the samples."""
    step = round(1e9 / record.sampling_rate)
    assert step == 1e9 / record.sampling_rate  # the step is a whole number of ns: the date-times are exact
    stamps = pd.Timestamp(start) + pd.to_timedelta(np.arange(record.n_samples) * step, unit="ns")
    lines = [",".join(("timestamp", *record.channel_names))]
    lines += [",".join((stamp.isoformat(), *map(repr, map(float, row))))
              for stamp, row in zip(stamps, record.acceleration)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return {"time_column": "timestamp"}


def _mat_v5(record: Record, path: Path) -> dict:
    """MATLAB v5: the matrix, a 1x1 fs and a cell array of channel names."""
    names = np.empty((1, record.n_channels), dtype=object)
    names[0, :] = record.channel_names
    scipy.io.savemat(path, {"acc": record.acceleration, "fs": np.array([[record.sampling_rate]]),
                            "channel_names": names, "start_time": START})
    return {}


def _mat_v73(record: Record, path: Path) -> dict:
    """MATLAB v7.3 as MATLAB writes it: HDF5 behind a 512-byte header, arrays column-major (so transposed),
    each with its MATLAB_class; a second matrix, so the option ``variable`` names the record's."""
    with h5py.File(path, "w", userblock_size=512) as h5:
        for name, value in (("acc", record.acceleration), ("fs", np.array([[record.sampling_rate]])),
                            ("calibration", np.ones((4, 3)))):
            h5[name] = np.asarray(value, dtype=np.float64).T
            h5[name].attrs["MATLAB_class"] = np.bytes_("double")
        h5["unit"] = np.array([[ord(c)] for c in "m/s^2"], dtype=np.uint16)  # a char row vector, column-major
        h5["unit"].attrs["MATLAB_class"] = np.bytes_("char")
        h5["unit"].attrs["MATLAB_int_decode"] = np.int32(2)
    text = f"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: {time.asctime()} HDF5 schema 1.00 .".encode()
    header = text.ljust(116) + b" " * 8 + b"\x00\x02" + b"IM"
    with open(path, "r+b") as stream:
        stream.write(header.ljust(512, b"\0"))
    return {"variable": "acc", "start_time": START}


def _tdms(record: Record, path: Path) -> dict:
    """TDMS in g, with a second group (temperatures), so the option ``group`` names the record's."""
    common = {"wf_increment": 1.0 / record.sampling_rate, "wf_start_time": np.datetime64(START[:19]),
              "unit_string": "g"}
    channels = [ChannelObject("Accelerations", name, record.acceleration[:, k] / STANDARD_GRAVITY, common)
                for k, name in enumerate(record.channel_names)]
    channels.append(ChannelObject("Temperatures", "air", np.array([12.5, 12.6])))
    with TdmsWriter(str(path)) as writer:
        writer.write_segment(channels)
    return {"group": "Accelerations"}


def _uff(record: Record, path: Path) -> dict:
    """UFF dataset 58, binary float64, one dataset per channel named by its response entity."""
    import pyuff

    sets = [pyuff.prepare_58(binary=1, func_type=1, rsp_node=k + 1, rsp_dir=1, ref_node=0, ref_dir=0,
                             rsp_ent_name=name, abscissa_spacing=1, ordinate_spec_data_type=12,
                             orddenom_spec_data_type=0, ordinate_axis_units_lab="m/s^2",
                             abscissa_axis_units_lab="s", data=record.acceleration[:, k], x=record.time,
                             id1=f"channel {name}")
            for k, name in enumerate(record.channel_names)]
    with warnings.catch_warnings():  # pyuff's writer leaves its file to the garbage collector
        warnings.simplefilter("ignore", ResourceWarning)
        pyuff.UFF(str(path)).write_sets(sets, mode="add", force_double=True)
        gc.collect()
    return {"start_time": START}


FORMATS = {"csv-rounded": (".csv", _csv_rounded), "csv-datetimes": (".txt", _csv_datetimes),
           "mat-v5": (".mat", _mat_v5), "mat-v73": (".mat", _mat_v73), "tdms": (".tdms", _tdms),
           "uff": (".uff", _uff)}


# ---------------------------------------------------------------- the acceptance


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    root = tmp_path_factory.mktemp("loggers")
    (root / "nominal").mkdir()
    (root / "nominal" / "campaign.toml").write_text(BASE_TOML.format(f=_frequencies()), encoding="utf-8")
    directory = simulate_campaign(load_campaign(root / "nominal"), root / "sim", positions=[1.9, 4.1, 5.7],
                                  duration=20.0, sampling_rate=256.0, tests=["T2"],
                                  impulses=[Impulse(0.5, 1.3, 5.0), Impulse(9.0, 6.2, 5.0)], snr_db=40.0, seed=4)
    campaign = load_campaign(directory)
    test = campaign.test("T2")
    return campaign, test, read_record(Path(directory) / test.record), analyse_test(campaign, test)


def _as_campaign(simulated, directory: Path, kind: str):
    """The simulated test with its record written as ``kind``, through a campaign file written and read back."""
    campaign, test, record, _ = simulated
    suffix, writer = FORMATS[kind]
    (directory / "records").mkdir(parents=True)
    options = writer(record, directory / "records" / f"T2{suffix}")
    channels = tuple(zip(record.channel_names, map(float, record.channel_positions)))
    other = replace(campaign, tests=(replace(test, record=f"records/T2{suffix}", channels=channels,
                                             record_format=options),))
    (directory / "campaign.toml").write_text(campaign_to_toml(other), encoding="utf-8")
    loaded = load_campaign(directory)
    assert loaded.test("T2").record_format == other.test("T2").record_format  # [test.record_format] round-trips
    return loaded


@pytest.mark.parametrize("kind", list(FORMATS))
def test_every_logger_format_gives_the_frequencies_of_the_hdf5_record(simulated, tmp_path, kind):
    _, _, record, reference = simulated
    campaign = _as_campaign(simulated, tmp_path, kind)
    test = campaign.test("T2")
    positions, options = _reading(campaign, test)
    read = read_record(Path(campaign.directory) / test.record, positions=positions, **options)
    assert read.channel_names == record.channel_names and read.sampling_rate == record.sampling_rate
    assert read.start_time == START  # from the file (date-times, .mat, TDMS) or the option (CSV, UFF)
    np.testing.assert_allclose(read.acceleration, record.acceleration, rtol=1e-14, atol=0)  # a few ulp at most
    spectra = analyse_test(campaign, test)
    assert reference.modes and spectra.modes == reference.modes
    np.testing.assert_allclose(spectra.frequencies, reference.frequencies, rtol=RTOL, atol=0)


def test_an_option_that_replaces_the_file_s_value_is_recorded_on_the_record(simulated, tmp_path):
    campaign = _as_campaign(simulated, tmp_path, "tdms")
    path = Path(campaign.directory) / campaign.test("T2").record
    positions, options = _reading(campaign, campaign.test("T2"))
    record = read_record(path, positions=positions, **options, start_time="2026-03-05T00:00:00+00:00",
                         temperature=4.5)
    assert record.start_time == "2026-03-05T00:00:00+00:00" and record.temperature == 4.5
    # The file's start time is replaced (and said so); it has no temperature: nothing replaced there.
    assert record.replaced == (("start_time", "2026-03-05T00:00:00+00:00", START),)


# ---------------------------------------------------------------- refusals, one line naming the file and the fix


def _refused(path: Path, match: str, field: str | None = None, **options) -> InputError:
    with pytest.raises(InputError, match=match) as info:
        read_record(path, **options)
    assert info.value.file == str(path) and str(path) in str(info.value) and "\n" not in str(info.value)
    if field is not None:
        assert info.value.field == field
    return info.value


@pytest.fixture(scope="module")
def short():
    """A short record with names and positions (the refusals need no spectra)."""
    rng = np.random.default_rng(2)
    return Record(rng.standard_normal((64, 2)), 256.0, ("a1", "a2"), np.array([1.0, 2.0]))


def test_csv_refusals_name_the_option_that_reads_the_file(short, tmp_path):
    positions = {"a1": 1.0, "a2": 2.0}
    path = tmp_path / "rounded.csv"
    _csv_rounded(short, path)
    _refused(path, "give separator = ';'", positions=positions)
    _refused(path, "units row.*skip_rows = \\[1\\]", "acceleration", positions=positions, separator=";")
    _refused(path, 'decimal = ","', positions=positions, separator=";", skip_rows=[1])
    error = _refused(path, "not uniformly sampled.*give sampling_rate \\(about 25[56]", "time", positions=positions,
                     separator=";", skip_rows=[1], decimal=",")
    assert "step" in error.message
    assert read_record(path, positions=positions, separator=";", skip_rows=[1], decimal=",",
                       sampling_rate=256.0).sampling_rate == 256.0
    gap = tmp_path / "gap.csv"
    _csv_datetimes(short, gap)
    lines = gap.read_text().splitlines()
    gap.write_text("\n".join(lines[:20] + lines[21:]) + "\n")  # a sample lost: a gap in the date-times
    _refused(gap, "not uniformly spaced.*give sampling_rate", "timestamp", positions=positions,
             time_column="timestamp")
    words = tmp_path / "words.csv"
    words.write_text("time,a1,a2\nnoon,1,2\nlater,1,2\n")
    _refused(words, "neither a time in seconds nor an ISO 8601 date-time", "time", positions=positions)
    _refused(path, "must be a unit of acceleration .*got 'V'", "unit", positions=positions, unit="V")  # (the option)


def test_matlab_refusals(short, tmp_path):
    positions = {"a1": 1.0, "a2": 2.0}
    path = tmp_path / "r.mat"
    scipy.io.savemat(path, {"acc": short.acceleration, "other": np.ones((5, 2)), "fs": np.array([[256.0, 1.0]])})
    _refused(path, "cannot tell the record's matrix.*give variable", "variable", positions=positions)
    _refused(path, "no variable 'accel'.*variable", "variable", positions=positions, variable="accel")
    _refused(path, "'fs' must be one number \\(a 1x1 array\\)", "fs", positions=positions, variable="acc")
    scipy.io.savemat(path, {"acc": short.acceleration})
    _refused(path, "no sampling rate.*give sampling_rate", "sampling_rate", positions=positions)
    _refused(path, "table \\(\\[test.channels\\]\\) lists 1", "channel_name", positions={"a1": 1.0},
             sampling_rate=256.0)
    assert read_record(path, positions=positions, sampling_rate=256.0).channel_names == ("a1", "a2")
    scipy.io.savemat(path, {"acc": short.acceleration.T, "fs": 256.0})
    _refused(path, "2 rows and 64 columns.*transpose", "variable", positions=positions)
    path.write_bytes(b"MATLAB 5.0 MAT-file" + b"\0" * 20)
    _refused(path, "not a MATLAB file")


def test_tdms_refusals(short, tmp_path):
    positions = {"a1": 1.0, "a2": 2.0}
    path = tmp_path / "r.tdms"
    _tdms(short, path)
    _refused(path, "cannot tell the record's group.*give group", "group", positions=positions)
    _refused(path, "no group 'Acc'.*Accelerations, Temperatures", "group", positions=positions, group="Acc")
    with TdmsWriter(str(path)) as writer:
        writer.write_segment([ChannelObject("G", "a1", short.acceleration[:, 0], {"unit_string": "V"}),
                              ChannelObject("G", "a2", short.acceleration[:, 1], {"unit_string": "V"})])
    _refused(path, "no sampling rate.*wf_increment; give sampling_rate", "sampling_rate", positions=positions)
    _refused(path, "unknown unit 'V'", "unit", positions=positions, sampling_rate=256.0)
    assert read_record(path, positions=positions, sampling_rate=256.0, unit="m/s^2").replaced == (
        ("unit", "m/s^2", "V"),)
    path.write_bytes(b"TDSm" + b"\0" * 10)
    _refused(path, "not a TDMS")


def test_uff_refusals(short, tmp_path):
    positions = {"a1": 1.0, "a2": 2.0}
    path = tmp_path / "r.uff"
    _uff(short, path)
    _refused(path, "no position for channel 'a2'", "channel_position", positions={"a1": 1.0})
    _refused(path, "must be a unit of acceleration .*got 'mV'", "unit", positions=positions, unit="mV")
    path.write_text("    -1\n    15\n         1         0         0         1 0.0 0.0 0.0\n    -1\n")
    _refused(path, "no dataset 58 of a time response", "acceleration", positions=positions)


# ---------------------------------------------------------------- the campaign's channel table and options


def _campaign_text(extra: str) -> str:
    return BASE_TOML.format(f=_frequencies()).replace('record = "records/T2.h5"\n',
                                                       'record = "records/T2.csv"\n' + extra)


@pytest.mark.parametrize(("extra", "field", "match"), [
    ("  [test.record_format]\n  sep = \";\"\n", "test[T2].record_format.sep", "unknown key 'sep'"),
    ("  [test.record_format]\n  sampling_rate = \"256\"\n", "test[T2].record_format.sampling_rate",
     "must be a number of Hz > 0"),
    ("  [test.record_format]\n  skip_rows = [0]\n", "test[T2].record_format.skip_rows", "line numbers >= 1"),
    ("  [test.record_format]\n  decimal = \",,\"\n", "test[T2].record_format.decimal", "one character"),
    ("  [test.record_format]\n  unit = \"V\"\n", "test[T2].record_format.unit", "a unit of acceleration"),
    ("  [test.record_format]\n  start_time = \"yesterday\"\n", "test[T2].record_format.start_time", "ISO 8601"),
    ("  [test.channels]\n  acc3 = { position = 9.9, direction = \"up\" }\n", "test[T2].channels.acc3.direction",
     "an angle in degrees"),
    ("  [test.channels]\n  acc3 = { position = 9.9, side = 1 }\n", "test[T2].channels.acc3.side", "unknown key"),
    ("  [test.channels]\n  acc3 = { direction = \"in\" }\n", "test[T2].channels.acc3.position", "required"),
])
def test_a_wrong_channel_or_option_names_its_key(tmp_path, extra, field, match):
    (tmp_path / "campaign.toml").write_text(_campaign_text(extra), encoding="utf-8")
    with pytest.raises(CampaignError, match=match) as info:
        load_campaign(tmp_path)
    assert info.value.field == field


def test_channels_inline_and_every_option_round_trip(tmp_path):
    extra = ('  [test.channels]\n  acc1 = 4.5\n  acc3 = { position = 6.9, direction = "in" }\n'
             '  [test.record_format]\n  unit = "g"\n  sampling_rate = 256\n  time_column = "t"\n'
             '  separator = ";"\n  decimal = ","\n  skip_rows = [1, 2]\n  start_time = 2026-03-01T00:00:00Z\n'
             '  temperature = 12\n  variable = "acc"\n  group = "G"\n')
    text = _campaign_text(extra) + '\n[record_format]\nunit = "mg"\n\n[channels]\nx = 1.0\n'
    (tmp_path / "campaign.toml").write_text(text, encoding="utf-8")
    campaign = load_campaign(tmp_path)
    test = campaign.test("T2")
    assert test.channels == (("acc1", 4.5), ("acc3", 6.9))
    options = dict(test.record_format)
    assert options["skip_rows"] == (1, 2) and options["start_time"] == "2026-03-01T00:00:00+00:00"
    assert options["sampling_rate"] == 256.0 and len(options) == 10
    (tmp_path / "again").mkdir()
    (tmp_path / "again" / "campaign.toml").write_text(campaign_to_toml(campaign), encoding="utf-8")
    again = load_campaign(tmp_path / "again")
    assert replace(again, directory=None) == replace(campaign, directory=None)
    # The test's own table and options win over the campaign's top-level ones.
    positions, merged = _reading(campaign, test)
    assert positions == {"acc1": 4.5, "acc3": 6.9} and merged["unit"] == "g"
    positions, merged = _reading(campaign, campaign.test("T1"))
    assert positions == {"x": 1.0} and merged == {"unit": "mg"}


# ---------------------------------------------------------------- track: an archive of CSV records


def test_track_takes_an_archive_of_csv_records_with_their_start_times(tmp_path):
    """The simulated archive's records rewritten as CSV with date-times (the channel table and the reader
    options once, at the top level of the cable's campaign) give the rows of the HDF5 archive, start times
    included."""
    from stcs_ident.simulate.archive import ArchiveOptions, simulate_archive
    from stcs_ident.track.store import processed_table

    (tmp_path / "nominal").mkdir()
    (tmp_path / "nominal" / "campaign.toml").write_text(
        BASE_TOML.replace('record = "records/T2.h5"\n', "").format(f=_frequencies()), encoding="utf-8")
    archive = simulate_archive({"C1": load_campaign(tmp_path / "nominal")}, tmp_path / "archive",
                               options=ArchiveOptions(days=3 / 24, interval=3600, duration=30.0), seed=5)
    before = processed_table(_tracked(archive, tmp_path / "h5"))
    cable = archive / "C1"
    paths = sorted((cable / "records").rglob("*.h5"))
    records = [read_record(path) for path in paths]
    for path, record in zip(paths, records):
        _csv_datetimes(record, path.with_suffix(".csv"), start=record.start_time)
        path.unlink()
    campaign = load_campaign(cable)
    campaign = replace(campaign, channels=tuple(zip(records[0].channel_names, map(float, records[0].channel_positions))),
                       record_format=(("time_column", "timestamp"),))
    (cable / "campaign.toml").write_text(campaign_to_toml(campaign), encoding="utf-8")
    after = processed_table(_tracked(archive, tmp_path / "csv"))
    assert len(after) == len(paths) == 3 and list(after["status"]) == ["ok"] * 3
    assert list(after["start_time"]) == [pd.Timestamp(r.start_time) for r in records] == list(before["start_time"])
    assert all(name.endswith(".csv") for name in after["record"])
    # The same samples (to an ulp, text printed with repr): the same tension to far below its 1σ (~1e-4).
    np.testing.assert_allclose(after["tension_N"], before["tension_N"], rtol=1e-9)


def _tracked(archive: Path, out: Path) -> Path:
    from stcs_ident.track.api import track

    track(archive, out)
    return out


def test_spectra_says_what_the_record_format_replaced(simulated, tmp_path):
    """A TDMS record whose start time the campaign replaces: spectra's result and JSON say so."""
    campaign = _as_campaign(simulated, tmp_path, "tdms")
    test = campaign.test("T2")
    test = replace(test, record_format=(*test.record_format, ("start_time", "2026-03-05T00:00:00+00:00")))
    spectra = analyse_test(replace(campaign, tests=(test,)), test)
    assert spectra.record_replaced == (("start_time", "2026-03-05T00:00:00+00:00", START),)
    assert spectra.summary()["record_replaced"] == [
        {"option": "start_time", "given": "2026-03-05T00:00:00+00:00", "file": START}]


def test_the_command_line_refuses_a_rounded_csv_in_one_line_naming_the_file_and_the_fix(simulated, tmp_path,
                                                                                       capsys):
    """`spectra` on a campaign whose CSV record has a rounded time column and no sampling_rate: exit 2, one
    line naming the file, the field and the option, nothing written."""
    from stcs_ident.cli.main import main

    campaign = _as_campaign(simulated, tmp_path, "csv-rounded")
    test = campaign.test("T2")
    without = replace(test, record_format=tuple((k, v) for k, v in test.record_format if k != "sampling_rate"))
    (tmp_path / "campaign.toml").write_text(campaign_to_toml(replace(campaign, tests=(without,))), encoding="utf-8")
    capsys.readouterr()
    assert main(["spectra", str(tmp_path), "--json", str(tmp_path / "out.json")]) == 2
    (err,) = [line for line in capsys.readouterr().err.splitlines() if line.startswith("stcs-ident:")]  # progress aside
    assert "T2.csv" in err and "field 'time'" in err, err
    assert "give sampling_rate" in err and not (tmp_path / "out.json").exists()


def _reading(campaign, test):
    """(positions, reader options) of ``test``'s record, as io gives them."""
    reading = record_reading(campaign, test)
    return reading.positions, reading.options
