"""The formulas of Zui, Shinke & Namita (1996) (:mod:`stcs_ident.identify.zui`): the rows as quoted, the
iteration between them, the error bands against the exact model, and an acceptance run on random cables
with finite-element reference frequencies."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stcs_ident.core.errors import ModelError
from stcs_ident.core.model import Boundary, Cable
from stcs_ident.forward.dsm import batch_frequencies
from stcs_ident.forward.fem import fe_frequencies
from stcs_ident.identify.zui import (
    ERROR_BANDS,
    EXCLUDED,
    MAX_MODE,
    ROW,
    ROWS,
    band_index,
    error_band,
    settle_row,
    zui_tension,
)

#: The hand-computed tension is the same arithmetic in another order: equal to the last few ulps.
HAND_RTOL = 1e-12


def clamped(length, mass, EI):
    return Cable(length, mass, EI, None, 0.0, boundary_a=Boundary.clamped(), boundary_b=Boundary.clamped())


# ---- each row against the table, by hand --------------------------------------------------------------------

L, M, EI = 50.0, 20.0, 2.0e5
C = math.sqrt(EI / (M * L**4))  # 0.04 Hz


#: One case per row: (mode, f/C, the row it must settle in, its tension typed from the table as quoted).
HAND_CASES = [
    # mode 1, taut ξ = 2 f/C = 100: stays in the top row
    (1, 50.0, "mode 1, xi >= 17", lambda f: 4 * M * (f * L) ** 2 * (1 - 2.20 * C / f - 0.550 * (C / f) ** 2)),
    # mode 1, taut ξ = 12 -> row 6-17 gives ξ = 2 √(0.865·36 − 11.6) = 8.8
    (1, 6.0, "mode 1, 6 <= xi <= 17", lambda f: 4 * M * (f * L) ** 2 * (0.865 - 11.6 * (C / f) ** 2)),
    # mode 1, taut ξ = 8 -> row 6-17 gives ξ = 3.0 -> row 0-6 gives ξ = 2 √(0.828·16 − 10.5) = 3.3
    (1, 4.0, "mode 1, 0 <= xi <= 6", lambda f: 4 * M * (f * L) ** 2 * (0.828 - 10.5 * (C / f) ** 2)),
    # mode 2, taut ξ = f/C = 300
    (2, 300.0, "mode 2, xi >= 60", lambda f: M * (f * L) ** 2 * (1 - 4.40 * C / f - 1.10 * (C / f) ** 2)),
    # mode 2, taut ξ = 40 -> ξ = 37.3
    (2, 40.0, "mode 2, 17 <= xi <= 60", lambda f: M * (f * L) ** 2 * (1.03 - 6.33 * C / f - 1.58 * (C / f) ** 2)),
    # mode 2, taut ξ = 12 -> ξ = 12 √(0.882 − 85/144) = 6.5
    (2, 12.0, "mode 2, 0 <= xi <= 17", lambda f: M * (f * L) ** 2 * (0.882 - 85.0 * (C / f) ** 2)),
    # mode 3, taut ξ = 2 f / (3 C) = 1000, ξ/n = 333
    (3, 1500.0, "mode n >= 3, xi >= 200", lambda f: 4 * M * (f * L / 3) ** 2 * (1 - 2.20 * 3 * C / f)),
]


@pytest.mark.parametrize("mode, ratio, label, hand", HAND_CASES, ids=[c[2] for c in HAND_CASES])
def test_each_row_reads_its_coefficients(mode, ratio, label, hand):
    f = ratio * C
    est = zui_tension(L, M, f, mode, EI)
    assert est.ok and est.reason is None and est.note is None
    assert est.row == label
    np.testing.assert_allclose(est.tension, hand(f), rtol=HAND_RTOL)
    # ξ reported is that of the tension found, and lies in the row's range
    assert est.xi == pytest.approx(L * math.sqrt(hand(f) / EI), rel=HAND_RTOL)
    assert ROW[label].contains(est.xi)
    assert est.error_band == error_band(ROW[label], est.xi, mode) is not None
    # dT/df at fixed row against a central difference of the hand formula; step 1e-6 f keeps the row, and the
    # difference's truncation (~h²) and rounding (~1e-16 / 1e-6) errors are both below 1e-8
    h = 1e-6 * f
    np.testing.assert_allclose(est.dT_df, (hand(f + h) - hand(f - h)) / (2 * h), rtol=1e-7)


def test_rows_are_the_quoted_table():
    """The row data itself, typed once more from the table (a second reading of the same source)."""
    quoted = {
        "mode 1, xi >= 17": (1, 17, math.inf, 4, 1.0, 2.20, 0.550),
        "mode 1, 6 <= xi <= 17": (1, 6, 17, 4, 0.865, 0.0, 11.6),
        "mode 1, 0 <= xi <= 6": (1, 0, 6, 4, 0.828, 0.0, 10.5),
        "mode 2, xi >= 60": (2, 60, math.inf, 1, 1.0, 4.40, 1.10),
        "mode 2, 17 <= xi <= 60": (2, 17, 60, 1, 1.03, 6.33, 1.58),
        "mode 2, 0 <= xi <= 17": (2, 0, 17, 1, 0.882, 0.0, 85.0),
        "mode n >= 3, xi >= 200": (None, 200, math.inf, 4, 1.0, 2.20, 0.0),
    }
    assert {r.label: (r.mode, r.xi_min, r.xi_max, r.lead, r.a0, r.a1, r.a2) for r in ROWS} == quoted
    assert set(ERROR_BANDS) == set(quoted)


# ---- edge cases ---------------------------------------------------------------------------------------------

def test_mode_3_below_xi_200_gives_no_answer():
    est = zui_tension(L, M, 150.0 * C, 3, EI)  # taut ξ = 2·150/3 = 100
    assert not est.ok and est.tension is None and est.row is None and est.error_band is None
    # the taut string's ξ, 100 up to rounding (1e-12: a few operations on doubles)
    assert "200" in est.reason and est.xi == pytest.approx(100.0, rel=1e-12)


@pytest.mark.parametrize("mode, ratio", [(1, 3.0), (2, 5.0)])
def test_frequency_too_low_gives_no_answer(mode, ratio):
    # below the clamped beam's zero-tension frequency (mode 1: 3.56 C, mode 2: 9.82 C) every row's bracket is < 0
    est = zui_tension(L, M, ratio * C, mode, EI)
    assert not est.ok and "<= 0" in est.reason


def test_excluded_parts_give_no_answer():
    # mode 1 just above its zero-tension frequency (3.5608 C): ξ ≈ 0.15, in the excluded part (ξ < 0.3) of the
    # row 0-6
    est = zui_tension(L, M, 3.562 * C, 1, EI)
    assert not est.ok and est.xi < EXCLUDED["mode 1, 0 <= xi <= 6"][1] and "left out" in est.reason
    # mode 20 at taut ξ = 2·3000/20 = 300: ξ/n = 15 is answered; mode 40 at ξ ≈ 300 (ξ/n ≈ 7.5) is not
    assert zui_tension(L, M, 3000 * C, 20, EI).ok
    est = zui_tension(L, M, 6000 * C, 40, EI)
    assert not est.ok and "xi/n" in est.reason
    est = zui_tension(L, M, 1e5 * C, MAX_MODE + 1, EI)
    assert not est.ok and str(MAX_MODE) in est.reason


def test_cycle_at_a_row_boundary_is_resolved_deterministically():
    # (f/C)² = 23.68 lies in (23.551, 23.815): the row 6-17 gives ξ = 2 √(0.865·23.68 − 11.6) = 5.961 < 6 and the
    # row 0-6 gives ξ = 2 √(0.828·23.68 − 10.5) = 6.035 > 6. The row 0-6 is nearer its range (6.035/6 against
    # 6/5.961) and is used.
    f = math.sqrt(23.68) * C
    est = zui_tension(L, M, f, 1, EI)
    assert est.ok and est.row == "mode 1, 0 <= xi <= 6" and "cycle" in est.note
    assert est.xi == pytest.approx(2 * math.sqrt(0.828 * 23.68 - 10.5), rel=1e-12)
    assert est.error_band == ERROR_BANDS["mode 1, 0 <= xi <= 6"][-1][2]  # ξ clipped to 6, the row's last band
    assert zui_tension(L, M, f, 1, EI) == est


def test_bad_input_names_the_field():
    with pytest.raises(ModelError, match="mode"):
        zui_tension(L, M, 1.0, 0, EI)
    with pytest.raises(ModelError, match="EI"):
        zui_tension(L, M, 1.0, 1, 0.0)


# ---- the bands against a fresh, coarser sweep of the exact model ---------------------------------------------

def sweep_errors(length, mass, EI, points):
    """(row label, interval index, mode, error) over ξ log-spaced as in benchmarks/zui_bands.py, coarser."""
    cable = clamped(length, mass, EI)
    out = []
    xi12 = np.geomspace(0.05, 1e4, points)
    xin = np.geomspace(180, 1e5, points // 10)
    for xi, modes in ((xi12, (1, 2)), (xin, range(3, MAX_MODE + 1))):
        tension = EI * (xi / length) ** 2
        f = batch_frequencies(cable, [], tension, max(modes), plane="out")
        for n in modes:
            for t, fn in zip(tension, f[:, n - 1]):
                row, t_zui, xi_zui, _ = settle_row(length, mass, float(fn), n, EI)
                if row is not None and t_zui > 0:
                    out.append((row.label, band_index(row, xi_zui, n), n, t_zui / t - 1))
    return out


@pytest.fixture(scope="module")
def swept():
    return sweep_errors(100.0, 50.0, 1.0e5, 3000)


def test_error_is_a_function_of_xi_alone():
    # a second cable (other l, m, EI) at the same ξ: the same errors; 1e-9 is far above the solver's root
    # tolerance (~1e-13 relative on the frequencies) and far below any band
    a = sweep_errors(100.0, 50.0, 1.0e5, 300)
    b = sweep_errors(37.0, 3.2, 7.5e3, 300)
    assert [x[:3] for x in a] == [x[:3] for x in b]
    np.testing.assert_allclose([x[3] for x in a], [x[3] for x in b], rtol=0, atol=1e-9)


def test_bands_hold_and_are_tight(swept):
    by_bin = {}
    for label, index, _, error in swept:
        if index is not None:
            by_bin.setdefault((label, index), []).append(abs(error))
    for label, intervals in ERROR_BANDS.items():
        for index, (low, high, band) in enumerate(intervals):
            errors = by_bin.get((label, index), [])
            # enough samples to see the interval's largest error (the narrowest, ξ 17-20, gets ~25)
            assert len(errors) >= 20, (label, low, high, len(errors))
            measured = max(errors)
            assert measured <= band, f"{label}, {low}-{high}: error {measured:.5f} above the band {band}"
            # not loose: the stated band is the dense sweep's largest error rounded up to two significant
            # digits, so at most ~10 % above it, plus what a coarser sweep misses of a peak at an interval's end;
            # 1.5x + 0.1 % leaves room for that and no more
            assert band <= 1.5 * measured + 0.001, f"{label}, {low}-{high}: band {band} loose ({measured:.5f})"


def test_excluded_parts_are_beyond_use(swept):
    # the part left out is where the error exceeds the row's band just above it (why it was left out)
    for label in EXCLUDED:
        errors = [abs(e) for lab, index, _, e in swept if lab == label and index is None]
        assert max(errors) > ERROR_BANDS[label][0][2]


# ---- acceptance: random cables, finite-element reference frequencies ----------------------------------------

#: FE mesh: 300 Hermite elements graded towards the clamps (grading 0.1 ξ puts elements into the boundary layer
#: of width l/ξ), sparse solver. Its frequency error against the exact model (checked below) stays under 2e-5
#: for the modes and ξ drawn, i.e. under 4e-5 on the tension: below 1/20 of the smallest band (0.092 %).
FE_ELEMENTS = 300
FE_MAX_ERROR = 2e-5


def fe_reference(cable, tension, n_modes, xi):
    return fe_frequencies(cable, [], tension, n_modes, n_elements=FE_ELEMENTS, solver="sparse",
                          grading=0.1 * xi, plane="out")


@pytest.mark.parametrize("xi, n_modes", [(0.3, 2), (6.0, 2), (17.0, 2), (60.0, 2), (3000.0, 2), (200.0, 20),
                                         (400.0, 40), (3000.0, 40)])
def test_fe_reference_is_accurate_enough(xi, n_modes):
    cable = clamped(80.0, 30.0, 2.0e5)
    tension = 2.0e5 * (xi / 80.0) ** 2
    exact = batch_frequencies(cable, [], np.array([tension]), n_modes, plane="out")[0]
    fe = fe_reference(cable, tension, n_modes, xi)
    modes = np.arange(1, n_modes + 1)
    drawn = (modes <= 2) | (xi / modes >= 10)  # only the modes the acceptance draws at this ξ
    assert np.max(np.abs(fe[drawn] / exact[drawn] - 1)) < FE_MAX_ERROR


#: Where each row's cables are drawn (true ξ, log-uniform): the row's range less its excluded part, the open
#: ends cut at 3000 (stays reach ξ ≈ 1000).
DRAW_RANGES = {
    "mode 1, xi >= 17": (17.0, 3000.0), "mode 1, 6 <= xi <= 17": (6.0, 17.0), "mode 1, 0 <= xi <= 6": (0.3, 6.0),
    "mode 2, xi >= 60": (60.0, 3000.0), "mode 2, 17 <= xi <= 60": (17.0, 60.0), "mode 2, 0 <= xi <= 17": (0.7, 17.0),
    "mode n >= 3, xi >= 200": (200.0, 3000.0),
}
CASES_PER_ROW = 60


@pytest.mark.parametrize("label", list(DRAW_RANGES))
def test_acceptance_on_random_cables(label):
    rng = np.random.default_rng(1996 + list(DRAW_RANGES).index(label))
    low, high = DRAW_RANGES[label]
    inside = 0
    for _ in range(CASES_PER_ROW):
        length, mass = math.exp(rng.uniform(math.log(5), math.log(400))), rng.uniform(1.0, 150.0)
        EI = math.exp(rng.uniform(math.log(1e3), math.log(1e7)))
        xi = math.exp(rng.uniform(math.log(low), math.log(high)))
        mode = ROW[label].mode or int(rng.integers(3, min(40, int(xi / 10)) + 1))
        tension = EI * (xi / length) ** 2
        f = fe_reference(clamped(length, mass, EI), tension, mode, xi)[mode - 1]
        est = zui_tension(length, mass, float(f), mode, EI)
        # an answer outside its band, or none (a true ξ near an excluded part whose answer falls in it), is a miss
        inside += est.ok and abs(est.tension / tension - 1) <= est.error_band
    # the bands are the largest error of a dense sweep: nearly all answers should lie inside; 95 % as asked
    assert inside >= 0.95 * CASES_PER_ROW, f"{label}: {inside} of {CASES_PER_ROW} within the band"
