"""A ``sampling_rate`` in record_format that disagrees with the file's own rate is refused, in every format that
has one; ``override_sampling_rate = true`` makes it replace the file's (and ``Record.replaced`` says so); a rate
that agrees within the file's rounding is taken silently; a file without a rate takes the given one.

The file's rate is 100 Hz here; the given 200 Hz would double every frequency (and quadruple the tension). The
tolerances tested at their edges are those of stcs_ident.io.records.rates: a stored binary number 1e-6
relative, a time column its printed resolution over the record's span plus 1e-6, UFF's six printed digits.
"""

from __future__ import annotations

import gc
import json
import warnings
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
import scipy.io
from nptdms import ChannelObject, TdmsWriter

from stcs_ident.core.errors import InputError
from stcs_ident.core.record import Record
from stcs_ident.io.records import read_record
from stcs_ident.io.records.hdf5 import write_record
from stcs_ident.io.records.rates import STORED_RTOL, FileRate, printed_resolution, resolved_rate
from stcs_ident.io.records.sep005 import write_sep005
from stcs_ident.io.records.uff import PRINTED_RTOL
from tests.test_logger_layouts import _lvm, _toa5

FS = 100.0
N = 400
NAMES = ("acc1", "acc2")
POSITIONS = {"acc1": 4.5, "acc2": 9.9}


def _acc(n: int = N) -> np.ndarray:
    rng = np.random.default_rng(3)
    return rng.standard_normal((n, 2))


def _csv(path: Path, acc: np.ndarray) -> Path:
    lines = ["time,acc1,acc2", *(",".join(repr(float(x)) for x in (k / FS, *row)) for k, row in enumerate(acc))]
    path.write_text("\n".join(lines) + "\n")
    return path


def _csv_datetimes(path: Path, acc: np.ndarray) -> Path:
    start = pd.Timestamp("2026-03-01T00:00:00")
    lines = ["time,acc1,acc2"]
    lines += [",".join([(start + pd.Timedelta(milliseconds=10 * k)).isoformat(timespec="milliseconds"),
                        *map(repr, map(float, row))]) for k, row in enumerate(acc)]
    path.write_text("\n".join(lines) + "\n")
    return path


def _hdf5(path: Path, acc: np.ndarray) -> Path:
    write_record(Record(acc, FS, NAMES, np.array([4.5, 9.9])), path)
    return path


def _mat(path: Path, acc: np.ndarray) -> Path:
    names = np.empty((1, 2), dtype=object)
    names[0, :] = NAMES
    scipy.io.savemat(path, {"acc": acc, "fs": FS, "channel_names": names})
    return path


def _mat_struct(path: Path, acc: np.ndarray) -> Path:
    scipy.io.savemat(path, {"rec": {"acc": acc, "fs": FS}, "fs": 50.0})  # the struct's fs is the record's
    return path


def _tdms(path: Path, acc: np.ndarray) -> Path:
    props = {"wf_increment": 1.0 / FS, "unit_string": "m/s^2"}
    with TdmsWriter(str(path)) as writer:
        writer.write_segment([ChannelObject("G", name, acc[:, k], props) for k, name in enumerate(NAMES)])
    return path


def _uff(path: Path, acc: np.ndarray) -> Path:
    import pyuff

    sets = [pyuff.prepare_58(binary=1, func_type=1, rsp_node=k + 1, rsp_dir=1, ref_node=0, ref_dir=0,
                             rsp_ent_name=name, abscissa_spacing=1, ordinate_spec_data_type=12,
                             orddenom_spec_data_type=0, ordinate_axis_units_lab="m/s^2",
                             abscissa_axis_units_lab="s", data=acc[:, k], x=np.arange(len(acc)) / FS,
                             id1=f"channel {name}")
            for k, name in enumerate(NAMES)]
    with warnings.catch_warnings():  # pyuff's writer leaves its file to the garbage collector
        warnings.simplefilter("ignore", ResourceWarning)
        pyuff.UFF(str(path)).write_sets(sets, mode="add", force_double=True)
        gc.collect()
    return path


def _sep005(path: Path, acc: np.ndarray) -> Path:
    write_sep005(Record(acc, FS, NAMES, np.array([4.5, 9.9])), path)
    return path


def _toa5_file(path: Path, acc: np.ndarray) -> Path:
    return _toa5(path, acc, units=("m/s^2", "m/s^2"))


def _lvm_file(path: Path, acc: np.ndarray) -> Path:
    return _lvm(path, acc, units=("m/s^2", "m/s^2"))


#: (suffix, writer, where the file's rate comes from, as the message names it)
FORMATS = {
    "csv": (".csv", _csv, "time column 'time'"),
    "csv-datetimes": (".csv", _csv_datetimes, "time column 'time'"),
    "toa5": (".dat", _toa5_file, "time column 'TIMESTAMP'"),
    "lvm": (".lvm", _lvm_file, "Delta_X"),
    "hdf5": (".h5", _hdf5, "attribute sampling_rate"),
    "mat": (".mat", _mat, "variable 'fs'"),
    "mat-struct": (".mat", _mat_struct, "variable 'rec.fs'"),
    "tdms": (".tdms", _tdms, "wf_increment"),
    "uff": (".uff", _uff, "abscissa increment"),
    "sep005": (".json", _sep005, "channels' rate"),
}


