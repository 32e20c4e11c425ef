"""Mode numbering from the family structure (spectra/numbering.py)."""

import math
import warnings

import numpy as np
import pytest

from stcs_ident.core.errors import NumberingWarning
from stcs_ident.core.model import Attachment, Cable
from stcs_ident.forward import natural_frequencies
from stcs_ident.spectra.numbering import assign, number_modes

STAY = Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=np.radians(30))
STAY_ATTS = [Attachment("damper", 3.0, 50.0, 5.0e4)]
HANGER = Cable(length=8.0, mass_per_length=30.0, EI=2.0e5)
HANGER_ATTS = [Attachment("clamp", 2.7, 15.0)]


def test_assign_is_order_preserving_and_skips_spurious_peaks():
    family = np.array([[1.0, 2.0, 3.0, 4.0, 5.0]])
    peaks = np.array([1.001, 2.5, 3.0, 4.999])  # 2.5 fits nothing
    modes, _cost = assign(peaks, np.full(4, 0.01), family)
    np.testing.assert_array_equal(modes[0], [1, 0, 3, 5])


@pytest.mark.parametrize("cable,atts,tension", [(STAY, STAY_ATTS, 4.0e6), (HANGER, HANGER_ATTS, 4.0e5)])
@pytest.mark.parametrize("tension_error", [0.75, 1.0, 1.32])  # frequencies ~13 % low to ~15 % high
@pytest.mark.parametrize("missing", [(), (0,), (1, 2), (0, 4, 6)])
def test_numbers_survive_a_wrong_nominal_and_missing_modes(cable, atts, tension, tension_error, missing):
    """The truth has the tension off by the given factor and EI 30 % off;
    some modes are missing; measured to 1e-4 relative."""
    true = natural_frequencies(Cable(cable.length, cable.mass_per_length, cable.EI * 1.3, cable.EA,
                                     cable.inclination), atts, tension * tension_error, 10)
    keep = np.array([k for k in range(10) if k not in missing])
    rng = np.random.default_rng(len(missing))
    f = true[keep] * (1 + 1e-4 * rng.standard_normal(keep.size))
    with warnings.catch_warnings():
        warnings.simplefilter("error", NumberingWarning)
        result = number_modes(f, 1e-4 * f, cable, atts, tension)
    np.testing.assert_array_equal(result.modes, keep + 1)
    assert not result.doubtful.any()


def test_spurious_peak_is_left_unassigned():
    true = natural_frequencies(HANGER, HANGER_ATTS, 4.0e5, 6)
    f = np.sort(np.append(true, 0.5 * (true[2] + true[3])))
    result = number_modes(f, 1e-4 * f, HANGER, HANGER_ATTS, 4.0e5)
    assert list(result.modes) == [1, 2, 3, 0, 4, 5, 6]


def test_ambiguous_numbering_is_flagged_not_guessed():
    """Only high modes, imprecise, and a nominal 30 % off: several numberings
    fit, so every peak is flagged and a warning says so."""
    true = natural_frequencies(STAY, STAY_ATTS, 4.0e6, 16)[10:14]
    with pytest.warns(NumberingWarning, match="doubtful"):
        result = number_modes(true, 5e-3 * true, STAY, STAY_ATTS, 4.0e6 * 1.3)
    assert result.doubtful.all()


def _assign_reference(f, sigma, family, unassigned):
    """The recurrence mode by mode, in plain Python (one family): the vectorised assign must equal it."""
    n, K = len(f), len(family)
    best = [[0.0] * (K + 1)] + [[math.inf] * (K + 1) for _ in range(n)]
    choice = [[0] * (K + 1) for _ in range(n + 1)]
    for j in range(1, n + 1):
        best[j][0], choice[j][0] = best[j - 1][0] + unassigned, 2
        for k in range(1, K + 1):
            options = [best[j][k - 1], best[j - 1][k - 1] + ((f[j - 1] - family[k - 1]) / sigma[j - 1]) ** 2,
                       best[j - 1][k] + unassigned]
            c = min(range(3), key=lambda i: (options[i], i))
            best[j][k], choice[j][k] = options[c], c
    modes, j, k = [0] * n, n, K
    while j > 0:
        c = choice[j][k]
        if c == 0:
            k -= 1
        elif c == 1:
            modes[j - 1], j, k = k, j - 1, k - 1
        else:
            j -= 1
    return modes, best[n][K]


