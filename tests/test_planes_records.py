"""Channel directions in records of every format (issue 24): a triaxial sensor is three channels at one position.

The record: two positions, three channels each (in-plane, out-of-plane, axial), written as HDF5 (the dataset,
the attribute), CSV or MATLAB with the campaign's channel table, UFF with response directions placed by the
reader option ``axes``, TDMS and SEP005 with a ``direction`` per channel; each read back with its directions.
Then the refusals, the record without directions (in-plane, with the note), the campaign's round trip and the
directions reaching ``track``'s reader.
"""

from __future__ import annotations

import gc
import re
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest
import scipy.io

from stcs_ident.core.errors import CampaignError, InputError, RecordWarning
from stcs_ident.core.planes import NO_DIRECTIONS_NOTE, directions_note
from stcs_ident.core.record import Record
from stcs_ident.io.campaign import campaign_to_toml, load_campaign
from stcs_ident.io.records import read_record
from stcs_ident.io.records.hdf5 import write_record
from stcs_ident.io.records.options import option_problem
from stcs_ident.io.records.sep005 import write_sep005
from stcs_ident.io.records.validation import check_positions
from stcs_ident.io.test_record import record_reading

NAMES = ("p1_in", "p1_out", "p1_ax", "p2_in", "p2_out", "p2_ax")
POSITIONS = (4.0, 4.0, 4.0, 9.0, 9.0, 9.0)
DIRECTIONS = ("in", "out", "axial", "in", "out", "axial")
#: The sensor's frame as a data logger labels it: X along the cable, Y in its plane, Z normal to it.
AXES = {"X": "axial", "Y": "in", "Z": "out"}
LABELS = ("Y", "Z", "X", "Y", "Z", "X")
RATE = 64.0


@pytest.fixture(scope="module")
def triaxial() -> Record:
    """Two triaxial sensors, 512 samples of distinct noise per channel (no channel dead or clipped)."""
    rng = np.random.default_rng(24)
    return Record(rng.normal(size=(512, 6)), RATE, NAMES, np.array(POSITIONS), start_time="2026-03-01T10:00:00Z",
                  channel_directions=DIRECTIONS)


def _same(read: Record, record: Record, atol: float = 0.0) -> None:
    """``read`` holds ``record``'s channels, at its positions, with its directions."""
    assert read.channel_names == record.channel_names
    assert np.array_equal(read.channel_positions, record.channel_positions)
    assert read.channel_directions == DIRECTIONS
    assert read.directions == DIRECTIONS
    np.testing.assert_allclose(read.acceleration, record.acceleration, rtol=0, atol=atol)


def _one_line(err: pytest.ExceptionInfo, file: Path, field: str, what: str) -> None:
    text = str(err.value)
    assert "\n" not in text
    assert str(file) in text and f"field '{field}'" in text
    assert re.search(what, text), text


def _write_csv(record: Record, path: Path) -> Path:
    columns = np.column_stack([record.time, record.acceleration])
    np.savetxt(path, columns, delimiter=",", header=",".join(("time", *record.channel_names)), comments="",
               fmt="%.17g")
    return path


def _h5_without_dataset(record: Record, path: Path) -> Path:
    """``record`` as HDF5 without the ``/channel_direction`` dataset (attributes are added by the tests)."""
    write_record(Record(record.acceleration, record.sampling_rate, record.channel_names, record.channel_positions),
                 path)
    return path


# ---------------------------------------------------------------- each format, read back with its directions


def test_hdf5_keeps_the_directions_in_its_dataset(triaxial, tmp_path):
    path = tmp_path / "r.h5"
    write_record(triaxial, path)
    with h5py.File(path) as h5:
        assert list(h5["channel_direction"].asstr()[()]) == list(DIRECTIONS)
    _same(read_record(path), triaxial)


@pytest.mark.parametrize("node", ["/", "acceleration"])
def test_hdf5_reads_the_directions_from_an_attribute(triaxial, tmp_path, node):
    path = _h5_without_dataset(triaxial, tmp_path / "r.h5")
    with h5py.File(path, "a") as h5:
        h5[node].attrs["channel_direction"] = list(DIRECTIONS)
    _same(read_record(path), triaxial)