def _write(tmp_path: Path, kind: str) -> Path:
    suffix, writer, _ = FORMATS[kind]
    return writer(tmp_path / f"r{suffix}", _acc())


@pytest.mark.parametrize("kind", list(FORMATS))
def test_a_conflicting_rate_is_refused_naming_both_and_the_override(tmp_path, kind):
    path = _write(tmp_path, kind)
    assert read_record(path, positions=POSITIONS).sampling_rate == pytest.approx(FS, rel=1e-9)  # the file's own
    with pytest.raises(InputError) as info:
        read_record(path, positions=POSITIONS, sampling_rate=2 * FS)
    text = str(info.value)
    assert info.value.field == "sampling_rate" and info.value.file == str(path) and "\n" not in text
    source = FORMATS[kind][2]
    assert f"record_format gives sampling_rate 200 Hz, the file's {source}" in text, text
    assert "says 100 Hz" in text or "says 99.99999" in text or "says 100.0000" in text, text
    assert "every frequency would be scaled by 2" in text and "override_sampling_rate = true to use 200 Hz" in text


@pytest.mark.parametrize("kind", list(FORMATS))
def test_override_sampling_rate_replaces_the_file_s_and_says_so(tmp_path, kind):
    path = _write(tmp_path, kind)
    record = read_record(path, positions=POSITIONS, sampling_rate=2 * FS, override_sampling_rate=True)
    assert record.sampling_rate == 2 * FS
    (entry,) = [item for item in record.replaced if item[0] == "sampling_rate"]
    assert entry[1] == 2 * FS and entry[2] == pytest.approx(FS, rel=1e-9)
    # The same rate as the file's, with or without the override: nothing replaced, nothing said.
    same = read_record(path, positions=POSITIONS, sampling_rate=FS, override_sampling_rate=True)
    assert same.sampling_rate == FS and not [item for item in same.replaced if item[0] == "sampling_rate"]


@pytest.mark.parametrize(("kind", "inside", "outside"), [
    # binary numbers: 1e-6 relative (STORED_RTOL)
    ("hdf5", 0.5 * STORED_RTOL, 2 * STORED_RTOL), ("mat", 0.5 * STORED_RTOL, 2 * STORED_RTOL),
    ("tdms", 0.5 * STORED_RTOL, 2 * STORED_RTOL), ("sep005", 0.5 * STORED_RTOL, 2 * STORED_RTOL),
    # UFF's increment printed to six significant digits: 5e-6 + 1e-6
    ("uff", 0.9 * PRINTED_RTOL, 1.1 * PRINTED_RTOL),
    # a time column printed to every digit of 0.01 s steps (repr): the span 3.99 s to ~1e-17 s, plus 1e-6
    ("csv", 0.5e-6, 3e-6),
    # date-times to the millisecond over 3.99 s: 1e-3 / 3.99 + 1e-6 = 2.516e-4
    ("csv-datetimes", 2.4e-4, 2.7e-4), ("toa5", 2.4e-3, 2.7e-3),  # TOA5 to 10 ms: 1e-2 / 3.99 + 1e-6
    # LVM's Delta_X 0.010000: half a unit of its last digit over it, 5e-5, plus 1e-6
    ("lvm", 4.5e-5, 6e-5),
])
def test_a_rate_within_the_file_s_rounding_is_taken_silently_and_one_beyond_is_refused(tmp_path, kind, inside,
                                                                                      outside):
    path = _write(tmp_path, kind)
    close = FS * (1 + inside)
    record = read_record(path, positions=POSITIONS, sampling_rate=close)
    assert record.sampling_rate == close and record.replaced == ()
    with pytest.raises(InputError, match="every frequency would be scaled by 1.0") as info:
        read_record(path, positions=POSITIONS, sampling_rate=FS * (1 + outside))
    assert info.value.field == "sampling_rate"


def test_a_time_column_printed_to_few_digits_agrees_with_the_rate_it_rounds(tmp_path):
    """0.00390625 s steps printed to 7 significant digits: not uniform (so sampling_rate is needed), and 256 Hz
    agrees with it; 256.5 Hz does not."""
    acc = _acc(2048)
    lines = ["time;acc1;acc2", *(";".join([f"{k / 256:.7g}".replace(".", ","), *(repr(float(x)).replace(".", ",")
                                                                               for x in row)])
                                 for k, row in enumerate(acc))]
    path = tmp_path / "r.csv"
    path.write_text("\n".join(lines) + "\n")
    options = {"positions": POSITIONS, "separator": ";", "decimal": ","}
    with pytest.raises(InputError, match="not uniformly sampled.*give sampling_rate"):
        read_record(path, **options)
    record = read_record(path, sampling_rate=256.0, **options)
    assert record.sampling_rate == 256.0 and record.replaced == ()
    with pytest.raises(InputError, match=r"gives sampling_rate 256.5 Hz, the file's time column 'time' says 255.99999"):
        read_record(path, sampling_rate=256.5, **options)


