"""Logger layouts behind the record-reader seam: Campbell Scientific TOA5, text with a preamble, the ``channels``
option, NI LabVIEW LVM, MATLAB structs, decimal-comma CSV; and what every reader refuses in one line naming the
file, the field and the option that would read it.

Each file is written here as its logger writes it, from samples printed with ``repr`` (every digit), so the
samples read back equal the written ones to a unit in the last place: one multiplication by a unit's factor,
or the text parsed by pandas' fast float parser (1e-15 relative at most; RTOL).
"""

from __future__ import annotations

import os
import pickle
import shutil
import warnings
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
import scipy.io

from stcs_ident.core.errors import CampaignError, InputError, RecordWarning
from stcs_ident.core.record import STANDARD_GRAVITY, Record
from stcs_ident.io.campaign import campaign_to_toml, load_campaign
from stcs_ident.io.records import read_record, reader_for
from stcs_ident.io.records.hdf5 import write_record
from stcs_ident.io.records.options import check_options, option_problem
from tests.fuzz_inputs import BASE_TOML, _frequencies

#: A sample read back from text, or scaled by a unit's factor once, is within a few units in the last place.
RTOL = 1e-14
FS = 100.0  # Hz
N = 300
START = "2026-03-01T00:00:00"


def _signals(n: int = N, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    return np.column_stack([np.sin(2 * np.pi * 3.1 * t) + 0.1 * rng.standard_normal(n),
                            np.cos(2 * np.pi * 7.3 * t) + 0.1 * rng.standard_normal(n)])


def _refused(path: Path, match: str, field: str | None = None, **options) -> InputError:
    with pytest.raises(InputError, match=match) as info:
        read_record(path, **options)
    text = str(info.value)
    assert info.value.file == str(path) and text.startswith(str(path)) and "\n" not in text, text
    assert "Traceback" not in text
    if field is not None:
        assert info.value.field == field, text
    return info.value


# ---------------------------------------------------------------- TOA5


def _toa5(path: Path, acc: np.ndarray, *, units=("g", "m/s^2"), gap: int | None = None, nan_at: int | None = None,
          names=("acc1", "acc2")) -> Path:
    """A CR1000X table as LoggerNet writes it: 4 header lines, quoted TIMESTAMP to 10 ms, RECORD, a battery
    voltage, two accelerations in their own units."""
    lines = ['"TOA5","Stay3","CR1000X","12345","CR1000X.Std.04.02","CPU:stay.CR1X","34567","Accel"',
             ",".join(f'"{n}"' for n in ("TIMESTAMP", "RECORD", "BattV", *names)),
             ",".join(f'"{u}"' for u in ("TS", "RN", "Volts", *units)),
             '"","","Smp","Smp","Smp"']
    start = pd.Timestamp(START)
    for k, row in enumerate(acc):
        step = k + (1 if gap is not None and k >= gap else 0)  # a lost sample: the clock jumps a step
        stamp = (start + pd.Timedelta(milliseconds=10 * step)).strftime("%Y-%m-%d %H:%M:%S.%f")[:-4]
        values = ["NAN" if nan_at == k else repr(float(x)) for x in row]
        lines.append(f'"{stamp}",{step},{12.61 + 0.01 * (k % 3):.2f},{",".join(values)}')
    path.write_text("\r\n".join(lines) + "\r\n", encoding="utf-8")
    return path


POSITIONS = {"acc1": 4.5, "acc2": 9.9}


def test_toa5_reads_the_acceleration_columns_in_their_own_units_and_leaves_the_others_out(tmp_path):
    acc = _signals()
    path = _toa5(tmp_path / "CR1000X_Accel.dat", acc)
    assert reader_for(path).name == "toa5"
    record = read_record(path, positions=POSITIONS)
    assert record.channel_names == ("acc1", "acc2") and record.sampling_rate == pytest.approx(FS, rel=1e-12)
    assert record.start_time == START
    np.testing.assert_allclose(record.acceleration[:, 0], acc[:, 0] * STANDARD_GRAVITY, rtol=RTOL)  # in g
    np.testing.assert_allclose(record.acceleration[:, 1], acc[:, 1], rtol=RTOL)  # in m/s^2
    assert "columns left out (not an acceleration unit): RECORD (RN), BattV (Volts)" in record.notes
    assert record.replaced == ()
    # Renamed .csv (as people do), the content still says TOA5: never the RECORD counter as an accelerometer.
    copy = Path(shutil.copy(path, tmp_path / "accel.csv"))
    again = read_record(copy, positions=POSITIONS)
    assert again.channel_names == ("acc1", "acc2")
    np.testing.assert_array_equal(again.acceleration, record.acceleration)


def test_toa5_options_channels_unit_and_rate(tmp_path):
    acc = _signals()
    path = _toa5(tmp_path / "r.dat", acc)
    one = read_record(path, positions={"acc2": 9.9}, channels=["acc2"])
    assert one.channel_names == ("acc2",)
    assert "columns left out (not in channels): RECORD, BattV, acc1" in one.notes
    both = read_record(path, positions=POSITIONS, unit="mg")  # unit replaces every channel's, said per column
    assert both.replaced == (("unit of acc1", "mg", "g"), ("unit of acc2", "mg", "m/s^2"))
    np.testing.assert_allclose(both.acceleration[:, 1], acc[:, 1] * 1e-3 * STANDARD_GRAVITY, rtol=RTOL)
    # A column without an acceleration unit named in channels is read in the unit given (in file order).
    volts = read_record(path, positions={"acc1": 1.0, "BattV": 2.0}, channels=["acc1", "BattV"], unit="g")
    assert volts.channel_names == ("BattV", "acc1") and volts.replaced == (("unit of acc1", "g", "g"),)[:0]


def test_toa5_refusals_name_the_option(tmp_path):
    acc = _signals()
    path = _toa5(tmp_path / "r.dat", acc)
    _refused(path, r"no position for channel 'acc2'.*channels = \[\"acc1\"\]", "channel_position",
             positions={"acc1": 4.5})
    _refused(path, "channel table lists 'BattV', a column left out .not an acceleration unit.; give channels",
             "channel_position", positions={**POSITIONS, "BattV": 1.0})
    _refused(path, "channels names 'acc3', not a column", "channels", positions=POSITIONS, channels=["acc3"])
    _refused(path, "channels names 'TIMESTAMP', the time column", "channels", positions=POSITIONS,
             channels=["TIMESTAMP"])
    _refused(path, "channel 'RECORD' is in 'RN', not a unit of acceleration.*give unit", "unit",
             positions={"RECORD": 1.0}, channels=["RECORD"])
    volts = _toa5(tmp_path / "volts.dat", acc, units=("mV", "mV"))
    _refused(volts, r"no column has a unit of acceleration.*acc1 'mV'.*give channels = ", "channels",
             positions=POSITIONS)
    gap = _toa5(tmp_path / "gap.dat", acc, gap=150)
    # A lost sample: the timestamps, printed to the 10 ms interval, cannot show it, the RECORD counter does.
    _refused(gap, "RECORD goes from 149 to 151 at lines 154 to 155: samples lost.*give sampling_rate", "RECORD",
             positions=POSITIONS)
    # With sampling_rate, the counter is not looked at; the timestamps' span (one step longer) then disagrees.
    _refused(gap, "gives sampling_rate 100 Hz, the file's time column 'TIMESTAMP' says 99.66666667 Hz.*"
             "override_sampling_rate = true", "sampling_rate", positions=POSITIONS, sampling_rate=FS)
    as_they_are = read_record(gap, positions=POSITIONS, sampling_rate=FS, override_sampling_rate=True)
    assert as_they_are.sampling_rate == FS and as_they_are.replaced[0][:2] == ("sampling_rate", FS)
    lost = _toa5(tmp_path / "nan.dat", acc, nan_at=40)
    _refused(lost, "channel 'acc1' has NaN at sample 40", "acceleration", positions=POSITIONS)
    lines = path.read_text().splitlines()
    short = tmp_path / "short.dat"
    short.write_text("\n".join(lines[:3]) + "\n")
    _refused(short, "not a TOA5 file: expected four header lines", positions=POSITIONS)
    units = tmp_path / "units.dat"
    units.write_text("\n".join([lines[0], lines[1], '"TS","RN","Volts","g"', *lines[3:]]) + "\n")
    _refused(units, "units line .line 3. has 4 fields for 5 column names", "unit", positions=POSITIONS)


def test_a_dat_file_is_read_by_its_content_or_refused_naming_what_was_expected(tmp_path):
    text = tmp_path / "plain.dat"
    text.write_text("time,a1\n0.0,1.0\n0.01,-2.0\n0.02,0.5\n")
    assert reader_for(text).name == "csv" and read_record(text, positions={"a1": 1.0}).sampling_rate == FS
    binary = tmp_path / "logger.dat"
    binary.write_bytes(bytes(range(256)) * 8)
    _refused(binary, "not a record layout this toolkit reads: expected a Campbell Scientific TOA5 table.*"
             "header_row")


# ---------------------------------------------------------------- text with a preamble


def _dewesoft(path: Path, acc: np.ndarray, *, units_row: bool = True) -> Path:
    """';'-separated, decimal commas, four metadata lines (one of them as wide as the data), a blank line, the
    header and a units row."""
    lines = ["Dewesoft X3 export;;", "Start;01.03.2026 10:00:00", "Sample rate;100;Hz", "", "Time;acc1;acc2"]
    if units_row:
        lines.append("[s];[g];[g]")
    lines += [";".join([f"{k / FS:.2f}", *(repr(float(x)) for x in row)]).replace(".", ",")
              for k, row in enumerate(acc)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_the_header_after_a_preamble_is_found_and_said(tmp_path):
    acc = _signals()
    path = _dewesoft(tmp_path / "export.txt", acc)
    options = {"positions": POSITIONS, "separator": ";", "decimal": ",", "unit": "g", "time_column": "Time"}
    # The header found, the units row under it refused as in any CSV: the message counts the file's lines.
    _refused(path, r"line 6 \('\[s\]', '\[g\]', '\[g\]'\) holds no number.*skip_rows = \[1\]", "acceleration",
             **options)
    record = read_record(path, skip_rows=[1], **options)
    assert record.notes == (("header line found at line 4 (0-based) after a preamble of 4 line(s), 3 columns: "
                             "give header_row = 4 in record_format to set it"),)
    np.testing.assert_allclose(record.acceleration, acc * STANDARD_GRAVITY, rtol=RTOL)
    assert record.sampling_rate == FS
    given = read_record(path, skip_rows=[1], header_row=4, **options)  # given: nothing to say
    assert given.notes == () and np.array_equal(given.acceleration, record.acceleration)
    _refused(path, "the header .line 2. has 2 columns, the rows 3", skip_rows=[1], header_row=1, **options)
    _refused(path, r"line 3 \(0-based, header_row\) is empty", header_row=3, **options)
    _refused(path, "line 900 .0-based, header_row. is empty or past the end", header_row=900, **options)


def test_a_preamble_without_the_option_used_to_give_duplicate_columns(tmp_path):
    """The first line "Dewesoft X3 export;;" split into 'Dewesoft X3 export', '', '': the header search reads
    past it; with header_row = 0 forced the refusal names the option."""
    path = _dewesoft(tmp_path / "export.csv", _signals(), units_row=False)
    record = read_record(path, positions=POSITIONS, separator=";", decimal=",", time_column="Time")
    assert record.channel_names == ("acc1", "acc2") and record.notes[0].startswith("header line found at line 4")
    _refused(path, "a preamble.*give header_row", positions=POSITIONS, separator=";", decimal=",", header_row=0,
             time_column="Time")


def test_a_csv_without_preamble_is_read_as_before_with_no_note(tmp_path):
    path = tmp_path / "r.csv"
    acc = _signals()
    lines = ["time,acc1,acc2", *(",".join(repr(float(x)) for x in (k / FS, *row)) for k, row in enumerate(acc))]
    path.write_text("\n".join(lines) + "\n")
    record = read_record(path, positions=POSITIONS)
    assert record.notes == () and record.replaced == ()
    np.testing.assert_allclose(record.acceleration, acc, rtol=RTOL)


# ---------------------------------------------------------------- the channels option


def _with_extras(path: Path, acc: np.ndarray) -> Path:
    lines = ["time,acc1,temp,acc2,batt"]
    lines += [",".join(repr(float(x)) for x in (k / FS, row[0], 12.5 + k * 1e-3, row[1], 12.7 - k * 1e-4))
              for k, row in enumerate(acc)]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_channels_names_the_acceleration_columns_and_the_others_are_listed(tmp_path):
    acc = _signals()
    path = _with_extras(tmp_path / "r.csv", acc)
    record = read_record(path, positions=POSITIONS, channels=["acc1", "acc2"])
    assert record.channel_names == ("acc1", "acc2")
    assert record.notes == ("columns left out (not in channels): temp, batt",)
    np.testing.assert_allclose(record.acceleration, acc, rtol=RTOL)
    # Without channels, a column without a position is refused, naming the option with the columns that have one.
    error = _refused(path, "no position for channel 'temp'", "channel_position", positions=POSITIONS)
    assert 'give channels = ["acc1", "acc2"] in record_format' in error.message and "[test.channels]" in error.message
    _refused(path, "channels names 'acc9', not a column of the file", "channels", positions=POSITIONS,
             channels=["acc1", "acc9"])
    _refused(path, "channels names 'time', the time column", "channels", positions=POSITIONS, channels=["time"])


@pytest.mark.parametrize(("key", "value", "match"), [
    ("channels", [], "at least one"), ("channels", ["a", "a"], "each once"), ("channels", "acc1", "a list"),
    ("channels", [" a"], "a list"), ("channels", [1], "a list"), ("header_row", -1, ">= 0"),
    ("header_row", True, ">= 0"), ("header_row", 1.5, ">= 0"), ("override_sampling_rate", "yes", "true or false"),
    ("override_sampling_rate", 1, "true or false"),
])
def test_the_new_options_are_checked(key, value, match):
    assert match in option_problem(key, value)
    with pytest.raises(InputError, match=match) as info:
        check_options({key: value}, file="r.csv")
    assert info.value.field == key


def test_the_new_options_round_trip_through_a_campaign(tmp_path):
    extra = ('  [test.record_format]\n  channels = ["acc1", "acc3"]\n  header_row = 4\n'
             '  override_sampling_rate = true\n  sampling_rate = 256\n')
    text = BASE_TOML.format(f=_frequencies()).replace('record = "records/T2.h5"\n', 'record = "records/T2.csv"\n' + extra)
    (tmp_path / "campaign.toml").write_text(text, encoding="utf-8")
    campaign = load_campaign(tmp_path)
    options = dict(campaign.test("T2").record_format)
    assert options["channels"] == ("acc1", "acc3") and options["header_row"] == 4
    assert options["override_sampling_rate"] is True
    (tmp_path / "again").mkdir()
    (tmp_path / "again" / "campaign.toml").write_text(campaign_to_toml(campaign), encoding="utf-8")
    assert dict(load_campaign(tmp_path / "again").test("T2").record_format) == options
    (tmp_path / "campaign.toml").write_text(text.replace("header_row = 4", "header_row = -4"), encoding="utf-8")
    with pytest.raises(CampaignError, match="line number >= 0") as info:
        load_campaign(tmp_path)
    assert info.value.field == "test[T2].record_format.header_row"


# ---------------------------------------------------------------- decimal-comma CSV without a units row


def test_a_semicolon_decimal_comma_csv_without_units_row_is_read(tmp_path):
    """The units-row test used to run before the decimal mark was applied: '0,01' was no number, and the
    first data row was taken for a units row."""
    acc = _signals()
    path = tmp_path / "r.csv"
    lines = ["time;acc1;acc2", *(";".join(repr(float(x)) for x in (k / FS, *row)).replace(".", ",")
                                 for k, row in enumerate(acc))]
    path.write_text("\n".join(lines) + "\n")
    record = read_record(path, positions=POSITIONS, separator=";", decimal=",")
    np.testing.assert_allclose(record.acceleration, acc, rtol=RTOL)
    assert record.sampling_rate == pytest.approx(FS, rel=1e-12) and record.notes == ()
    # A units row is still refused, naming the option.
    lines.insert(1, "s;m/s2;m/s2")
    path.write_text("\n".join(lines) + "\n")
    _refused(path, r"line 2 .*holds no number.*skip_rows = \[1\]", "acceleration", positions=POSITIONS, separator=";",
             decimal=",")


# ---------------------------------------------------------------- LVM


def _lvm(path: Path, acc: np.ndarray, *, delta_x: str = "0.010000", units=("g", "m/s^2", "Volts"),
         x_columns: str = "One", segments: int = 1, date: str = "2026/03/01", extra_header: str = "") -> Path:
    """A LabVIEW Measurement file as Write To Measurement File writes it: the file header, a segment header
    with one value per channel (and a trailing tab), the X_Value column and a Comment column."""
    n_channels = len(units)
    per = "\t".join
    head = (f"LabVIEW Measurement\t\nWriter_Version\t2\nReader_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\n"
            f"Multi_Headings\tNo\nX_Columns\t{x_columns}\nTime_Pref\tRelative\nOperator\tstay-lab\n"
            f"Date\t{date}\nTime\t10:00:00.2470703125\n{extra_header}***End_of_Header***\t\n")
    body = ""
    for _ in range(segments):
        body += (f"\nChannels\t{n_channels}\t\n"
                 f"Samples\t{per([str(len(acc))] * n_channels)}\t\n"
                 f"Date\t{per([date] * n_channels)}\t\n"
                 f"Time\t{per(['10:00:00.2470703125'] * n_channels)}\t\n"
                 f"Y_Unit_Label\t{per(units)}\t\n"
                 f"X_Dimension\t{per(['Time'] * n_channels)}\t\n"
                 f"X0\t{per(['0.0000000000000000E+0'] * n_channels)}\t\n"
                 f"Delta_X\t{per([delta_x] * n_channels)}\t\n"
                 "***End_of_Header***\t\n"
                 f"X_Value\t{per(['acc1', 'acc2', 'batt'][:n_channels])}\tComment\n")
        for k, row in enumerate(acc):
            values = [repr(float(x)) for x in row] + [f"{12.6 + 0.01 * (k % 3):.2f}"][:n_channels - 2]
            body += f"{k * float(delta_x):.6f}\t{per(values)}\t\n"
    path.write_text(head + body, encoding="utf-8")
    return path


def test_lvm_reads_its_channels_rate_and_start_time_from_the_header(tmp_path):
    acc = _signals()
    path = _lvm(tmp_path / "run.lvm", acc)
    assert reader_for(path).name == "lvm"
    record = read_record(path, positions=POSITIONS)
    assert record.channel_names == ("acc1", "acc2") and record.sampling_rate == pytest.approx(FS, rel=1e-12)
    assert record.start_time == "2026-03-01T10:00:00.247070"
    np.testing.assert_allclose(record.acceleration[:, 0], acc[:, 0] * STANDARD_GRAVITY, rtol=RTOL)
    np.testing.assert_allclose(record.acceleration[:, 1], acc[:, 1], rtol=RTOL)
    assert record.notes == ("columns left out (not an acceleration unit): batt (Volts)",)
    # Renamed .txt: its content names the LVM reader (it used to leak a pandas tokenizer error).
    copy = Path(shutil.copy(path, tmp_path / "run.txt"))
    np.testing.assert_array_equal(read_record(copy, positions=POSITIONS).acceleration, record.acceleration)
    # A Delta_X printed to a few digits: the rate it gives, and a note saying so.
    rounded = read_record(_lvm(tmp_path / "rounded.lvm", acc, delta_x="0.003906"), positions=POSITIONS)
    assert rounded.sampling_rate == pytest.approx(1 / 0.003906, rel=1e-12)
    assert "printed to a few digits only" in rounded.notes[-1] and "give sampling_rate" in rounded.notes[-1]


class _Planted:
    """A pickle that, loaded, creates a directory: the proof a planted file ran code."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return os.mkdir, (str(self.marker),)


def test_a_pickle_planted_beside_an_lvm_record_is_never_loaded_and_nothing_is_written(tmp_path):
    import lvm_read

    folder = tmp_path / "records"
    folder.mkdir()
    path = _lvm(folder / "run.lvm", _signals())
    marker = tmp_path / "code-ran"
    (folder / "run.lvm.pkl").write_bytes(pickle.dumps(_Planted(marker)))  # newer than the record: the package's bait
    before = sorted((p.name, p.stat().st_mtime_ns, p.stat().st_size) for p in folder.iterdir())
    record = read_record(path, positions=POSITIONS)
    assert record.channel_names == ("acc1", "acc2") and not marker.exists()
    assert sorted((p.name, p.stat().st_mtime_ns, p.stat().st_size) for p in folder.iterdir()) == before
    # The hazard is real: the package's own read(), even told not to use pickles, loads it (in a copy).
    bait = tmp_path / "bait"
    shutil.copytree(folder, bait)
    os.utime(bait / "run.lvm.pkl")  # (copytree keeps the times; the package compares change times)
    lvm_read.read(str(bait / "run.lvm"), read_from_pickle=False, dump_file=False)
    assert marker.is_dir()


def test_lvm_refusals(tmp_path):
    acc = _signals()
    _refused(_lvm(tmp_path / "two.lvm", acc, segments=2), "holds 2 data segments", "acceleration",
             positions=POSITIONS)
    _refused(_lvm(tmp_path / "multi.lvm", acc, x_columns="Multi"), "X_Columns = Multi", "X_Columns",
             positions=POSITIONS)
    _refused(_lvm(tmp_path / "date.lvm", acc, date="01.03.2026"), "not a date .YYYY/MM/DD.*give start_time",
             "start_time", positions=POSITIONS)
    _refused(_lvm(tmp_path / "volts.lvm", acc, units=("V", "V", "V")), "no column has a unit of acceleration",
             "channels", positions=POSITIONS)
    _refused(_lvm(tmp_path / "zero.lvm", acc, delta_x="0"), "Delta_X must be one number > 0", "sampling_rate",
             positions=POSITIONS)
    path = _lvm(tmp_path / "r.lvm", acc)
    text = path.read_text()
    cut = tmp_path / "cut.lvm"
    cut.write_text(text[:text.index("Delta_X")])
    _refused(cut, "cannot read the file as LVM|holds 0 data segments|no rows", positions=POSITIONS)
    bad = tmp_path / "bad.lvm"
    bad.write_bytes(b"\x00\x01binary" * 50)
    _refused(bad, "not an LVM file", positions=POSITIONS)
    renamed = tmp_path / "notlvm.lvm"
    renamed.write_text("time,a\n0,1\n")
    _refused(renamed, "not an LVM file: its first line is 'time,a'", positions=POSITIONS)


# ---------------------------------------------------------------- MATLAB structs


def _cell(names):
    cell = np.empty((1, len(names)), dtype=object)
    cell[0, :] = names
    return cell


def test_a_matlab_struct_field_is_the_record_with_the_struct_s_fs(tmp_path):
    acc = _signals()
    path = tmp_path / "rec.mat"
    scipy.io.savemat(path, {"rec": {"acc": acc, "fs": FS, "channel_names": _cell(["acc1", "acc2"])}, "fs": 50.0})
    record = read_record(path, positions=POSITIONS, variable="rec.acc")
    assert record.sampling_rate == FS and record.channel_names == ("acc1", "acc2")  # rec.fs, not the file's fs
    np.testing.assert_array_equal(record.acceleration, acc)
    assert read_record(path, positions=POSITIONS).sampling_rate == FS  # the only matrix: no option needed
    _refused(path, r"no variable 'rec.accel' in the file \(variables: rec.acc, rec.fs, rec.channel_names, fs\)",
             "variable", positions=POSITIONS, variable="rec.accel")
    # No fs in the struct: the file's; neither: the option.
    scipy.io.savemat(path, {"rec": {"acc": acc}, "fs": FS})
    assert read_record(path, positions=POSITIONS, variable="rec.acc").sampling_rate == FS
    scipy.io.savemat(path, {"rec": {"acc": acc, "meta": {"note": "x"}}})
    _refused(path, "no sampling rate: the struct 'rec' nor the file hold none", "sampling_rate", positions=POSITIONS,
             variable="rec.acc")
    assert read_record(path, positions=POSITIONS, variable="rec.acc", sampling_rate=FS).sampling_rate == FS
    nested = tmp_path / "nested.mat"
    scipy.io.savemat(nested, {"test": {"run": {"acc": acc, "Fs": FS}}})
    assert read_record(nested, positions=POSITIONS, variable="test.run.acc").sampling_rate == FS


def _mat_v73_struct(path: Path, acc: np.ndarray, fs: float) -> Path:
    """MATLAB v7.3 as MATLAB writes a struct: a group (MATLAB_class struct) whose fields are datasets."""
    with h5py.File(path, "w", userblock_size=512) as h5:
        group = h5.create_group("rec")
        group.attrs["MATLAB_class"] = np.bytes_("struct")
        for name, value in (("acc", acc), ("fs", np.array([[fs]]))):
            group[name] = np.asarray(value, dtype=np.float64).T
            group[name].attrs["MATLAB_class"] = np.bytes_("double")
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Sun Mar  1 10:00:00 2026 HDF5 schema 1.00 ."
    with open(path, "r+b") as stream:
        stream.write((header.ljust(116) + b" " * 8 + b"\x00\x02" + b"IM").ljust(512, b"\0"))
    return path


def test_a_matlab_v73_struct_field_is_the_record(tmp_path):
    acc = _signals()
    path = _mat_v73_struct(tmp_path / "rec.mat", acc, FS)
    record = read_record(path, positions=POSITIONS, variable="rec.acc")
    assert record.sampling_rate == FS
    np.testing.assert_array_equal(record.acceleration, acc)


# ---------------------------------------------------------------- HDF5: complex positions


def test_an_hdf5_record_with_complex_positions_is_refused(tmp_path):
    path = tmp_path / "r.h5"
    write_record(Record(_signals(), FS, ("acc1", "acc2"), np.array([4.5, 9.9])), path)
    with h5py.File(path, "r+") as h5:
        del h5["channel_position"]
        h5["channel_position"] = np.array([4.5 + 1j, 9.9 + 0j])
    _refused(path, "must be real numbers .* got complex128", "channel_position")
    with pytest.raises(InputError, match="positions must be real numbers") as info:  # the record's own check too
        Record(_signals(), FS, ("acc1", "acc2"), np.array([4.5 + 1j, 9.9]))
    assert info.value.field == "channel_position"


# ---------------------------------------------------------------- garbage: one line, never a traceback


@pytest.fixture(scope="module")
def samples(tmp_path_factory):
    root = tmp_path_factory.mktemp("garbage")
    acc = _signals(60)
    return {"toa5": _toa5(root / "r.dat", acc).read_bytes(), "lvm": _lvm(root / "r.lvm", acc).read_bytes(),
            "preamble": _dewesoft(root / "r.txt", acc).read_bytes()}


@pytest.mark.parametrize("kind", ["toa5", "lvm", "preamble"])
def test_truncated_and_mutated_files_give_one_line_never_a_traceback(tmp_path, samples, kind):
    """Each sample file cut at many places and with bytes flipped: read, or refused with an InputError naming
    the file (any other exception, or a warning other than a dropped channel, fails: warnings are errors)."""
    suffix = {"toa5": ".dat", "lvm": ".lvm", "preamble": ".txt"}[kind]
    options = {"positions": POSITIONS,
               **({"separator": ";", "decimal": ",", "skip_rows": [1], "time_column": "Time"} if kind == "preamble"
                  else {})}
    data = samples[kind]
    rng = np.random.default_rng(7)
    variants = [data[:cut] for cut in sorted(set(rng.integers(0, len(data), 40).tolist()))]
    for _ in range(40):
        flipped = bytearray(data)
        for at in rng.integers(0, len(data), 3):
            flipped[at] = int(rng.integers(0, 256))
        variants.append(bytes(flipped))
    read = 0
    for k, variant in enumerate(variants):
        path = tmp_path / f"v{k}{suffix}"
        path.write_bytes(variant)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RecordWarning)
                read_record(path, **options)
            read += 1
        except InputError as err:
            assert err.file == str(path) and "\n" not in str(err), str(err)
    assert read > 0  # some variants are still records (a cut after the last row, a flipped digit)


def test_samples_too_large_for_their_spread_are_refused_not_a_warning(tmp_path):
    """A corrupt binary file's flipped exponent (1e200 m/s²): the spread of the channel overflows; refused in one
    line (it used to be a RuntimeWarning from the screening, an error under this suite's warning filter)."""
    acc = _signals()
    acc[10, 1] = 1e200
    path = tmp_path / "r.h5"
    write_record(Record(np.ones((2, 2)), FS, ("acc1", "acc2"), np.array([4.5, 9.9])), path)
    with h5py.File(path, "r+") as h5:
        del h5["acceleration"]
        h5["acceleration"] = acc
    _refused(path, "channel 'acc2' has samples up to 1e\\+200 m/s², too large", "acceleration")
