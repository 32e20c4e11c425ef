"""The exact complex modes (forward/damped.py) against the finite-element reference and the asymptotes.

1. Random cables with dampers, exact against finite elements (forward/fem_damped.py: graded meshes, doubled
   until two refinements agree, Richardson-extrapolated), to the issue's 1e-6 in frequency and 1e-4 in
   damping ratio, with the elements' own convergence checked on every case.
2. Krenk (2000, J. Appl. Mech. 67, 772-776), a taut string with a damper at x_d near an end:
   ζ_n ≈ (x_d/l) η/(1 + η²), η = (c/√(H m)) π n x_d/l, maximum x_d/(2l) at η = 1; its relative error is
   O(x_d/l).
3. Bending stiffness (the extension studied by Main & Jones 2007, J. Eng. Mech. 133(4), Parts I and II,
   and Hoang & Fujino 2007, J. Eng. Mech. 133(11)): the maximum drops and moves to larger η as the
   boundary layer δ = √(EI/H) grows against x_d. The formula checked here is derived in the docstring of
   :func:`bending_asymptote` (those papers' text was not at hand to compare it with symbol by symbol).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from stcs_ident.core.errors import ComputationError
from stcs_ident.core.model import Attachment, Cable, Damper
from stcs_ident.forward.damped import complex_modes
from stcs_ident.forward.fem_damped import fe_complex_modes
from tests.random_cables import random_end

FREQUENCY_RTOL = 1e-6  # the requirement for the exact solver, relative
DAMPING_ATOL = 1e-4  # the requirement, absolute in ζ
FE_UNCERTAINTY = 1e-7  # the reference's estimated error must be a tenth of the frequency tolerance
FE_FIRST, FE_MOST = 50, 3200  # elements of the coarsest and the finest mesh tried


# ------------------------------------------------------------------ random cables


def random_damped_configuration(rng):
    """A cable with dampers: (cable, attachments, tension, tension_model, n_modes).

    Strings and beams (ξ = l √(H/EI) from 3 to 1000), clamped, pinned or elastic ends, 0-2 attachments
    (masses and springs), 1-2 dampers (one at 1-5 % of the span from one end, the other at 1-5 % from the
    other end) of size η = c π x_d/(l √(H m)) from 0.1 to 10 with, half the time, a spring and a moving
    mass; the sag term on half the cables (tension_model "uniform", λ² from 0.1 to 50, inclination up to
    45°), left out on the others ("none").
    """
    length = rng.uniform(10.0, 200.0)
    m = 10 ** rng.uniform(-0.5, 2)
    theta = math.radians(rng.uniform(0, 45))
    w = m * 9.81 * math.cos(theta)
    sag = rng.uniform(0.001, 0.02)  # sag over span
    H = w * length / (8 * sag)
    EI = 0.0 if rng.random() < 0.25 else H * (length / 10 ** rng.uniform(math.log10(3), 3)) ** 2
    EA = None
    if rng.random() < 0.5:
        lam2 = rng.uniform(0.1, 50.0)
        EA = lam2 * H * length * (1 + 8 * sag**2) / ((w * length / H) ** 2 * length)
    cable = Cable(length, m, EI, EA=EA, inclination=theta, boundary_a=random_end(rng, EI, length),
                  boundary_b=random_end(rng, EI, length))
    atts = []
    for i in range(int(rng.integers(0, 3))):
        mass = rng.uniform(0, 0.1) * m * length if rng.random() < 0.7 else 0.0
        spring = 10 ** rng.uniform(-1, 1) * H / length if rng.random() < 0.4 else 0.0
        atts.append(Attachment(f"A{i}", rng.uniform(0.15, 0.85) * length, mass, spring))
    near_b = rng.random() < 0.5
    for k in range(int(rng.integers(1, 3))):
        frac = rng.uniform(0.01, 0.05)
        x = (1 - frac) * length if (k == 0) == near_b else frac * length
        eta = 10 ** rng.uniform(-1, 1)
        extras = rng.random() < 0.5
        atts.append(Damper(f"D{k}", x, coefficient=eta * math.sqrt(H * m) / (math.pi * frac),
                           stiffness=rng.uniform(0, 1) * H / (frac * length) if extras else 0.0,
                           mass=rng.uniform(0, 0.02) * m * length if extras else 0.0))
    return cable, atts, H, ("uniform" if EA is not None else "none"), int(rng.integers(3, 7))


def _nearest(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Index into ``b`` of the root nearest each of ``a``."""
    return np.argmin(np.abs(a[:, None] - b[None, :]), axis=1)


