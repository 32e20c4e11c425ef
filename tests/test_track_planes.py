"""track with both planes: a row's modes carry their planes, the tension is fitted from both, and the parts
written before the ``planes`` column still read (every mode in-plane, as they were processed)."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pandas as pd
import pytest

from stcs_ident.core.model import Cable, Campaign, Setup, Test
from stcs_ident.forward import natural_frequencies
from stcs_ident.io.tables import write_parquet
from stcs_ident.io.test_record import record_reading
from stcs_ident.track import process
from stcs_ident.track.archive import CableSpec
from stcs_ident.track.store import ROW_COLUMNS, append_part, read_parts

CABLE = Cable(300.0, 100.0, 2.0e6, 2.0e9, math.radians(30.0))  # λ² ≈ 2: the planes' first modes 8 % apart
TENSION = 4.0e6
SIGMA = 1e-3


@dataclass
class FakeSpectra:
    """What ``analyse_record`` gives, reduced to what a row and the fit read."""

    modes: tuple
    frequencies: tuple
    uncertainty: tuple
    planes: tuple

    @property
    def mode_planes(self):
        return self.planes


@dataclass
class FakeRecord:
    start_time: object = np.datetime64("2026-03-01T00:00:00")
    temperature: float | None = None


def spec(tmp_path, directions=()) -> CableSpec:
    campaign = Campaign("stay", CABLE, (Setup("S"),), (Test("T1", "S", 3.8e6, channel_directions=directions),))
    return CableSpec("stay", str(tmp_path), campaign, "S", 3.8e6, directions=tuple(dict(directions).items()))


def test_a_row_lists_the_planes_and_the_tension_comes_from_both(tmp_path, monkeypatch):
    f_in = natural_frequencies(CABLE, (), TENSION, 4, plane="in")
    f_out = natural_frequencies(CABLE, (), TENSION, 4, plane="out")
    spectra = FakeSpectra((1, 2, 3, 4) * 2, tuple(f_in) + tuple(f_out), (SIGMA,) * 8, ("in",) * 4 + ("out",) * 4)
    seen = {}

    def fake_open(campaign, test):
        seen["directions"] = record_reading(campaign, test).directions
        return str(tmp_path / "r.h5"), FakeRecord()

    # patched where track.process looks them up
    monkeypatch.setattr(process, "open_test_record", fake_open)
    monkeypatch.setattr(process, "analyse_record", lambda *args, **kwargs: spectra)
    (tmp_path / "r.h5").write_bytes(b"")
    row = process.process_record(spec(tmp_path, {"acc2": "out"}), str(tmp_path / "r.h5"), "id")
    assert row["status"] == "ok", row["reason"]
    assert row["planes"] == ["in"] * 4 + ["out"] * 4 and row["modes"] == [1, 2, 3, 4] * 2
    # exact frequencies: the fit's tolerance; numbered all in-plane the out-of-plane mode 1 would pull it ~1 % off
    assert row["tension_N"] == pytest.approx(TENSION, rel=1e-7)
    assert seen["directions"] == {"acc2": "out"}  # the campaign's directions reach the reader


def test_a_part_written_before_the_planes_reads_all_in_plane(tmp_path):
    row = {k: None for k in ROW_COLUMNS}
    row.update(cable="stay", record="a.h5", record_id="x", start_time=np.datetime64("2026-03-01T00:00:00"),
               temperature_degC=math.nan, status="ok", reason="", n_modes=2, modes=[1, 2], planes=["in", "in"],
               frequencies_Hz=[0.36, 0.67], frequency_sigma_Hz=[1e-3, 1e-3], tension_N=4e6, tension_sigma_N=4e3,
               version="v", size_bytes=1, mtime_ns=1)
    path = append_part(tmp_path, [row])
    assert "planes" in pd.read_parquet(path)
    old = pd.read_parquet(path).drop(columns="planes")  # as a part of the previous schema
    write_parquet(old, path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an unreadable part would warn
        rows, read, unreadable = read_parts(tmp_path)
    assert read == [path] and not unreadable
    assert list(rows["planes"][0]) == ["in", "in"]
