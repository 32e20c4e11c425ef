"""The stated tension σ covers the truth when what is held fixed is itself uncertain.

Each data set is one test of a cable whose true EI, length and mass per length
depart from the campaign's nominal values as its ``[tolerance]`` says (EI 30 %,
length 0.2 %, mass per length 1 %, one standard deviation), measured with noise of the stated frequency
uncertainty. The identified tension ratio's |error| ≤ 1σ must hold in 68 ± 7 %
of the data sets and ≤ 3σ in ≥ 98 %, per condition: one mode, few modes, many
modes; EI held fixed (its tolerance propagated) or fitted; EI known (1 %) or not
(30 %); a stiff cable (ξ = l√(H/EI) ≈ 15, like a short hanger or a lab tube) and a
slender stay (ξ ≈ 140).

The seeds here (from 10 000) were never used while the rule was written (seeds
0-199 were); the rule has no free constant to tune anyway.
"""

import math
import warnings

import numpy as np
import pytest

from stcs_ident.core.model import Boundary, Cable, Campaign, Setup, Test
from stcs_ident.forward import batch_frequencies
from stcs_ident.identify import identify

#: (length m, mass kg/m, tension N, EI N m²): ξ = l √(H/EI) ≈ 15 and ≈ 140.
CABLES = {"stiff": (10.0, 5.0, 5.0e4, 2.2e4), "slender": (100.0, 60.0, 4.0e6, 2.0e6)}
#: Frequency noise (one standard deviation, and the stated uncertainty), relative to f1.
NOISE = 0.002
LENGTH_TOLERANCE = 0.002
MASS_TOLERANCE = 0.01
TRIALS = 300
FIRST_SEED = 10_000
# 68.3 % expected; over 300 data sets the binomial standard deviation is 2.7 %, so 61-75 % is ±2.6 of it
# (a calibrated rule fails this about 1 % of the time per condition).
ONE_SIGMA = (0.61, 0.75)
# 99.7 % expected; 98 % is the floor (6 of 300 outside 3σ).
THREE_SIGMA = 0.98

# condition: (cable, modes per test, free parameters, EI tolerance)
CONDITIONS = {
    "stiff, one mode, EI held (30 %)": ("stiff", 1, "tension", 0.3),
    "stiff, one mode, EI known (1 %)": ("stiff", 1, "tension", 0.01),
    "stiff, three modes, EI held (30 %)": ("stiff", 3, "tension", 0.3),
    "stiff, three modes, EI fitted": ("stiff", 3, "tension,EI", 0.3),
    "stiff, eight modes, EI fitted": ("stiff", 8, "tension,EI", 0.3),
    "slender, one mode, EI held (30 %)": ("slender", 1, "tension", 0.3),
    "slender, eight modes, EI held (30 %)": ("slender", 8, "tension", 0.3),
    "slender, eight modes, EI fitted": ("slender", 8, "tension,EI", 0.3),
}


def data_set(seed, cable, n_modes, ei_tolerance):
    """A campaign whose nominal EI and length are off by draws of their tolerances, and the true tension (N)."""
    length, mass, tension, EI = CABLES[cable]
    rng = np.random.default_rng(seed)
    true_EI = EI * (1 + ei_tolerance * rng.standard_normal())
    true_length = length * (1 + LENGTH_TOLERANCE * rng.standard_normal())
    true_mass = mass * (1 + MASS_TOLERANCE * rng.standard_normal())
    true_tension = tension * math.exp(0.3 * rng.standard_normal())
    f = batch_frequencies(Cable(true_length, true_mass, true_EI), (), np.array([true_tension]), n_modes)[0]
    sigma = NOISE * f[0]
    f = f + sigma * rng.standard_normal(n_modes)
    stated = true_tension * (1 + 0.1 * rng.standard_normal())  # the tension gauge's reading, 10 % off
    test = Test("T1", "bare", stated, tuple(f), uncertainty=(sigma,) * n_modes)
    # The tension's search bounds widened from 0.5-2x: with EI 30 % off, a stiff cable's three modes can pull the
    # fit below half the stated tension, where the default bound would make it a failure (not a σ to check).
    campaign = Campaign("coverage", Cable(length, mass, EI), (Setup("bare"),), (test,),
                        tolerance=(("EI", ei_tolerance), ("length", LENGTH_TOLERANCE),
                                   ("mass_per_length", MASS_TOLERANCE)),
                        bounds=(("tension", (0.1, 10.0)),))
    return campaign, true_tension


def normalised_errors(condition, trials=TRIALS, **options):
    cable, n_modes, params, ei_tolerance = CONDITIONS[condition]
    z = []
    for seed in range(FIRST_SEED, FIRST_SEED + trials):
        campaign, truth = data_set(seed, cable, n_modes, ei_tolerance)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # identifiability warnings of single-mode fits are not the point here
            result = identify(campaign, params=params, **options)
        value, sigma = result.value("tension[T1]")
        z.append((value - truth) / sigma)
    return np.abs(np.array(z))


