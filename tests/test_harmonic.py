"""The harmonic series of a set of peaks, found from the peaks alone (spectra/harmonic.py).

References: the pinned tensioned beam's closed form f_n = n/(2L) √(T/m) √(1 + n²π² EI/(T L²)) (docs/model.md),
which is the series' own form (so f₀ and B come back to rounding), and the exact model of a clamped, sagging
stay (forward.natural_frequencies), which the series only approximates within its tolerance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stcs_ident.core.model import Cable
from stcs_ident.forward import natural_frequencies
from stcs_ident.spectra.harmonic import harmonic_series
from stcs_ident.spectra.scale_check import check_scale, round_factor


def pinned_beam(n, length=20.0, mass=30.0, tension=4e5, EI=2e5):
    """The closed form of the pinned tensioned beam, Hz."""
    n = np.asarray(n, float)
    return n / (2 * length) * math.sqrt(tension / mass) * np.sqrt(1 + n**2 * math.pi**2 * EI / (tension * length**2))


@pytest.mark.parametrize("EI", [0.0, 2e4, 2e5, 2e6, 1.6e7])  # B from 0 to 2 (ξ = √(T L²/EI) from ∞ to 3)
def test_the_closed_form_of_a_pinned_beam_is_recovered(EI):
    n = np.arange(1, 9)
    f = pinned_beam(n, EI=EI)
    series = harmonic_series(f, 1e-4 * f)
    f0, B = pinned_beam(1, EI=0.0)[()], math.pi**2 * EI / (4e5 * 20.0**2)
    assert np.array_equal(series.modes, n) and not series.ambiguous
    # the form is exact: the fit's least squares leave rounding only
    assert series.fundamental == pytest.approx(f0, rel=1e-9) and series.inharmonicity == pytest.approx(B, abs=1e-9)


def test_missing_modes_odd_modes_only_and_a_high_start_are_numbered():
    n = np.arange(1, 31)
    f = pinned_beam(n, EI=2e3)
    for keep in (list(range(0, 30, 2)), list(range(14, 30))):  # odd modes only; from mode 15 on
        series = harmonic_series(f[keep], 1e-3 * f[keep])
        assert np.array_equal(series.modes, n[keep]) and not series.ambiguous
    # four sparse peaks (modes 3, 5, 6, 9): a stretched series spanning fewer modes fits them within the ambiguity;
    # said so, never a sure wrong number
    assert harmonic_series(f[[2, 4, 5, 8]], 1e-3 * f[[2, 4, 5, 8]]).ambiguous


def test_a_stiff_series_seen_from_a_high_mode_is_right_or_ambiguous():
    """Modes 15-30 of a member stretched by its stiffness (B n² up to 1.1): the same peaks as modes 16-31 of
    another stretched series fit within the 2 % model tolerance; never a sure wrong number."""
    n = np.arange(15, 31)
    f = pinned_beam(n, EI=2e5)
    series = harmonic_series(f, 1e-3 * f)
    assert series.ambiguous or np.array_equal(series.modes, n)
    assert np.array_equal(series.modes, n)  # the best is still the true one


def test_the_exact_family_of_a_clamped_sagging_stay_is_numbered():
    stay = Cable(length=200.0, mass_per_length=90.0, EI=4e5, EA=2e9, inclination=math.radians(25))
    for plane in ("in", "out"):
        f = natural_frequencies(stay, (), 5e6, 25, plane=plane)
        series = harmonic_series(f, 2e-3 * f, max_peaks=25)
        assert np.array_equal(series.modes, np.arange(1, 26)), plane
    # by default the lowest 20 peaks are numbered, the others left at 0
    assert harmonic_series(f, 2e-3 * f).modes.tolist() == list(range(1, 21)) + [0] * 5


def test_stray_peaks_are_left_out_and_the_sub_harmonic_loses():
    f = pinned_beam(np.arange(1, 21), EI=2e4)
    strays = np.array([0.52 * (f[2] + f[3]), 0.5 * (f[10] + f[11])])  # halfway: on the series f0/2
    series = harmonic_series(np.r_[f, strays], np.full(22, 1e-3), max_peaks=22)
    assert np.array_equal(series.modes[:20], np.arange(1, 21)) and np.all(series.modes[20:] == 0)
    assert series.fundamental == pytest.approx(pinned_beam(1, EI=0.0)[()], rel=1e-3)


def test_peaks_that_number_themselves_no_way_are_ambiguous():
    assert harmonic_series([]) is None
    one = harmonic_series([3.0])
    assert one.ambiguous and one.modes.tolist() == [1]
    two = harmonic_series([3.0, 7.1], [1e-3, 1e-3])  # 3:7, or 6:14 ... or any pair of a stretched series
    assert two.ambiguous
    with pytest.raises(ValueError):
        harmonic_series([1.0, 2.0], [0.1])


def test_the_scale_check_reads_a_slip_and_only_a_slip():
    f = pinned_beam(np.arange(1, 13), EI=2e4)
    nominal = lambda n: pinned_beam(np.arange(1, n + 1), EI=2e4)
    same = check_scale("in", f, 1e-3 * f, nominal)
    assert same.conclusive and not same.implausible and same.ratio == pytest.approx(1.0, rel=1e-6)
    for factor in (2.0, 0.5, 10.0):  # a sampling rate typed wrong scales every peak
        check = check_scale("in", factor * f, 1e-3 * f, nominal)
        assert check.implausible and check.ratio == pytest.approx(factor, rel=1e-6)
        assert round_factor(check.ratio) == factor
    tension_off = check_scale("in", math.sqrt(1.25) * f, 1e-3 * f, nominal)  # a stated tension 20 % low
    assert not tension_off.implausible and round_factor(tension_off.ratio) is None
    assert not check_scale("in", f[:2], 1e-3 * f[:2], nominal).conclusive  # two peaks judge nothing