def test_a_file_without_a_rate_takes_the_given_one(tmp_path):
    acc = _acc()
    csv = tmp_path / "r.csv"
    csv.write_text("\n".join(["acc1,acc2", *(",".join(map(repr, map(float, row))) for row in acc)]) + "\n")
    assert read_record(csv, positions=POSITIONS, sampling_rate=200.0).sampling_rate == 200.0
    h5 = _hdf5(tmp_path / "r.h5", acc)
    with h5py.File(h5, "r+") as file:
        del file.attrs["sampling_rate"]
    record = read_record(h5, sampling_rate=200.0)
    assert record.sampling_rate == 200.0 and record.replaced == ()
    mat = tmp_path / "r.mat"
    scipy.io.savemat(mat, {"acc": acc})
    assert read_record(mat, positions=POSITIONS, sampling_rate=200.0).sampling_rate == 200.0
    text = _lvm(tmp_path / "r.lvm", acc, units=("m/s^2", "m/s^2"), x_columns="No").read_text()
    lvm = tmp_path / "r2.lvm"
    lvm.write_text(text.replace("Delta_X\t0.010000\t0.010000\t\n", ""))
    with pytest.raises(InputError, match="no Delta_X and no X_Value column; give sampling_rate") as info:
        read_record(lvm, positions=POSITIONS)
    assert info.value.field == "sampling_rate"
    assert read_record(lvm, positions=POSITIONS, sampling_rate=200.0).sampling_rate == 200.0


def test_a_csv_time_column_unreadable_as_times_gives_no_rate_to_conflict_with(tmp_path):
    acc = _acc()
    path = tmp_path / "r.csv"
    path.write_text("\n".join(["time,acc1,acc2", *(",".join([f"t{k}", *map(repr, map(float, row))])
                                                   for k, row in enumerate(acc))]) + "\n")
    assert read_record(path, positions=POSITIONS, sampling_rate=200.0).sampling_rate == 200.0


def test_resolved_rate_and_printed_resolution():
    replaced: list = []
    found = FileRate(100.0, "attribute sampling_rate")
    assert resolved_rate(None, found, file="f", replaced=replaced) == 100.0
    assert resolved_rate(100.00005, found, file="f", replaced=replaced) == 100.00005 and replaced == []
    assert resolved_rate(120.0, None, file="f", replaced=replaced) == 120.0
    assert resolved_rate(120.0, found, override=True, file="f", replaced=replaced) == 120.0
    assert replaced == [("sampling_rate", 120.0, 100.0)]
    with pytest.raises(InputError, match="scaled by 1.2;") as info:
        resolved_rate(120.0, found, file="f", replaced=[])
    assert info.value.field == "sampling_rate" and info.value.file == "f"
    assert [printed_resolution(t) for t in ("0.0039", "3.9e-3", "20", "1,25", "-0.5E+2", "x", "", None)] == [
        pytest.approx(1e-4), pytest.approx(1e-4), 1.0, pytest.approx(1e-2), pytest.approx(10.0), None, None, None]


def test_the_campaign_s_override_reaches_the_reader(tmp_path):
    """override_sampling_rate in [test.record_format] is an option like the others: opening a test's record passes
    it to read_record."""
    from stcs_ident.io.campaign import load_campaign
    from stcs_ident.io.test_record import open_test_record
    from tests.fuzz_inputs import BASE_TOML, _frequencies

    (tmp_path / "records").mkdir()
    _csv(tmp_path / "records" / "T2.csv", _acc())
    extra = ('  [test.channels]\n  acc1 = 4.5\n  acc2 = 9.9\n  [test.record_format]\n  sampling_rate = 200.0\n')
    text = BASE_TOML.format(f=_frequencies()).replace('record = "records/T2.h5"\n', 'record = "records/T2.csv"\n' + extra)
    (tmp_path / "campaign.toml").write_text(text, encoding="utf-8")
    campaign = load_campaign(tmp_path)
    with pytest.raises(InputError, match="override_sampling_rate"):
        open_test_record(campaign, campaign.test("T2"))
    (tmp_path / "campaign.toml").write_text(text.replace("sampling_rate = 200.0\n", "sampling_rate = 200.0\n"
                                                         "  override_sampling_rate = true\n"), encoding="utf-8")
    _, record = open_test_record(load_campaign(tmp_path), load_campaign(tmp_path).test("T2"))
    assert record.sampling_rate == 200.0 and record.replaced[0][:2] == ("sampling_rate", 200.0)
    assert json.dumps(record.replaced[0][2]) and record.replaced[0][2] == pytest.approx(FS, rel=1e-12)