@pytest.mark.slow
@pytest.mark.parametrize("condition", list(CONDITIONS))
def test_tension_sigma_covers_the_truth(condition):
    z = normalised_errors(condition)
    one, three = np.mean(z <= 1), np.mean(z <= 3)
    print(f"{condition}: |error| <= 1 sigma {one:.1%}, <= 3 sigma {three:.1%}, median |z| {np.median(z):.2f}")
    assert ONE_SIGMA[0] <= one <= ONE_SIGMA[1], f"{condition}: 1-sigma coverage {one:.1%}"
    assert three >= THREE_SIGMA, f"{condition}: 3-sigma coverage {three:.1%}"


@pytest.mark.slow
def test_without_the_tolerances_the_sigma_of_one_mode_is_far_too_small():
    """The check above can fail: the σ from the frequencies alone (EI taken as exact) covers a stiff cable's
    tension in far fewer than 68 % of the data sets."""
    z = normalised_errors("stiff, one mode, EI held (30 %)", trials=100, tolerances=False)
    assert np.mean(z <= 1) < 0.2


def test_one_mode_of_a_taut_string_gets_the_closed_form_sigma():
    """A pinned string (EI = 0): H = 4 l² m f², so σ_H/H = √((2σ_f/f)² + (2 t_l)² + t_m²) with the length's and
    the mass per length's relative tolerances t_l, t_m; the fit's σ (one mode, no degree of freedom left) must be
    that, and without the tolerances 2σ_f/f."""
    length, mass, f1, sigma_f, tol, tol_m = 50.0, 40.0, 2.0, 0.004, 0.002, 0.01
    H = 4 * length**2 * mass * f1**2
    cable = Cable(length, mass, 0.0, boundary_a=Boundary.pinned(), boundary_b=Boundary.pinned())
    test = Test("T1", "bare", 1.05 * H, (f1,), uncertainty=(sigma_f,))
    campaign = Campaign("string", cable, (Setup("bare"),), (test,),
                        tolerance=(("length", tol), ("mass_per_length", tol_m)))
    result = identify(campaign, params="tension")
    value, sigma = result.value("tension[T1]")
    # the fit converges to 1e-14 and the string's root is exact: 1e-9 leaves a wide margin
    assert value == pytest.approx(H, rel=1e-9)
    # first order in σ: the Jacobian's central difference (step 1e-6) is exact to ~1e-10 for H ∝ f²
    assert sigma / H == pytest.approx(math.sqrt((2 * sigma_f / f1) ** 2 + (2 * tol) ** 2 + tol_m**2), rel=1e-6)
    assert any(n.kind == "tolerances_propagated" and "length 0.2 %" in str(n) and "mass_per_length 1 %" in str(n)
               for n in result.notes)
    bare = identify(campaign, params="tension", tolerances=False)
    assert bare.value("tension[T1]")[1] / H == pytest.approx(2 * sigma_f / f1, rel=1e-6)


def test_a_tolerance_of_zero_and_fitted_values_are_not_propagated():
    length, mass, tension, EI = CABLES["slender"]
    f = batch_frequencies(Cable(length, mass, EI), (), np.array([tension]), 4)[0]
    test = Test("T1", "bare", tension, tuple(f), uncertainty=(0.001,) * 4)
    campaign = Campaign("exact", Cable(length, mass, EI), (Setup("bare"),), (test,),
                        tolerance=(("EI", 0.0), ("length", 0.0), ("mass_per_length", 0.0)))
    assert not any(n.kind == "tolerances_propagated" for n in identify(campaign, params="tension").notes)
    campaign = Campaign("exact", Cable(length, mass, EI), (Setup("bare"),), (test,),
                        tolerance=(("length", 0.0), ("mass_per_length", 0.0)))
    result = identify(campaign, params="tension,EI")  # EI fitted: its tolerance is not a nuisance
    assert not any(n.kind == "tolerances_propagated" for n in result.notes)
    held = identify(campaign, params="tension")
    assert any(n.kind == "tolerances_propagated" and "EI 30 %" in str(n) for n in held.notes)


def test_the_json_gives_both_shares_of_each_sigma():
    length, mass, tension, EI = CABLES["stiff"]
    f = batch_frequencies(Cable(length, mass, EI), (), np.array([tension]), 1)[0]
    test = Test("T1", "bare", tension, tuple(f), uncertainty=(0.01,))
    campaign = Campaign("stiff", Cable(length, mass, EI), (Setup("bare"),), (test,))
    result = identify(campaign, params="tension")
    sources = result.summary()["uncertainty_sources"]
    assert sources["held"] == {"EI": "30 %", "length": "0.2 %", "mass_per_length": "1 %"}
    share_f = sources["frequencies"]["tension_ratio"]["T1"]
    share_t = sources["tolerances"]["tension_ratio"]["T1"]
    # the shares add in quadrature to the stated σ (exactly: one covariance, split in two)
    assert math.hypot(share_f, share_t) == pytest.approx(result.get("tension_ratio[T1]")[1], rel=1e-12)
    # a stiff cable's one mode: EI's 30 % is most of it (about 4 % of the tension against 0.3 % from 0.01 Hz)
    assert share_t > 5 * share_f
    assert "uncertainty_sources" not in identify(campaign, params="tension", tolerances=False).summary()