def test_hdf5_dataset_wins_over_the_attributes_and_the_root_over_acceleration(triaxial, tmp_path):
    path = tmp_path / "r.h5"
    write_record(triaxial, path)
    with h5py.File(path, "a") as h5:
        h5.attrs["channel_direction"] = ["out"] * 6
        h5["acceleration"].attrs["channel_direction"] = ["axial"] * 6
    assert read_record(path).channel_directions == DIRECTIONS
    with h5py.File(path, "a") as h5:
        del h5["channel_direction"]
    assert read_record(path).channel_directions == ("out",) * 6


def test_hdf5_axis_labels_are_placed_by_the_option_axes(triaxial, tmp_path):
    path = _h5_without_dataset(triaxial, tmp_path / "r.h5")
    with h5py.File(path, "a") as h5:
        h5.attrs["channel_direction"] = list(LABELS)
    _same(read_record(path, axes=AXES), triaxial)


def test_csv_takes_the_directions_of_the_channel_table(triaxial, tmp_path):
    path = _write_csv(triaxial, tmp_path / "r.csv")
    read = read_record(path, positions=dict(zip(NAMES, POSITIONS)), directions=dict(zip(NAMES, DIRECTIONS)))
    _same(read, triaxial, atol=0.0)  # written with 17 digits: read back exactly


def test_matlab_takes_the_directions_of_the_channel_table_or_its_own(triaxial, tmp_path):
    path = tmp_path / "r.mat"
    scipy.io.savemat(path, {"acc": triaxial.acceleration, "fs": RATE,
                            "channel_names": np.array(NAMES, dtype=object)})
    read = read_record(path, positions=dict(zip(NAMES, POSITIONS)), directions=dict(zip(NAMES, DIRECTIONS)))
    _same(read, triaxial)
    scipy.io.savemat(path, {"acc": triaxial.acceleration, "fs": RATE, "channel_names": np.array(NAMES, dtype=object),
                            "channel_directions": np.array(LABELS, dtype=object)})
    _same(read_record(path, positions=dict(zip(NAMES, POSITIONS)), axes=AXES), triaxial)


def _write_uff(record: Record, path: Path, codes) -> Path:
    import pyuff

    sets = [pyuff.prepare_58(binary=1, func_type=1, rsp_node=k + 1, rsp_dir=int(code), ref_node=0, ref_dir=0,
                             rsp_ent_name=name, abscissa_spacing=1, ordinate_spec_data_type=12,
                             orddenom_spec_data_type=0, ordinate_axis_units_lab="m/s^2",
                             abscissa_axis_units_lab="s", data=record.acceleration[:, k], x=record.time)
            for k, (name, code) in enumerate(zip(record.channel_names, codes))]
    with warnings.catch_warnings():  # pyuff's writer leaves its file to the garbage collector
        warnings.simplefilter("ignore", ResourceWarning)
        pyuff.UFF(str(path)).write_sets(sets, mode="add", force_double=True)
        gc.collect()
    return path


#: UFF response directions of LABELS (1, 2, 3: X, Y, Z), one of them negative (-Z: the same plane).
UFF_CODES = (2, 3, 1, 2, -3, 1)


def test_uff_response_directions_are_placed_by_the_option_axes(triaxial, tmp_path):
    path = _write_uff(triaxial, tmp_path / "r.uff", UFF_CODES)
    read = read_record(path, positions=dict(zip(NAMES, POSITIONS)), axes=AXES)
    _same(read, triaxial)


def test_uff_axes_without_the_option_are_read_in_plane_with_a_warning(triaxial, tmp_path):
    path = _write_uff(triaxial, tmp_path / "r.uff", UFF_CODES)
    with pytest.warns(RecordWarning, match=r"p1_in \(\+Y\).*no axes.*every channel read as in-plane"):
        read = read_record(path, positions=dict(zip(NAMES, POSITIONS)))
    assert read.channel_directions is None and read.directions == ("in",) * 6
    assert directions_note(read) == NO_DIRECTIONS_NOTE