def fe_reference(cable, atts, H, tension_model, n_modes):
    """The finite-element roots, Richardson-extrapolated, with their estimated error and the mesh.

    The graded mesh (grading 2) is doubled from FE_FIRST elements until two refinements differ by d
    (largest relative change of a root) with d/15 <= FE_UNCERTAINTY, the error of the extrapolation
    s + (s - s_coarse)/15 for elements converging as h⁴ (h⁶ for a string: the extrapolation then
    over-corrects by less than d/15), and the refinement before changed them at least 8 times more (the
    asymptotic regime: 16 for h⁴, 64 for h⁶), unless d < 1e-10 (converged to rounding, where no ratio can
    be measured). Two more modes than asked, so none drops off the top between meshes.
    """
    levels, n = [], FE_FIRST
    while n <= FE_MOST:
        s = fe_complex_modes(cable, atts, H, n_modes + 2, n_elements=n, tension_model=tension_model,
                             grading=2.0).s
        if levels:
            order = _nearest(levels[-1], s)  # the same modes in the same order on every mesh
            assert np.unique(order).size == order.size, f"roots swapped between meshes: {cable}, {atts}"
            s = s[order]
        levels.append(s)
        if len(levels) >= 3:
            change = [np.max(np.abs(b[:n_modes] - a[:n_modes]) / np.abs(b[:n_modes]))
                      for a, b in zip(levels[-3:-1], levels[-2:])]
            if change[1] < 1e-10 or (change[1] / 15 <= FE_UNCERTAINTY and change[0] >= 8 * change[1]):
                return levels[-1] + (levels[-1] - levels[-2]) / 15, change[1] / 15, n
        n *= 2
    raise AssertionError(f"the finite elements did not converge by {FE_MOST} elements: {cable}, {atts}")


def exact_modes(cable, atts, H, tension_model, n_modes):
    """The exact solver's modes; when it refuses the band's top (two modes' order unsure there), one mode
    more, as its message asks."""
    try:
        return complex_modes(cable, atts, H, n_modes, tension_model=tension_model)
    except ComputationError as exc:
        if "ask for one mode more" not in str(exc):
            raise
        return complex_modes(cable, atts, H, n_modes + 1, tension_model=tension_model)


def check_against_elements(case) -> dict:
    """Exact against finite elements for one configuration; the measured errors."""
    cable, atts, H, tension_model, n_modes = case
    exact = exact_modes(cable, atts, H, tension_model, n_modes).s
    # A real root (ζ = 1) is an overdamped pair, not a mode: the elements list modes only (Im s > 0).
    oscillating = exact[exact.imag > 1e-12 * np.abs(exact)]
    reference, uncertainty, n_elements = fe_reference(cable, atts, H, tension_model, exact.size)
    where = f"{cable}, {atts}, H={H}, tension_model={tension_model!r}"
    pairs = _nearest(oscillating, reference)
    assert np.unique(pairs).size == pairs.size, where  # no element root taken for two exact ones
    matched = reference[pairs]
    np.testing.assert_allclose(np.abs(oscillating), np.abs(matched), rtol=FREQUENCY_RTOL, err_msg=where)
    np.testing.assert_allclose(-oscillating.real / np.abs(oscillating), -matched.real / np.abs(matched),
                               rtol=0, atol=DAMPING_ATOL, err_msg=where)
    # No mode missed by the exact solver: every element mode below its highest |s| is one of its modes.
    below = reference[np.abs(reference) < np.abs(oscillating).max() * (1 - 1e-6)]
    assert np.all(np.min(np.abs(below[:, None] - oscillating[None, :]), axis=1) < 1e-6 * np.abs(below)), where
    return {"frequency": np.max(np.abs(np.abs(oscillating) / np.abs(matched) - 1)),
            "damping": np.max(np.abs(oscillating.real / np.abs(oscillating) - matched.real / np.abs(matched))),
            "uncertainty": uncertainty, "elements": n_elements, "overdamped": exact.size - oscillating.size}


