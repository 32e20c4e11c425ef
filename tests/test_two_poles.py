"""One pole or two in a band (spectra/two_poles.py, spectra/second_resonances.py; issue 36, item 2).

The records: one or two modes as AR(2) filters of white noise (exact damped poles), on two channels with sensor
noise; and the biaxial bridge records of benchmarks/plane_records.py (a deck's mode within 0.5-2 % of a cable mode
moving the anchorage, no axial channel: the deck's mode is no peak of its own there).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.signal import lfilter

from benchmarks.plane_records import make_bridge_case
from stcs_ident.spectra.ambient_fit import fit_ambient
from stcs_ident.spectra.pipeline import analyse_record
from stcs_ident.spectra.two_poles import THRESHOLD, second_resonance, two_poles

FS = 50.0


def _mode(rng, n: int, frequency: float, zeta: float) -> np.ndarray:
    """A mode's response to white noise: the AR(2) filter of its exact damped pole pair (warmed up)."""
    w = 2 * np.pi * frequency
    r = np.exp(-zeta * w / FS)
    a = [1.0, -2 * r * np.cos(w * np.sqrt(1 - zeta**2) / FS), r * r]
    return lfilter([1.0], a, rng.standard_normal(n + 6000))[6000:]


def _band_fit(x: np.ndarray, f0: float, half_width: float, zeta: float):
    n = x.shape[0]
    dft = np.fft.rfft(x, axis=0) / np.sqrt(n)
    return fit_ambient(dft, n, FS, f0, half_width, np.ones(x.shape[1]), peak_width=2 * zeta * f0, spread=False)


def test_one_mode_is_one_pole():
    """Under one pole the statistic stays below its threshold: THRESHOLD (30) was set on 2985 single-mode bands
    of another seed (benchmarks/two_poles.py null: largest 28.4, 99.9th percentile 26.3); here 150 more, 30-600
    s, ζ 0.2-2 %, sensor noise 1-30 % of the rms. At the calibration's rate (none at 30 in 2985) one false alarm
    in 150 is already unlikely; two would say the threshold is wrong."""
    rng = np.random.default_rng(2024)
    statistics = []
    for _ in range(150):
        duration = float(rng.choice([30.0, 60.0, 120.0, 600.0]))
        zeta = float(np.exp(rng.uniform(np.log(0.002), np.log(0.02))))
        f0 = rng.uniform(5, 15)
        q = _mode(rng, int(FS * duration), f0, zeta)
        x = np.outer(q, rng.uniform(0.3, 1.0, 2))
        x += rng.uniform(0.01, 0.3) * x.std() * rng.standard_normal(x.shape)
        fit = _band_fit(x, f0, max(8 * zeta * f0, 12 / duration), zeta)
        result = None if fit is None or fit.band is None else two_poles(*fit.band[:3])
        if result is not None:
            statistics.append(result.statistic)
    statistics = np.array(statistics)
    assert statistics.size >= 140
    assert np.sum(statistics >= THRESHOLD) <= 1, np.sort(statistics)[-5:]
    assert 3.0 < np.median(statistics) < 15.0  # the statistic is computed, not 0: a few units of 2Δℓ per pole


def test_two_modes_are_two_poles():
    """Two modes sharing the channels' shape, the second 8 half-power half-widths above the first at half its
    amplitude (ζ 0.5 %, 120 s): measured on other seeds, 77 and 92 of 100 found (the misfit gate misses the
    rest), every one within 3σ of the second mode. Asserted: at least 30 of 50 found, all within 3σ."""
    rng = np.random.default_rng(7)
    found, within = 0, 0
    for _ in range(50):
        f0, zeta = rng.uniform(5, 15), 0.005
        f_b = f0 * (1 + 8 * zeta)
        n = int(FS * 120)
        qa, qb = _mode(rng, n, f0, zeta), _mode(rng, n, f_b, zeta)
        x = np.outer(qa + 0.5 * np.std(qa) / np.std(qb) * qb, [1.0, 0.6])
        x += 0.3 * x.std() * rng.standard_normal(x.shape)
        fit = _band_fit(x, f0, 3 * (f_b - f0), zeta)
        second = None if fit is None else second_resonance(fit)
        if second is not None:
            found += 1
            within += abs(second[0] - f_b) <= 3 * second[1]
            assert second[2] >= THRESHOLD
    assert found >= 30
    assert within == found


@pytest.mark.slow
def test_a_deck_mode_merged_with_a_cable_mode_is_reported(monkeypatch):
    """Biaxial records of a stay with a deck's mode 0.5-2 % from a cable mode and no axial channel (seeds not
    looked at before this test was written: 300-307, 8 found): the second poles reported as structural lie within
    3σ of a structural frequency (a deck's mode or its harmonic), several are found (on seeds 200-229 of stays and
    hangers: 35, every one within 3σ), and every numbered mode is the same with the test as without it."""
    from stcs_ident.spectra import peaks

    reported = 0
    for seed in range(300, 308):
        case = make_bridge_case("stay", seed, layout="biaxial")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = analyse_record(case.campaign, case.test, case.record, "x")
            with monkeypatch.context() as patch:
                patch.setattr(peaks, "second_resonance", lambda fit: None)
                without = analyse_record(case.campaign, case.test, case.record, "x")
        assert r.modes == without.modes and np.array_equal(r.frequencies, without.frequencies)
        assert np.array_equal(r.uncertainty, without.uncertainty)
        for f, u, reason in r.structural:
            if "second pole" not in reason:
                continue
            reported += 1
            assert min(abs(f - s) for s in case.structural) <= 3 * u, (seed, f, u, case.structural)
            assert any(note.kind == "second_resonance" and f"{f:.4f}" in str(note) for note in r.notes)
    assert reported >= 4


@pytest.mark.slow
def test_a_record_read_in_one_plane_widens_a_misfitting_mode():
    """The biaxial bridge records reduced to their in-plane channels without directions (as a user's record
    without them is read): a mode whose fit misfits its band has its 1σ widened as a plane's would be (a note
    says so). Measured on seeds 400-439, stays: the modes within 2 % of a structural frequency 45.5 → 80.0 %
    within 1σ, 90.9 → 94.5 % within 3σ. Here seeds 500-519 (not looked at before): at least 60 % within 1σ,
    which the unwidened 1σ (45 %) does not reach, and 90 % within 3σ."""
    from stcs_ident.core.record import Record

    z, notes = [], 0
    for seed in range(500, 520):
        case = make_bridge_case("stay", seed, layout="biaxial")
        keep = [i for i, d in enumerate(case.record.channel_directions) if d == "in"]
        record = Record(acceleration=case.record.acceleration[:, keep], sampling_rate=case.record.sampling_rate,
                        channel_names=tuple(case.record.channel_names[i] for i in keep),
                        channel_positions=case.record.channel_positions[keep])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = analyse_record(case.campaign, case.test, record, "x")
        notes += sum(n.kind == "misfit" for n in r.notes)
        for mode, f, u in zip(r.modes, r.frequencies, r.uncertainty):
            true = case.truth["in"][mode - 1]
            if min(abs(true - s) for s in case.structural) < 0.02 * true:
                z.append(abs(f - true) / u)
    z = np.array(z)
    assert z.size >= 15 and notes >= 5
    assert np.mean(z <= 1) >= 0.6, np.sort(z)
    assert np.mean(z <= 3) >= 0.9, np.sort(z)