def test_uff_channels_all_along_one_axis_are_read_in_plane_quietly(triaxial, tmp_path):
    """A logger of one-axis sensors writes one axis for all: nothing to place, no warning (warnings are errors)."""
    path = _write_uff(triaxial, tmp_path / "r.uff", (3,) * 6)
    read = read_record(path, positions=dict(zip(NAMES, POSITIONS)))
    assert read.channel_directions is None


def test_uff_scalar_directions_say_nothing(triaxial, tmp_path):
    path = _write_uff(triaxial, tmp_path / "r.uff", (0,) * 6)
    assert read_record(path, positions=dict(zip(NAMES, POSITIONS)), axes=AXES).channel_directions is None


def test_tdms_direction_properties(triaxial, tmp_path):
    from nptdms import ChannelObject, TdmsWriter

    path = tmp_path / "r.tdms"
    given = ("in", "out", 0.0, "Y", "+z", "-X")  # names, an angle as a number, and axes, with and without a sign
    channels = [ChannelObject("acc", name, triaxial.acceleration[:, k],
                              {"wf_increment": 1.0 / RATE, "direction": given[k]}) for k, name in enumerate(NAMES)]
    with TdmsWriter(str(path)) as writer:
        writer.write_segment(channels)
    read = read_record(path, positions=dict(zip(NAMES, POSITIONS)), axes=AXES)
    assert read.channel_directions == ("in", "out", "in", "in", "out", "axial")
    with pytest.raises(InputError) as err:
        read_record(path, positions=dict(zip(NAMES, POSITIONS)), axes={"X": "axial", "Y": "in"})
    _one_line(err, path, "axes", r"channel 'p2_out' is along Z.*does not place")


def test_sep005_writes_and_reads_the_directions(triaxial, tmp_path):
    path = tmp_path / "r.json"
    write_sep005(triaxial, path)
    _same(read_record(path), triaxial)


def test_an_angle_is_kept(triaxial, tmp_path):
    path = _h5_without_dataset(triaxial, tmp_path / "r.h5")
    with h5py.File(path, "a") as h5:
        h5.attrs["channel_direction"] = ["30", "-45.5", "axial", "in", "90", "360"]
    assert read_record(path).channel_directions == (30.0, -45.5, "axial", "in", "out", "in")
    with h5py.File(path, "a") as h5:
        h5.attrs["channel_direction"] = np.array([30, -45, 0, 90, 180, 270], dtype=np.int64)  # numbers: degrees
    assert read_record(path).channel_directions == (30.0, -45.0, "in", "out", 180.0, -90.0)


# ---------------------------------------------------------------- refusals, one line each


@pytest.mark.parametrize(("directions", "what"), [
    (["in"] * 5, r"must have 6 entries, one per channel, got 5"),
    (["in", "out", "vertical", "in", "out", "axial"], r"channel 'p1_ax': must be .*got 'vertical'"),
    (["in", "out", "nan", "in", "out", "axial"], r"channel 'p1_ax': must be .*got nan"),
])
@pytest.mark.parametrize("where", ["dataset", "attribute"])
def test_hdf5_refuses_a_wrong_count_or_text(triaxial, tmp_path, directions, what, where):
    path = _h5_without_dataset(triaxial, tmp_path / "r.h5")
    with h5py.File(path, "a") as h5:
        if where == "dataset":
            h5.create_dataset("channel_direction", data=directions, dtype=h5py.string_dtype())
        else:
            h5.attrs["channel_direction"] = directions
    with pytest.raises(InputError) as err:
        read_record(path)
    _one_line(err, path, "channel_direction", what)


def test_hdf5_refuses_an_axis_the_option_does_not_place(triaxial, tmp_path):
    path = _h5_without_dataset(triaxial, tmp_path / "r.h5")
    with h5py.File(path, "a") as h5:
        h5.attrs["channel_direction"] = list(LABELS)
    with pytest.raises(InputError) as err:
        read_record(path, axes={"Y": "in", "Z": "out"})
    _one_line(err, path, "axes", r"channel 'p1_ax' is along X")