#: Random cases on which the exact solver refuses with "a mode was lost" (reported to forward/damped.py; the
#: elements find every root there): (seed, index) -> what happens. Each is a strict xfail below, so a fix
#: shows as a failure asking to remove it from this list; the random tests leave these out.
#: Cases the solver once refused ("a mode was lost"), kept as tests of what fixed them (the deflated
#: re-solve of a path that fell onto another's root, the count limited to ζ < 0.5).
HARD_CASES = {
    (13, 92): "a near crossover (sag, λ² ≈ 4π²): two undamped roots 0.9 % apart, one damped mode almost "
              "undamped (ζ = 9e-6) beside a damped one; two paths end on one root",
    (1, 55): "a near crossover with two dampers, roots 3 % apart (ζ = 2e-4 and 2e-3): two paths end on one root",
    (3, 68): "a near crossover with two dampers, roots 2 % apart (ζ = 9e-6 and 1.3e-2): two paths end on one root",
    (1, 28): "a beam (ξ = 25, pinned and elastic ends) with two dampers with springs and masses: a root of "
             "ζ = 0.70 at s = -86.6 + 87.2i lies in the count's rectangle below the band's top (mode 6 at "
             "79.8 rad/s, 7 at 100.1), so the count finds one root more than the six paths",
}


def random_case(seed: int, index: int):
    """The ``index``-th configuration drawn with ``seed``."""
    rng = np.random.default_rng(seed)
    for _ in range(index):
        random_damped_configuration(rng)
    return random_damped_configuration(rng)


def _run_cases(seed: int, count: int) -> None:
    rng = np.random.default_rng(seed)
    for index in range(count):
        case = random_damped_configuration(rng)
        check_against_elements(case)


def test_random_cables_with_dampers_agree_with_the_elements():
    """20 random cables (the generator's docstring says which): frequencies to 1e-6 and damping ratios to
    1e-4 against the converged elements (their own error below 1e-7 on every case; agreement measured
    6e-9 and 8e-9)."""
    _run_cases(2026, 20)


@pytest.mark.slow
def test_a_hundred_more_random_cables_with_dampers_agree_with_the_elements():
    """100 more random cables, another seed; as the test above (agreement measured 3e-8 and 1.5e-8)."""
    _run_cases(13, 100)


@pytest.mark.parametrize("seed, index", sorted(HARD_CASES))
def test_cases_the_solver_once_refused_agree_with_the_elements(seed, index):
    check_against_elements(random_case(seed, index))


# ------------------------------------------------------------------ Krenk's universal curve

L, M, H = 100.0, 50.0, 2.0e6


def _damper_size(eta: float, xd: float) -> float:
    """c (N s/m) of the damper size η for mode 1 at x_d on the module's cable."""
    return eta * math.sqrt(H * M) / (math.pi * xd / L)


def test_the_exact_model_follows_krenk_s_universal_curve_to_order_xd_over_l():
    """ζ_n/(x_d/l) against η_n/(1 + η_n²), modes 1-3, η_1 from 0.1 to 10, x_d/l = 0.005, 0.01, 0.02.

    The asymptote neglects terms of relative order x_d/l: the error must stay below 1.5 x_d/l (measured
    1.01-1.35 x_d/l, growing with the mode), and it must halve when x_d/l halves (the exact model tends to
    the asymptote, at the rate the theory says, rather than sitting near it by chance)."""
    etas = np.geomspace(0.1, 10.0, 15)
    worst = {}
    for ratio in (0.005, 0.01, 0.02):
        xd = ratio * L
        errors = []
        for eta in etas:
            modes = complex_modes(Cable(L, M, 0.0), [Damper("D", xd, coefficient=_damper_size(eta, xd))], H, 3)
            eta_n = eta * np.arange(1, 4)
            krenk = ratio * eta_n / (1 + eta_n**2)
            errors.append(np.abs(modes.damping / krenk - 1))
        worst[ratio] = np.max(errors)
        assert worst[ratio] <= 1.5 * ratio
    # O(x_d/l): 2, plus the next order's share, which grows with x_d/l (2.17 and 2.32 measured).
    assert worst[0.01] / worst[0.005] == pytest.approx(2.0, rel=0.15)
    assert worst[0.02] / worst[0.01] == pytest.approx(2.0, rel=0.25)


