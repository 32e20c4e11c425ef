"""Short ambient records: the modes the nominal model expects are proposed where none was detected.

On a 60-s wind record of a 120 m stay the overview is coarse (0.2 Hz) and only a few of its modes rise above
the detection threshold; the fit band of a detected mode (eight half-power widths) then holds the undetected
ones beside it, and its one pole landed between them with a 1σ that knew nothing of them. Measured on track's
72-record archives of the stay of campaigns/damped-stay (two cables, 6 h of 60-s records; the truth the
simulator wrote), before → after the proposals:

- bare: records with a tension 52 → 72, modes per record 4 → 16, frequencies within 1σ / 3σ 40 / 83 % →
  59 / 96 % (mode 5 and up 31 / 79 % → 56 / 95 %), tension 63 / 90 % → 67 / 97 %;
- damped: 45 → 72 records, 4 → 13 modes, 36 / 83 % → 52 / 93 %, tension 44 / 84 % → 44 / 90 %;
- 10-minute records (every mode detected): unchanged, 70 / 99 %.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stcs_ident.core.errors import InputError
from stcs_ident.forward import natural_frequencies
from stcs_ident.io.campaign import load_campaign
from stcs_ident.simulate.simulate import Ambient, simulate_record_with_truth
from stcs_ident.spectra import find_peaks
from stcs_ident.spectra.detection import detect_multiresolution, expected_proposals
from stcs_ident.spectra.overview import ambient_overview

#: The stay of campaigns/damped-stay, without its damper.
STAY = load_campaign(Path(__file__).resolve().parent.parent / "campaigns" / "damped-stay").cable
TENSION = 4.0e6


def _record(seed: int, duration: float = 60.0):
    return simulate_record_with_truth(STAY, (), TENSION, [0.23 * 120, 0.5 * 120, 0.71 * 120], duration=duration,
                                      sampling_rate=100.0, damping=0.005, ambient=Ambient(20.0), snr_db=30.0,
                                      seed=seed)


def _nominal():
    """The nominal family at a reference tension 2 % off the truth (a monitoring campaign's reference)."""
    return natural_frequencies(STAY, (), 1.02 * TENSION, 15)


def _errors(result, truth) -> tuple[int, np.ndarray]:
    """(peaks, |f − f_true| / 1σ per peak, against the nearest true mode)."""
    f = np.array([p.frequency for p in result.peaks])
    sigma = np.array([p.uncertainty for p in result.peaks])
    nearest = truth.frequencies[np.argmin(np.abs(f[:, None] - truth.frequencies[None, :]), axis=1)]
    return f.size, np.abs(f - nearest) / sigma


def test_expected_modes_must_be_frequencies():
    record, _ = _record(0, duration=20.0)
    for bad in ([1.0, np.nan], [-2.0], [[0.0]]):
        with pytest.raises(InputError) as err:
            find_peaks(record, f_min=0.5, f_max=20.0, expected=bad)
        assert err.value.field == "expected"


def test_nothing_is_proposed_without_a_detection_nor_beside_one():
    record, _ = _record(1)
    x = record.acceleration - record.acceleration.mean(axis=0)
    overview = ambient_overview(x, record.sampling_rate)
    detected, threshold = detect_multiresolution([overview], 0.45, 20.0, None)
    nominal = _nominal()
    assert expected_proposals(overview, threshold, nominal, [], 0.45, 20.0) == []
    assert detected, "a 60-s wind record of the stay shows some mode"
    proposals = expected_proposals(overview, threshold, nominal, detected, 0.45, 20.0)
    spacing = np.min(np.diff(nominal))
    assert proposals and all(p.proposal for p in proposals)
    # none beside a detected peak; each near the expected mode it stands for, and within the band
    assert all(min(abs(p.frequency - d.frequency) for d in detected) > 0.2 * spacing for p in proposals)
    assert all(np.min(np.abs(nominal - p.frequency)) <= 0.3 * spacing for p in proposals)
    assert all(0.45 <= p.frequency <= 20.0 + 0.3 * spacing for p in proposals)


@pytest.mark.slow
def test_short_records_find_most_modes_with_a_wider_1_sigma_coverage():
    """12 sixty-second records of the bare stay. Guards set below the figures measured on them (the docstring's
    archive gives alike): with the proposals 16.0 peaks a record (without: 8.8), 61.5 % of them within 1σ of the
    true mode and 97.4 % within 3σ (without: 65.7 and 96.2 %). Before the raw valley told apart the modes of a
    short record's coarse overview (detection._separated), the detection alone found 1.0 a record (the others
    suppressed as the strongest one's shoulders) and the proposals 14.9 (60 / 96.6 %). The 1σ is still short of
    honest on such records (docs/track.md)."""
    with_, without = [], []
    counts = {"with": 0, "without": 0}
    for seed in range(100, 112):
        record, truth = _record(seed)
        for name, expected, out in (("with", _nominal(), with_), ("without", None, without)):
            n, z = _errors(find_peaks(record, f_min=0.45, f_max=1.3 * _nominal()[-1], expected=expected), truth)
            counts[name] += n
            out.extend(z)
    with_, without = np.array(with_), np.array(without)
    assert counts["without"] >= 6 * 12, counts  # the detection alone: 8.8 a record (1.0 when merged)
    assert counts["with"] >= 1.5 * counts["without"], counts  # the proposals add the undetected ones (1.83x)
    assert np.mean(with_ < 3) >= 0.95, np.mean(with_ < 3)
    # the proposals' extra, weaker modes do not cost coverage beyond the spread of ~100-200 peaks (2 %)
    assert np.mean(with_ < 3) >= np.mean(without < 3) - 0.02, (np.mean(with_ < 3), np.mean(without < 3))