def test_the_channel_table_refuses_an_unknown_direction(triaxial, tmp_path):
    path = _write_csv(triaxial, tmp_path / "r.csv")
    with pytest.raises(InputError) as err:
        read_record(path, positions=dict(zip(NAMES, POSITIONS)), directions={"p1_in": "sideways"})
    _one_line(err, path, "channel_direction", r"channel 'p1_in': .*got 'sideways'")


def test_sep005_refuses_an_unknown_direction(triaxial, tmp_path):
    path = tmp_path / "r.json"
    write_sep005(triaxial, path)
    path.write_text(path.read_text().replace('"direction": "axial"', '"direction": "diagonal"', 1))
    with pytest.raises(InputError) as err:
        read_record(path)
    _one_line(err, path, "direction", r"channel 'p1_ax': .*got 'diagonal'")


@pytest.mark.parametrize(("value", "what"), [
    ({"W": "in"}, r"unknown axis 'W'"), ({"X": "up"}, r"axis X: must be"), ("X", r"must be a table"),
    ({}, r"at least one axis"), ({"X": "in", "x": "out"}, r"axis X is given twice"), ({"+X": "in"}, r"unknown axis"),
])
def test_the_option_axes_is_checked(value, what):
    assert re.search(what, option_problem("axes", value))


def test_a_wrong_axes_option_is_refused_when_read(triaxial, tmp_path):
    path = tmp_path / "r.h5"
    write_record(triaxial, path)
    with pytest.raises(InputError) as err:
        read_record(path, axes={"Q": "in"})
    _one_line(err, path, "axes", r"unknown axis 'Q'")


# ---------------------------------------------------------------- no directions: in-plane, with the note


def test_a_record_without_directions_is_read_in_plane_with_the_note(triaxial, tmp_path):
    path = _write_csv(triaxial, tmp_path / "r.csv")
    read = read_record(path, positions=dict(zip(NAMES, POSITIONS)))
    assert read.channel_directions is None
    assert read.directions == ("in",) * 6
    assert directions_note(read) == NO_DIRECTIONS_NOTE == "no channel directions given: every channel read as in-plane"
    assert directions_note(read_record(path, positions=dict(zip(NAMES, POSITIONS)), directions={"p1_out": "out"})) \
        is None
    plain = _h5_without_dataset(triaxial, tmp_path / "r.h5")
    assert directions_note(read_record(plain)) == NO_DIRECTIONS_NOTE


def test_three_channels_at_one_position_are_not_refused(triaxial):
    check_positions(triaxial, 10.0)  # two positions, three channels each, within [0, 10] m: nothing to refuse
    with pytest.raises(InputError, match="outside the cable span"):
        check_positions(triaxial, 8.0)  # the check still works: 9 m lies beyond a 8 m span


# ---------------------------------------------------------------- the campaign


CAMPAIGN = """
[campaign]
name = "triaxial"

[cable]
length = 12.0
mass_per_length = 10.0
EI = 1000.0

[record_format]
axes = {{ X = "axial", y = "in", Z = 30 }}

[channels]
{top}

[[setup]]
name = "bare"

[[test]]
name = "T1"
setup = "bare"
tension = 1e5
record = "{record}"
  [test.channels]
{test}
  [test.record_format]
  axes = {{ X = "axial", Y = "in", Z = "out" }}
"""


def _campaign(directory: Path, record: str = "r.csv", top: str = 'a = { position = 1.0, direction = "out" }',
              test: str = "") -> Path:
    if not test:
        test = "\n".join(f'  {n} = {{ position = {p}, direction = "{d}" }}' for n, p, d in zip(NAMES, POSITIONS,
                                                                                                 DIRECTIONS))
    directory.mkdir(parents=True, exist_ok=True)
    (directory / "campaign.toml").write_text(CAMPAIGN.format(top=top, test=test, record=record), encoding="utf-8")
    return directory