def _best_damping(cable: Cable, xd: float, guess: float) -> tuple[float, float]:
    """The largest mode-1 damping ratio over the damper size η, and the η that gives it."""
    def minus_zeta(log_eta):
        damper = Damper("D", xd, coefficient=_damper_size(math.exp(log_eta), xd))
        return -complex_modes(cable, [damper], H, 1).damping[0]

    best = minimize_scalar(minus_zeta, bounds=(math.log(guess / 4), math.log(guess * 4)), method="bounded",
                           options={"xatol": 1e-4})
    return -best.fun, math.exp(best.x)


def test_the_largest_damping_of_a_string_is_half_the_damper_s_relative_position_at_eta_one():
    """x_d/l = 0.01: the maximum x_d/(2l) within 1.5 x_d/l (the asymptote's order; 1.03 x_d/l measured),
    at η = 1 within 2 % (0.02 % measured: the peak's place is insensitive to the leading correction)."""
    xd = 0.01 * L
    best, eta = _best_damping(Cable(L, M, 0.0), xd, 1.0)
    assert best / (xd / (2 * L)) == pytest.approx(1.0, rel=1.5 * xd / L)
    assert eta == pytest.approx(1.0, rel=0.02)


# ------------------------------------------------------------------ bending stiffness


def bending_asymptote(eta, xd, length, delta):
    """ζ of mode 1 for a damper at x_d near a clamped end of a tensioned beam, δ = √(EI/H), and the largest
    ζ with the η that gives it: (ζ(η), ζ_max, η_opt).

    Matched asymptotics for x_d, δ << l: near the end the
    motion is static, EI u'''' − H u'' = F δ(x − x_d), clamped at 0; far from it the mode is a string's,
    u ≈ B (x − x₀). The clamped layer gives u = B φ(x), φ(x) = x − δ(1 − e^{−x/δ}); a point force F at
    x_d with no slope far away moves x_d by F a*/H, a* = x_d − (δ/2)(3 − 4e^{−x_d/δ} + e^{−2x_d/δ}), and
    the far field by F φ(x_d)/H (reciprocity). With F = −c s u(x_d), the far field's zero moves to
    x₀ = δ + (φ²/a*) iη̃/(1 + iη̃), η̃ = η a*/x_d, so ζ = Im x₀/l:

        ζ = (φ(x_d)²/(a* l)) η̃/(1 + η̃²),    ζ_max = φ(x_d)²/(2 a* l) at η = x_d/a*.

    δ → 0 gives Krenk's curve; δ >> x_d gives ζ_max → (3/8) x_d/l. Neglected: terms of relative order
    x_d/l and δ/l.
    """
    e = math.exp(-xd / delta) if delta > 0 else 0.0
    phi = xd - delta * (1 - e)
    a_star = xd - 0.5 * delta * (3 - 4 * e + e * e)
    eta_t = eta * a_star / xd
    return phi**2 / (a_star * length) * eta_t / (1 + eta_t**2), phi**2 / (2 * a_star * length), xd / a_star


@pytest.mark.parametrize("layers", [10.0, 3.0, 1.0])
def test_bending_stiffness_lowers_and_moves_the_largest_damping(layers):
    """A clamped tensioned beam, damper at x_d = 0.01 l, δ = √(EI/H) = x_d/layers.

    Against :func:`bending_asymptote`: the largest ζ within 1.5 (x_d + 2δ)/l, the asymptote's neglected
    order (the string's x_d/l, plus δ/l from each clamped end's layer shortening the outer mode; measured
    0.96-1.0 (x_d + 2δ)/l), and its η within 2 (x_d + 2δ)/l (measured 0.16-0.67). Fails if bending stiffness
    is ignored or mishandled: the maximum drops to 0.95, 0.88 and 0.81 of the string's, beyond these
    tolerances, and moves to η = 1.18, 1.88 and 5.95."""
    xd, delta = 0.01 * L, 0.01 * L / layers
    cable = Cable(L, M, H * delta**2)
    _, zeta_max, eta_opt = bending_asymptote(1.0, xd, L, delta)
    best, eta = _best_damping(cable, xd, eta_opt)
    order = (xd + 2 * delta) / L
    assert best == pytest.approx(zeta_max, rel=1.5 * order)
    assert eta == pytest.approx(eta_opt, rel=2 * order)
    string_max = bending_asymptote(1.0, xd, L, 0.0)[1]
    assert abs(zeta_max / string_max - 1) > 3 * order  # the drop is larger than the tolerance: a real check
