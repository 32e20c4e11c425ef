"""Tests of acceleration-record I/O (stcs_ident.spectra.io).

Round trips through HDF5, CSV and SEP005, then one test per bad input:
each checks the error's field and that its one-line text names the file
and the field. Bad files are written with h5py directly.
"""

from __future__ import annotations

import os

import h5py
import numpy as np
import pandas as pd
import pytest

from stcs_ident.core.errors import InputError, RecordWarning
from stcs_ident.core.record import STANDARD_GRAVITY, Record
from stcs_ident.io.records.csv_text import record_from_csv
from stcs_ident.io.records.hdf5 import read_record, write_record
from stcs_ident.io.records.sep005 import from_sep005, to_sep005
from stcs_ident.io.records.validation import check_duration, check_positions

FS = 200.0  # Hz
N = 2000  # samples: 10 s
NAMES = ("A1", "A2", "A3")
POSITIONS = (2.0, 5.5, 9.0)  # m from end A
START = "2023-06-29T15:00:00+00:00"


def _signals(n: int = N, n_channels: int = 3, seed: int = 0) -> np.ndarray:
    """Sines plus noise: healthy channels, never dead nor clipped."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    return np.column_stack(
        [np.sin(2 * np.pi * (1.3 + j) * t) + 0.1 * rng.standard_normal(n) for j in range(n_channels)]
    )


def _write_h5(path, *, acceleration=None, names=NAMES, positions=POSITIONS, omit=(), **attrs):
    """An HDF5 record as a user would write it; ``omit`` leaves attributes or datasets out."""
    attributes = {"format": "stcs-record", "version": 1, "sampling_rate": FS, "unit": "m/s^2", **attrs}
    datasets = {
        "acceleration": _signals() if acceleration is None else acceleration,
        "channel_name": np.array(names, dtype=h5py.string_dtype()),
        "channel_position": np.asarray(positions, dtype=np.float64),
    }
    with h5py.File(path, "w") as h5:
        for key, value in attributes.items():
            if key not in omit:
                h5.attrs[key] = value
        for key, value in datasets.items():
            if key not in omit:
                h5.create_dataset(key, data=value)
    return path


def _record(acceleration=None, **kwargs) -> Record:
    fields = {"sampling_rate": FS, "channel_names": NAMES, "channel_positions": POSITIONS} | kwargs
    return Record(acceleration=_signals() if acceleration is None else acceleration, **fields)


def _check_error(excinfo, file, field) -> None:
    """The error carries the field, and its one line names the file and the field."""
    err = excinfo.value
    text = str(err)
    assert err.field == field
    assert "\n" not in text
    if file is not None:
        assert text.startswith(f"{file}: ")
    if field is not None:
        assert f"field '{field}'" in text


# ---------------------------------------------------------------- round trips


def test_hdf5_round_trip(tmp_path):
    record = _record(start_time=START)
    path = tmp_path / "rec.h5"
    write_record(record, path)
    back = read_record(path)
    np.testing.assert_array_equal(back.acceleration, record.acceleration)  # float64 both ways: exact
    np.testing.assert_array_equal(back.channel_positions, record.channel_positions)
    assert back.channel_names == NAMES
    assert back.sampling_rate == FS
    assert back.start_time == START
    assert back.source == str(path)
    assert back.dropped == ()
    assert os.listdir(tmp_path) == ["rec.h5"]  # no temporary file left behind


def test_written_layout_follows_contract(tmp_path):
    path = tmp_path / "rec.h5"
    write_record(_record(), path)
    with h5py.File(path, "r") as h5:
        assert h5.attrs["format"] == "stcs-record" and h5.attrs["version"] == 1 and h5.attrs["unit"] == "m/s^2"
        assert "start_time" not in h5.attrs
        assert h5["acceleration"].dtype == np.float64 and h5["acceleration"].shape == (N, 3)
        assert list(h5["channel_name"].asstr()[()]) == list(NAMES)
        assert h5["channel_position"].dtype == np.float64


def test_failed_write_leaves_target_untouched(tmp_path, monkeypatch):
    path = tmp_path / "rec.h5"
    path.write_bytes(b"old")

    def refuse(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", refuse)
    with pytest.raises(OSError, match="disk full"):
        write_record(_record(), path)
    assert path.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["rec.h5"]


def test_float32_and_start_time_read(tmp_path):
    acceleration = _signals().astype(np.float32)
    record = read_record(_write_h5(tmp_path / "rec.h5", acceleration=acceleration, start_time=START))
    assert record.acceleration.dtype == np.float64
    np.testing.assert_array_equal(record.acceleration, acceleration.astype(np.float64))
    assert record.start_time == START


def test_g_converted_to_si(tmp_path):
    acceleration = _signals()
    record = read_record(_write_h5(tmp_path / "rec.h5", acceleration=acceleration, unit="g"))
    # One multiplication by the defined constant: equal to the last bit.
    np.testing.assert_array_equal(record.acceleration, acceleration * STANDARD_GRAVITY)


@pytest.mark.parametrize("as_mapping", [True, False], ids=["mapping", "sequence"])
def test_csv_round_trip(tmp_path, as_mapping):
    acceleration = _signals()
    table = pd.DataFrame(acceleration, columns=NAMES)
    table.insert(0, "time", np.arange(N) / FS)
    path = tmp_path / "rec.csv"
    table.to_csv(path, index=False)
    positions = dict(zip(NAMES, POSITIONS)) if as_mapping else POSITIONS
    record = record_from_csv(path, positions)
    # pandas writes floats with round-trip precision: exact.
    np.testing.assert_array_equal(record.acceleration, acceleration)
    np.testing.assert_allclose(record.sampling_rate, FS, rtol=1e-12)
    assert record.channel_names == NAMES
    np.testing.assert_array_equal(record.channel_positions, POSITIONS)
    assert record.source == str(path)


def test_csv_in_g(tmp_path):
    path = tmp_path / "rec.csv"
    pd.DataFrame({"time": np.arange(N) / FS, "A1": _signals()[:, 0]}).to_csv(path, index=False)
    record = record_from_csv(path, [3.0], unit="g")
    np.testing.assert_array_equal(record.acceleration[:, 0], _signals()[:, 0] * STANDARD_GRAVITY)


def test_sep005_round_trip():
    record = _record(start_time=START)
    channels = to_sep005(record)
    assert [c["name"] for c in channels] == list(NAMES)
    for channel in channels:
        assert channel["fs"] == FS and channel["quantity"] == "acceleration" and channel["unit_str"] == "m/s^2"
        assert channel["data"].ndim == 1 and channel["start_timestamp"] == START
    back = from_sep005(channels)
    np.testing.assert_array_equal(back.acceleration, record.acceleration)
    np.testing.assert_array_equal(back.channel_positions, POSITIONS)
    assert back.channel_names == NAMES and back.sampling_rate == FS and back.start_time == START


def test_sep005_positions_argument_and_g():
    data = _signals()
    channels = [{"name": n, "data": data[:, j], "fs": FS, "unit_str": "g"} for j, n in enumerate(NAMES)]
    record = from_sep005(channels, positions=dict(zip(NAMES, POSITIONS)))
    np.testing.assert_array_equal(record.channel_positions, POSITIONS)
    np.testing.assert_array_equal(record.acceleration, data * STANDARD_GRAVITY)


def test_sep005_without_position_refused():
    channels = [{"name": "A1", "data": _signals()[:, 0], "fs": FS, "unit_str": "m/s^2"}]
    with pytest.raises(InputError, match="no position for channel 'A1'") as excinfo:
        from_sep005(channels)
    _check_error(excinfo, None, "channel_position")


def test_sep005_sampling_rates_must_agree():
    channels = to_sep005(_record())
    channels[1]["fs"] = 2 * FS
    with pytest.raises(InputError) as excinfo:
        from_sep005(channels)
    _check_error(excinfo, None, "sampling_rate")


# ---------------------------------------------------------------- samples


@pytest.mark.parametrize("bad, shown", [(np.nan, "NaN"), (np.inf, "inf")])
def test_non_finite_samples_refused(tmp_path, bad, shown):
    acceleration = _signals()
    acceleration[17, 1] = bad
    acceleration[40, 1] = bad
    path = _write_h5(tmp_path / "rec.h5", acceleration=acceleration)
    with pytest.raises(InputError, match=f"channel 'A2' has {shown} at sample 17") as excinfo:
        read_record(path)
    _check_error(excinfo, path, "acceleration")


def test_dead_channel_dropped_with_warning(tmp_path):
    acceleration = _signals()
    acceleration[:, 1] = 0.25  # a constant offset: the sensor is dead
    path = _write_h5(tmp_path / "rec.h5", acceleration=acceleration)
    with pytest.warns(RecordWarning, match="A2") as caught:
        record = read_record(path)
    assert str(path) in str(caught[0].message)
    assert record.channel_names == ("A1", "A3")
    np.testing.assert_array_equal(record.channel_positions, [POSITIONS[0], POSITIONS[2]])
    assert record.dropped == (("A2", "dead: constant signal"),)


def test_clipped_channel_dropped_with_warning(tmp_path):
    acceleration = _signals()
    acceleration[:, 2] = np.clip(2.0 * acceleration[:, 2], -1.5, 1.5)  # saturates at every peak
    path = _write_h5(tmp_path / "rec.h5", acceleration=acceleration)
    with pytest.warns(RecordWarning, match="A3") as caught:
        record = read_record(path)
    assert str(path) in str(caught[0].message)
    assert record.channel_names == ("A1", "A2")
    assert record.dropped == (("A3", "clipped at ±1.5 m/s²"),)


def test_brief_hold_at_the_peak_is_not_clipping(tmp_path):
    # 5 samples at the maximum: shorter than 20 and under 0.5 % of 2000.
    acceleration = _signals()
    peak = int(np.argmax(acceleration[:, 0]))
    acceleration[peak : peak + 5, 0] = acceleration[peak, 0]
    record = read_record(_write_h5(tmp_path / "rec.h5", acceleration=acceleration))
    assert record.channel_names == NAMES


def test_all_channels_dead_refused(tmp_path):
    path = _write_h5(tmp_path / "rec.h5", acceleration=np.zeros((N, 3)))
    with pytest.raises(InputError, match="no usable channel") as excinfo:
        read_record(path)
    _check_error(excinfo, path, "acceleration")


# ---------------------------------------------------------------- datasets


@pytest.mark.parametrize(
    "acceleration, field",
    [
        (np.ones(N), "acceleration"),  # 1-D
        (np.ones((N, 3, 2)), "acceleration"),  # 3-D
        (np.ones((0, 3)), "acceleration"),  # no samples
        (_signals(n_channels=2), "channel_name"),  # 2 channels, 3 names
    ],
    ids=["1-D", "3-D", "no-samples", "channel-count"],
)
def test_wrong_shape_refused(tmp_path, acceleration, field):
    path = _write_h5(tmp_path / "rec.h5", acceleration=acceleration)
    with pytest.raises(InputError) as excinfo:
        read_record(path)
    _check_error(excinfo, path, field)


@pytest.mark.parametrize("name", ["acceleration", "channel_name", "channel_position"])
def test_missing_dataset_refused(tmp_path, name):
    path = _write_h5(tmp_path / "rec.h5", omit=(name,))
    with pytest.raises(InputError, match="missing dataset") as excinfo:
        read_record(path)
    _check_error(excinfo, path, name)


def test_duplicate_channel_names_refused(tmp_path):
    path = _write_h5(tmp_path / "rec.h5", names=("A1", "A2", "A1"))
    with pytest.raises(InputError, match="duplicate channel name 'A1'") as excinfo:
        read_record(path)
    _check_error(excinfo, path, "channel_name")


def test_non_finite_position_refused(tmp_path):
    path = _write_h5(tmp_path / "rec.h5", positions=(2.0, np.nan, 9.0))
    with pytest.raises(InputError, match="'A2'") as excinfo:
        read_record(path)
    _check_error(excinfo, path, "channel_position")


# ---------------------------------------------------------------- attributes


@pytest.mark.parametrize("name", ["format", "version", "sampling_rate", "unit"])
def test_missing_attribute_refused(tmp_path, name):
    path = _write_h5(tmp_path / "rec.h5", omit=(name,))
    with pytest.raises(InputError, match="missing root attribute") as excinfo:
        read_record(path)
    _check_error(excinfo, path, name)


@pytest.mark.parametrize("rate", [0.0, -200.0, np.inf])
def test_bad_sampling_rate_refused(tmp_path, rate):
    path = _write_h5(tmp_path / "rec.h5", sampling_rate=rate)
    with pytest.raises(InputError, match="> 0") as excinfo:
        read_record(path)
    _check_error(excinfo, path, "sampling_rate")


def test_unknown_unit_refused(tmp_path):
    path = _write_h5(tmp_path / "rec.h5", unit="m/s")  # a velocity
    with pytest.raises(InputError, match="'m/s'.*use one of m/s\\^2") as excinfo:
        read_record(path)
    _check_error(excinfo, path, "unit")


@pytest.mark.parametrize("unit,scale", [("m/s^2", 1.0), ("m/s²", 1.0), ("m/s2", 1.0), (" m/s2 ", 1.0),
                                        ("mm/s^2", 1e-3), ("mm/s2", 1e-3), ("g", 9.80665), ("G", 9.80665),
                                        ("mg", 9.80665e-3)])
def test_the_unit_spellings_of_data_loggers_are_read_with_their_scale(tmp_path, unit, scale):
    """One table of unit spellings serves every reader: HDF5's unit and SEP005's unit_str alike."""
    acceleration = _signals()
    record = read_record(_write_h5(tmp_path / "rec.h5", acceleration=acceleration, unit=unit))
    np.testing.assert_allclose(record.acceleration, acceleration * scale, rtol=1e-15)
    channels = [{"name": n, "data": acceleration[:, j], "fs": FS, "unit_str": unit, "position": p}
                for j, (n, p) in enumerate(zip(NAMES, POSITIONS))]
    np.testing.assert_allclose(from_sep005(channels).acceleration, acceleration * scale, rtol=1e-15)


@pytest.mark.parametrize("field, value", [("format", "other-record"), ("version", 2), ("start_time", "yesterday")])
def test_bad_attribute_value_refused(tmp_path, field, value):
    path = _write_h5(tmp_path / "rec.h5", **{field: value})
    with pytest.raises(InputError) as excinfo:
        read_record(path)
    _check_error(excinfo, path, field)


# ---------------------------------------------------------------- files


def test_non_hdf5_file_refused(tmp_path):
    path = tmp_path / "rec.h5"
    path.write_text("time,A1\n0,1\n")
    with pytest.raises(InputError, match="not an HDF5 file") as excinfo:
        read_record(path)
    _check_error(excinfo, path, None)


def test_missing_file_refused(tmp_path):
    path = tmp_path / "absent.h5"
    with pytest.raises(InputError, match="file not found") as excinfo:
        read_record(path)
    _check_error(excinfo, path, None)


def test_non_uniform_csv_time_refused(tmp_path):
    table = pd.DataFrame(_signals(), columns=NAMES)
    table.insert(0, "time", np.arange(N) / FS)
    path = tmp_path / "rec.csv"
    table.drop(index=500).to_csv(path, index=False)  # one sample lost
    with pytest.raises(InputError, match="not uniformly sampled") as excinfo:
        record_from_csv(path, POSITIONS)
    _check_error(excinfo, path, "time")


def test_csv_text_sample_refused(tmp_path):
    path = tmp_path / "rec.csv"
    path.write_text("time,A1\n0.0,1.0\n0.005,oops\n0.01,2.0\n")
    with pytest.raises(InputError, match="line 3") as excinfo:
        record_from_csv(path, [1.0])
    _check_error(excinfo, path, "acceleration")


# ---------------------------------------------------------------- checks against the cable


def test_position_outside_span_refused(tmp_path):
    record = read_record(_write_h5(tmp_path / "rec.h5", positions=(2.0, 5.5, 25.0)))
    check_positions(record, 30.0)  # inside a longer cable: fine
    with pytest.raises(InputError, match="'A3'") as excinfo:
        check_positions(record, 20.0)
    _check_error(excinfo, record.source, "channel_position")


def test_record_shorter_than_five_periods_refused(tmp_path):
    record = read_record(_write_h5(tmp_path / "rec.h5", acceleration=_signals(n=400)))  # 2 s
    check_duration(record, f1=3.0)  # 5 periods = 1.67 s: enough
    with pytest.raises(InputError, match="lasts 2 s.*at least 5 s") as excinfo:
        check_duration(record, f1=1.0)
    _check_error(excinfo, record.source, "acceleration")


def test_hdf5_options_stand_in_for_and_replace_the_file_s_rate_and_unit(tmp_path):
    """A campaign's record_format applies to HDF5 too: sampling_rate stands in for a missing attribute, and a
    unit given replaces the file's (the record lists what it replaced)."""
    from stcs_ident.io.records import read_record as read_any

    path = tmp_path / "r.h5"
    write_record(_record(), path)
    with h5py.File(path, "r+") as h5:
        del h5.attrs["sampling_rate"]
    with pytest.raises(InputError, match="missing root attribute"):
        read_any(path)
    record = read_any(path, sampling_rate=50.0, unit="g")
    assert record.sampling_rate == 50.0 and record.replaced == (("unit", "g", "m/s^2"),)
    # One multiplication each way: equal to within one rounding.
    np.testing.assert_allclose(record.acceleration, _record().acceleration * STANDARD_GRAVITY, rtol=1e-15)