def test_the_campaign_keeps_directions_and_axes_through_its_round_trip(tmp_path):
    first = load_campaign(_campaign(tmp_path / "a"))
    test = first.tests[0]
    assert record_reading(first, test).directions == dict(zip(NAMES, DIRECTIONS))
    assert dict(first.record_format)["axes"] == (("X", "axial"), ("Y", "in"), ("Z", 30.0))
    assert dict(test.record_format)["axes"] == (("X", "axial"), ("Y", "in"), ("Z", "out"))
    text = campaign_to_toml(first)
    assert '[record_format.axes]\nX = "axial"\nY = "in"\nZ = 30.0\n' in text  # a table, as the user writes it
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "campaign.toml").write_text(text, encoding="utf-8")
    again = load_campaign(tmp_path / "b")
    assert again.channel_directions == first.channel_directions == (("a", "out"),)
    assert again.tests[0].channel_directions == test.channel_directions
    assert again.record_format == first.record_format
    assert again.tests[0].record_format == test.record_format


def test_the_campaign_refuses_a_wrong_axes_option(tmp_path):
    directory = _campaign(tmp_path / "a")
    toml = directory / "campaign.toml"
    toml.write_text(toml.read_text().replace('Z = "out"', 'Z = "up"'), encoding="utf-8")
    with pytest.raises(CampaignError) as err:
        load_campaign(directory)
    _one_line(err, toml, "test[T1].record_format.axes", r"axis Z: must be")


def test_a_triaxial_csv_record_is_read_as_the_spectra_read_it(triaxial, tmp_path):
    """As spectra.pipeline reads a test's record: the campaign's positions, directions and options."""
    directory = _campaign(tmp_path / "a")
    _write_csv(triaxial, directory / "r.csv")
    campaign = load_campaign(directory)
    test = campaign.tests[0]
    positions, options = _reading(campaign, test)
    read = read_record(directory / "r.csv", positions=positions, directions=record_reading(campaign, test).directions,
                       **options)
    _same(read, triaxial)


def test_a_triaxial_uff_record_is_placed_by_the_campaign_axes(triaxial, tmp_path):
    test = "\n".join(f"  {n} = {p}" for n, p in zip(NAMES, POSITIONS))  # positions only: the file's axes
    directory = _campaign(tmp_path / "a", record="r.uff", top="a = 1.0", test=test)
    _write_uff(triaxial, directory / "r.uff", UFF_CODES)
    campaign = load_campaign(directory)
    positions, options = _reading(campaign, campaign.tests[0])
    assert record_reading(campaign, campaign.tests[0]).directions is None
    _same(read_record(directory / "r.uff", positions=positions, **options), triaxial)


def test_track_reads_a_record_with_the_campaigns_directions(triaxial, tmp_path, monkeypatch):
    """The cable's top-level [channels] directions reach track's reader (the analysis is stubbed out)."""
    from stcs_ident.track import process
    from stcs_ident.track.archive import discover

    top = "\n".join(f'{n} = {{ position = {p}, direction = "{d}" }}' for n, p, d in zip(NAMES, POSITIONS, DIRECTIONS))
    cable = _campaign(tmp_path / "archive" / "c1", top=top, test="  a = 1.0")
    cable_toml = cable / "campaign.toml"  # the test's own table would win: keep the top level's only
    cable_toml.write_text(cable_toml.read_text().replace("  [test.channels]\n  a = 1.0\n", ""), encoding="utf-8")
    (cable / "records").mkdir()
    path = _write_csv(triaxial, cable / "records" / "r.csv")
    seen = {}

    def analysed(campaign, test, record, path, **kwargs):
        seen.update(record=record, test=test)
        raise InputError("stub: the analysis is not this test's")

    monkeypatch.setattr(process, "analyse_record", analysed)
    (spec,) = discover(tmp_path / "archive")
    assert dict(spec.directions) == dict(zip(NAMES, DIRECTIONS))
    options = dict(spec.record_format)
    options["start_time"] = "2026-03-01T10:00:00Z"
    spec = type(spec)(**{**spec.__dict__, "record_format": tuple(options.items())})
    row = process.process_record(spec, str(path), "id")
    assert row["reason"].endswith("stub: the analysis is not this test's")
    _same(seen["record"], triaxial)
    assert seen["test"].channel_directions == tuple(zip(NAMES, DIRECTIONS))


def _reading(campaign, test):
    """(positions, reader options) of ``test``'s record, as io gives them."""
    reading = record_reading(campaign, test)
    return reading.positions, reading.options
