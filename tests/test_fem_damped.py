"""The finite-element reference of cables with dampers (complex modes): against the undamped model and Krenk.

Krenk (2000, J. Appl. Mech. 67, 772-776): a taut string with a viscous damper of coefficient c at x_d near an
end, x_d/l small: ζ_n ≈ (x_d/l) η/(1 + η²), η = (c/√(H m)) π n x_d/l, the "universal curve" with its maximum
x_d/(2l) at η = 1. The asymptote differs from the exact model by O(x_d/l): 2-3 % of ζ at x_d/l = 0.02.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from stcs_ident.core.errors import ComputationError, ModelError
from stcs_ident.core.model import Attachment, Boundary, Cable, Damper
from stcs_ident.forward import fem_damped
from stcs_ident.forward.fem import fe_modes
from stcs_ident.forward.fem_damped import fe_complex_modes

L, M, H = 100.0, 50.0, 2.0e6
XD = 0.02 * L


@pytest.mark.parametrize("n", [1, 2, 3])
@pytest.mark.parametrize("eta", [0.3, 1.0, 3.0])
def test_a_string_with_a_damper_near_an_end_follows_krenk_s_universal_curve(n, eta):
    c = eta * np.sqrt(H * M) / (np.pi * n * XD / L)
    modes = fe_complex_modes(Cable(L, M, 0.0), [Damper("D", XD, coefficient=c)], H, 4, n_elements=80)
    krenk = (XD / L) * eta / (1 + eta**2)
    assert modes.damping[n - 1] == pytest.approx(krenk, rel=0.04)  # O(x_d/l) = 2 %: 0.2-2.7 % measured
    assert modes.frequency[n - 1] == pytest.approx(n * np.sqrt(H / M) / (2 * L), rel=0.03)  # shifted by < x_d/l


def test_the_largest_damping_is_half_the_damper_s_relative_position():
    etas = np.geomspace(0.2, 5.0, 25)
    zeta = [fe_complex_modes(Cable(L, M, 0.0), [Damper("D", XD, coefficient=e * np.sqrt(H * M) / (np.pi * XD / L))],
                             H, 1, n_elements=60).damping[0] for e in etas]
    best = int(np.argmax(zeta))
    assert 0.7 <= etas[best] <= 1.4  # the grid's neighbours of η = 1 (it steps by 14 %)
    assert max(zeta) == pytest.approx(XD / (2 * L), rel=0.05)  # O(x_d/l) = 2 %: 2.1 % measured


def test_a_weak_damper_leaves_the_undamped_modes_and_damps_them_to_first_order():
    """A dashpot of 1e-6 N s/m with its parallel spring and mass, with the sag term: the frequencies are the
    undamped model's with an attachment of that spring and mass, to 1e-10 (both solves carry rounding
    relative to the low modes, 7e-13 measured; the dashpot shifts them by ~ζ² = 1e-24), and the damping
    ratios are first-order perturbation theory's ζ_n = c φ_n(x_d)²/(2 ω_n) (φ_n mass-normalised), to 1 %:
    ζ ~ 1e-12 is read from Re s ~ 1e-10 beside |s| ~ 100, whose rounding is ~1e-14 (0.11 % measured)."""
    cable = Cable(30.0, 12.0, 5.0e4, EA=3.0e9, inclination=0.4)
    damper = Damper("D", 1.2, coefficient=1e-6, stiffness=2.0e3, mass=4.0)
    modes = fe_complex_modes(cable, [Attachment("W", 11.0, 20.0), damper], 1.5e6, 5, n_elements=120)
    undamped, x, shapes, _ = fe_modes(cable, [Attachment("W", 11.0, 20.0), Attachment("D", 1.2, 4.0, 2.0e3)],
                                      1.5e6, 5, n_elements=120)
    np.testing.assert_allclose(modes.frequency, undamped, rtol=1e-10)
    at_damper = shapes[np.argmin(np.abs(x - 1.2))]
    np.testing.assert_allclose(modes.damping, 1e-6 * at_damper**2 / (2 * 2 * np.pi * undamped), rtol=0.01)


def test_a_strongly_damped_beam_converges_as_the_mesh_is_refined_without_drifting():
    """A 118 m taut beam (ξ = 300, sag term, clamped) with a damper at 3 % of the span five times beyond its
    optimum, with spring and mass: the complex roots converge as h⁴ (each doubling of the graded mesh
    divides the change by at least 8; 9-14 measured) down to 1e-8, where the dense QZ of the companion form
    used before drifted away from 3e-5 to 3e-4 between 200 and 800 elements."""
    length, m, tension = 118.0, 60.0, 4e6
    cable = Cable(length, m, tension * (length / 300) ** 2, EA=2e9, inclination=0.5)
    damper = Damper("D", 0.03 * length, coefficient=5 * np.sqrt(tension * m) / (np.pi * 0.03), stiffness=2e4,
                    mass=10.0)
    s = [fe_complex_modes(cable, [damper], tension, 4, n_elements=n, grading=2.0).s for n in (100, 200, 400, 800)]
    change = [np.max(np.abs(b / a - 1)) for a, b in itertools.pairwise(s)]
    assert all(later < earlier / 8 for earlier, later in itertools.pairwise(change))
    assert change[-1] < 1e-6


def test_an_overdamped_pair_is_not_a_mode():
    """A heavy damper mass (165 kg) on its spring with a strong dashpot: that local mode's pair of roots has
    met on the real axis (s = -0.64 rad/s, overdamped). The modes are the roots with Im s > 0 only: the
    real root, the lowest |s| of all, is not listed as a mode of damping ratio 1."""
    cable = Cable(168.8, 68.1, 1.105e8, boundary_a=Boundary(4.5e7), boundary_b=Boundary.pinned())
    atts = [Attachment("A0", 59.0, 887.0), Attachment("A1", 127.3, 991.0),
            Damper("D0", 160.4, mass=165.5, stiffness=8885.0, coefficient=4.07e5)]
    modes = fe_complex_modes(cable, atts, 8.9e5, 6, n_elements=200)
    assert np.all(modes.s.imag > 0)
    assert np.all(modes.damping < 0.05)  # 0.008-0.03 measured
    assert np.all(np.diff(np.abs(modes.s)) > 0)


def test_a_root_missed_by_the_first_solve_is_caught_by_the_second(monkeypatch):
    """The band check is live: hide mode 2 (and its conjugate) from the solve shifted to 0, and the solve
    shifted to -|s_N|/2 finds it and refuses."""
    solve = fem_damped._roots_near

    def hiding(model, C, omega0, shift, k):
        roots = solve(model, C, omega0, shift, k)
        if shift != 0:
            return roots
        second = np.sort(np.abs(roots[roots.imag > 0]))[1]
        return roots[np.abs(np.abs(roots) - second) > 1e-9 * second]

    monkeypatch.setattr(fem_damped, "_roots_near", hiding)
    with pytest.raises(ComputationError, match="missed by the other"):
        fe_complex_modes(Cable(L, M, 0.0), [Damper("D", XD, coefficient=1e5)], H, 4, n_elements=100)


def test_a_damper_outside_the_span_is_refused_naming_it():
    with pytest.raises(ModelError, match=r"damper\[D\]\.position"):
        fe_complex_modes(Cable(L, M, 0.0), [Damper("D", 120.0, coefficient=1.0)], H, 2)


@pytest.mark.parametrize("n_modes", [0, 2.5, True, 500])
def test_a_bad_number_of_modes_is_refused_naming_it(n_modes):
    with pytest.raises(ModelError, match="n_modes"):
        fe_complex_modes(Cable(L, M, 0.0), [Damper("D", XD, coefficient=1e3)], H, n_modes, n_elements=100)
