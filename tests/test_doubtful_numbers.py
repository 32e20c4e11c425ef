"""The numbering's doubt, where numbers are fitted: a mode number that another family of modes gives almost as
well is kept out of the fits of ``identify`` (with a note), ``diagnose`` and ``track`` (flagged in the row); a
record with no sure number gives no tension.

A 60-second record of a damped stay with a single peak was numbered 13 instead of 11 and gave 2.82 MN ± 17 kN
for a cable at 4.01 MN, a row with status ok 70σ off; the numbering had called that number doubtful. Here the
spectra are given (the numbering's verdict is the input), the fit is the real one.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from stcs_ident.core.errors import InputError
from stcs_ident.core.model import Cable, Campaign, Damper, Setup, Test
from stcs_ident.forward import natural_frequencies
from stcs_ident.identify import identify
from stcs_ident.identify.measurement import without_doubtful
from stcs_ident.track import process
from stcs_ident.track.archive import CableSpec
from stcs_ident.track.process import process_record

STAY = Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=math.radians(30.0))
BARE = Campaign("stay", STAY, setups=(Setup("S", ()),), tests=(Test("T", "S", 4.0e6),))
TENSION = 4.02e6


def _spectra(modes, frequencies, doubtful, damping=None):
    return SimpleNamespace(modes=tuple(modes), mode_planes=("in",) * len(modes), frequencies=np.array(frequencies),
                           uncertainty=np.full(len(modes), 1e-3), damping=damping,
                           damping_uncertainty=None if damping is None else np.full(len(modes), 1e-3),
                           doubtful=tuple(doubtful))


def _row(tmp_path, monkeypatch, modes, frequencies, doubtful):
    spectra = _spectra(modes, frequencies, doubtful)
    monkeypatch.setattr(process, "analyse_record", lambda *a, **k: spectra)
    monkeypatch.setattr(process, "open_test_record", lambda campaign, test: ("r.h5", type("R", (), {
        "start_time": pd.Timestamp("2024-01-01T00:00:00Z"), "temperature": 10.0})()))
    return process_record(CableSpec("stay", str(tmp_path), BARE, "S", 4.0e6), str(tmp_path / "records" / "r.h5"), "x")


def test_a_doubtful_number_is_flagged_and_left_out_of_the_tension(tmp_path, monkeypatch):
    f = natural_frequencies(STAY, (), TENSION, 12)
    # Modes 1-4 sure; the peak of mode 11 numbered 13 (as the short record's was), doubtful.
    row = _row(tmp_path, monkeypatch, (1, 2, 3, 4, 13), [*f[:4], f[10]], (False,) * 4 + (True,))
    assert row["status"] == "ok", row["reason"]
    assert row["doubtful"] == [False, False, False, False, True] and row["modes"] == [1, 2, 3, 4, 13]
    # The four exact frequencies alone: the fit's tolerance (1e-14) and the solver's (1e-12), far below 1e-6.
    assert row["tension_N"] == pytest.approx(TENSION, rel=1e-6)
    # With the doubtful mode fitted (its weight the others'), the fit gives 2.94 MN: (11/13)² ≈ 0.72 on that
    # mode, outweighing the four sure ones. The check that it did not:
    assert abs(row["tension_N"] - TENSION) < row["tension_sigma_N"]


def test_a_record_with_no_sure_number_gives_no_tension_and_says_why(tmp_path, monkeypatch):
    f = natural_frequencies(STAY, (), TENSION, 12)
    row = _row(tmp_path, monkeypatch, (13,), [f[10]], (True,))
    assert row["status"] == "failed" and math.isnan(row["tension_N"])
    assert "doubtful" in row["reason"] and f"{f[10]:.3f} Hz" in row["reason"]
    assert row["doubtful"] == [True] and row["frequencies_Hz"] == [pytest.approx(f[10])]


def test_spectra_without_flags_fit_every_mode(tmp_path, monkeypatch):
    f = natural_frequencies(STAY, (), TENSION, 4)
    row = _row(tmp_path, monkeypatch, (1, 2, 3, 4), f, (False,) * 4)
    assert row["status"] == "ok" and row["doubtful"] == [False] * 4
    assert row["tension_N"] == pytest.approx(TENSION, rel=1e-6)


def test_identify_leaves_doubtful_numbers_out_with_a_note_and_refuses_a_test_with_none_sure():
    f = natural_frequencies(STAY, (), TENSION, 12)
    result = identify(BARE, ["T"], "tension", picked={"T": _spectra((1, 2, 3, 13), [*f[:3], f[10]],
                                                                    (False, False, False, True))})
    assert result.value("tension")[0] == pytest.approx(TENSION, rel=1e-6)  # mode "13" would give ~2.9 MN
    assert any("modes 13 left out" in str(n) for n in result.notes)
    with pytest.raises(InputError) as err:
        identify(BARE, ["T"], "tension", picked={"T": _spectra((13,), [f[10]], (True,))})
    assert err.value.field == "test[T].record" and "doubtful" in str(err.value)


def test_the_sure_modes_keep_their_damping_ratios():
    """Before, diagnose's own copy of this dropped every damping ratio of a test that lost a mode: a damped
    cable's damper was then judged on its frequencies alone."""
    damped = Campaign("d", STAY, setups=(Setup("S", (Damper("D", 3.0, coefficient=1e5),)),),
                      tests=(Test("T", "S", 4.0e6),))
    spectra = _spectra((1, 2, 3), [1.0, 2.0, 3.0], (False, True, False), damping=np.array([0.011, 0.012, 0.013]))
    out, notes = without_doubtful(damped, {"T": spectra})
    assert out["T"].modes.tolist() == [1, 3] and out["T"].damping.tolist() == [0.011, 0.013]
    assert "modes 2 left out" in str(notes[0])
    out, notes = without_doubtful(damped, {"T": _spectra((4,), [4.0], (True,))})
    assert out["T"] is None and "every mode left out" in str(notes[0])