def test_the_row_at_once_assignment_equals_the_recurrence_mode_by_mode():
    """assign takes each row of its dynamic programme at once (a running minimum along the modes); on random
    peaks and families, ties included (integer frequencies), it gives the same modes and cost."""
    from stcs_ident.spectra.numbering import assign
    from stcs_ident.spectra.options import NumberingOptions

    rng = np.random.default_rng(3)
    for trial in range(200):
        n, K = int(rng.integers(1, 15)), int(rng.integers(1, 20))
        f = np.sort(rng.uniform(0, 60, n))
        family = np.sort(rng.uniform(0, 60, K))
        if trial % 2:
            f, family = np.round(f), np.round(family)
        sigma = rng.uniform(0.5, 3.0, n)
        modes, cost = assign(f, sigma, family[None, :])
        expected_modes, expected_cost = _assign_reference(f, sigma, family, NumberingOptions().unassigned_cost)
        assert list(modes[0]) == expected_modes and cost[0] == expected_cost


@pytest.mark.parametrize("eta", [0.3, 1.0, 5.0])
def test_damped_families_from_the_undamped_grid_match_the_exact_complex_ones(eta):
    """With a dashpot the search grid's families are the undamped ones times the damper's effect solved on a
    coarse grid (numbering._families): they must stay well inside the numbering's 0.3 % model tolerance of the
    exact complex families, at the grid's points between the coarse ones."""
    from stcs_ident.core.model import Damper
    from stcs_ident.forward import batch_frequencies
    from stcs_ident.spectra.numbering import DAMPED_GRID, _families

    cable = Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=math.radians(30.0))
    tension, xd = 4.0e6, 3.0
    optimum = math.sqrt(tension * cable.mass_per_length) * cable.length / (math.pi * xd)  # η₁ = 1
    damper = [Damper("D", xd, 10.0, coefficient=eta * optimum)]
    t_ratio, ei_ratio = np.geomspace(0.6, 1.5, 13), np.geomspace(0.2, 5.0, 6)
    assert t_ratio.size * ei_ratio.size > np.prod(DAMPED_GRID)  # the coarse path is the one tested
    got = _families(cable, damper, tension, t_ratio, ei_ratio, 15, ("uniform", {"plane": "in"}))
    exact = batch_frequencies(cable, damper, tension * t_ratio[:, None], 15, EI=cable.EI * ei_ratio[None, :])
    undamped = batch_frequencies(cable, damper, tension * t_ratio[:, None], 15, EI=cable.EI * ei_ratio[None, :],
                                 coefficients=[0.0])
    assert np.max(np.abs(exact / undamped - 1)) > 5e-3  # the damper moves the frequencies: it is not ignored
    # 1e-3: a third of the numbering's model tolerance (measured: at most 8e-4 on a 49 x 15 grid, 25 modes)
    assert np.max(np.abs(got / exact - 1)) < 1e-3


def test_the_search_grid_is_solved_once_per_model_and_gives_the_same_numbers(monkeypatch):
    """A monitoring archive numbers every record of a cable against one nominal model: its grid's families
    are kept (numbering._FAMILIES) and not solved again; the numbers are the same either way."""
    from stcs_ident.core.memo import BoundedCache
    from stcs_ident.spectra import numbering

    cable = Cable(length=80.0, mass_per_length=50.0, EI=1.0e5, EA=2.0e9, inclination=math.radians(25.0))
    atts = [Attachment("W", 7.0, 30.0)]
    true = natural_frequencies(cable, atts, 3.1e6, 12)
    monkeypatch.setattr(numbering, "_FAMILIES", BoundedCache(numbering.MAX_GRIDS))
    calls = []
    solve = numbering._families
    monkeypatch.setattr(numbering, "_families", lambda *a: calls.append(1) or solve(*a))
    first = number_modes(true[1:], np.full(11, 1e-3), cable, atts, 3.0e6)
    again = number_modes(true[1:] * 1.002, np.full(11, 1e-3), cable, atts, 3.0e6)
    assert len(calls) == 1  # the second record's grid came from the first's
    monkeypatch.setattr(numbering, "_FAMILIES", BoundedCache(numbering.MAX_GRIDS))
    fresh = number_modes(true[1:] * 1.002, np.full(11, 1e-3), cable, atts, 3.0e6)
    assert len(calls) == 2
    assert np.array_equal(first.modes, np.arange(2, 13)) and np.array_equal(again.modes, fresh.modes)
    assert again.tension_ratio == fresh.tension_ratio and np.array_equal(again.predicted, fresh.predicted)
