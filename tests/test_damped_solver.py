"""The complex-mode solver's machinery (issue 13): compiled kernel against the numpy reference, the
undamped limit with the sag term, the count certificate, and what routes through it.

The physics (Krenk's curve, the finite-element reference on random cables) is checked in test_damped.py and
test_damped_reference.py; here: that the two code paths agree to round-off, that the certificate does fail
when a mode is lost, and that a damper reaches every caller of ``batch_frequencies``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stcs_ident.core.errors import ComputationError
from stcs_ident.core.model import Attachment, Boundary, Cable, Damper
from stcs_ident.forward import batch_frequencies, damped, natural_frequencies
from stcs_ident.forward.batch import build_batch
from stcs_ident.forward.damped import batch_complex_modes, complete, complex_modes, follow_roots
from stcs_ident.forward.roots import solve_modes

STAY = Cable(200.0, 80.0, 5.0e5, EA=2.0e9, inclination=math.radians(30.0))
H = 5.0e6
#: Mode 1's optimal dashpot for a damper at 4 m (η = c π x_d/(l √(H m)) = 1).
C_OPT = math.sqrt(H * 80.0) / (math.pi * 4.0 / 200.0)


def _numpy(monkeypatch):
    monkeypatch.setattr(damped, "_damped_kernel", None)


@pytest.mark.skipif(damped._damped_kernel is None, reason="the compiled kernel is not built")
@pytest.mark.parametrize("scale", [1e-2, 1.0, 100.0])
@pytest.mark.parametrize("beam", [True, False])
def test_the_compiled_kernel_equals_the_numpy_reference(monkeypatch, scale, beam):
    """Same numerics in C and numpy: equal to round-off (1e-13 of |s|: the last digits of the secant's stop),
    one damper small, optimal or beyond it, and two dampers with an attachment."""
    cable = STAY if beam else Cable(200.0, 80.0, 0.0, EA=2.0e9, inclination=math.radians(30.0))
    atts = [Damper("D1", 4.0, 10.0, coefficient=scale * C_OPT), Attachment("W", 61.0, 40.0, 2e3),
            Damper("D2", 196.0, coefficient=0.3 * scale * C_OPT)]
    compiled = batch_complex_modes(cable, atts, H, 6)
    _numpy(monkeypatch)
    reference = batch_complex_modes(cable, atts, H, 6)
    np.testing.assert_allclose(compiled, reference, rtol=1e-13, atol=0)


def test_without_a_dashpot_the_solver_is_the_undamped_one_with_sag():
    atts = [Attachment("W", 61.0, 40.0, 2e3)]
    s = batch_complex_modes(STAY, atts, H, 8)
    assert np.all(s.real == 0)
    np.testing.assert_array_equal(np.abs(s) / (2 * math.pi), natural_frequencies(STAY, atts, H, 8))


def test_a_vanishing_dashpot_approaches_the_undamped_modes_with_sag():
    """A dashpot of 1e-6 N s/m moves nothing by more than 1e-12 (its first-order shift is ~1e-14)."""
    s = batch_complex_modes(STAY, [Damper("D1", 4.0, 10.0, coefficient=1e-6)], H, 6)
    f0 = natural_frequencies(STAY, [Attachment("D1", 4.0, 10.0)], H, 6)
    np.testing.assert_allclose(np.abs(s) / (2 * math.pi), f0, rtol=1e-12)
    assert np.all(-s.real / np.abs(s) < 1e-9)


@pytest.mark.parametrize("path", ["compiled", "numpy"])
def test_very_large_dashpots_at_both_ends_are_followed_to_the_pinned_roots(monkeypatch, path):
    """Dashpots of 100 × the optimum at both ends: each mode's path passes its maximum damping early in the
    continuation and ends near the root with both damper nodes pinned (within the little damping left)."""
    if path == "numpy":
        _numpy(monkeypatch)
    atts = [Damper("D1", 4.0, coefficient=100 * C_OPT), Damper("D2", 195.0, coefficient=100 * C_OPT)]
    modes = complex_modes(STAY, atts, H, 10)
    pinned = natural_frequencies(STAY, [Attachment("D1", 4.0, stiffness=1e12), Attachment("D2", 195.0,
                                                                                          stiffness=1e12)], H, 10)
    np.testing.assert_allclose(modes.frequency, pinned, rtol=2e-3)  # what damping is left moves |s| this much
    assert np.all(modes.damping < 2e-3)


def test_the_count_finds_a_lost_mode_again_and_refuses_a_false_one():
    """A root replaced by a copy of its neighbour (a path that jumped) is found again by the band search; a
    point that is no root, put among the roots, makes the count refuse."""
    atts = [Damper("D1", 4.0, coefficient=C_OPT)]
    _, [(batch, _)] = build_batch(STAY, atts, H)
    omega = solve_modes(batch, np.zeros(7, int), np.arange(1, 8))
    pinned = damped._pinned_roots(batch, np.array([0]), 7)[0]
    s = follow_roots(batch, 0, omega, pinned)
    np.testing.assert_array_equal(complete(batch, 0, omega, s, 6), s)  # the true roots pass as they are
    lost = s.copy()
    lost[3] = lost[2]
    np.testing.assert_allclose(complete(batch, 0, omega, lost, 6), s, rtol=1e-9)
    false = s.copy()
    false[3] = 0.5 * (s[3] + s[4])  # not a root, and the true one gone: the count is right, the points not
    false = np.append(false, 0.5 * (s[1] + s[2]))  # one point too many
    with pytest.raises(ComputationError, match="by the argument principle"):
        complete(batch, 0, omega, false, 6)


def test_a_heavy_damper_s_own_overdamped_modes_do_not_capture_a_cable_mode():
    """A 10 kg damper with a large dashpot on a 200 m stay has overdamped roots of its own that cross the
    cable modes' paths (the path of mode 25 ended on one); asked for 60 modes, every cable mode is found
    (the count holds) and none is overdamped."""
    atts = [Damper("D1", 4.0, 10.0, coefficient=4e5)]
    modes = complex_modes(STAY, atts, H, 60)
    assert np.all(modes.damping < 0.05)
    assert np.all(np.diff(modes.frequency) > 0)


def test_batch_frequencies_with_a_damper_gives_the_complex_modes_frequencies():
    """identify, diagnose and numbering call batch_frequencies: a damper reaches them as |s|/2π, and a
    coefficient override turns a plain attachment into a damper."""
    atts = [Damper("D1", 4.0, coefficient=C_OPT)]
    f = batch_frequencies(STAY, atts, [H, 1.1 * H], 5)
    for row, tension in zip(f, [H, 1.1 * H]):
        np.testing.assert_allclose(row, complex_modes(STAY, atts, tension, 5).frequency, rtol=1e-14)
    plain = [Attachment("D1", 4.0)]
    np.testing.assert_allclose(batch_frequencies(STAY, plain, H, 5, coefficients=[[C_OPT]])[0], f[0], rtol=1e-14)


def test_an_elastic_end_and_a_damper_with_a_spring_and_a_mass():
    """Every kind of term at once (end spring, damper spring and mass, an attachment) on both code paths'
    certificate: the solve succeeds and the damping ratios lie below Krenk's bound x_d/(2l) (a spring and
    a mass on the damper only lower what it can add)."""
    cable = Cable(150.0, 60.0, 2e5, EA=1.5e9, inclination=math.radians(25.0),
                  boundary_a=Boundary(1e7), boundary_b=Boundary.clamped())
    atts = [Damper("D1", 3.0, 15.0, 2e4, coefficient=2e5), Attachment("W", 70.0, 25.0)]
    modes = complex_modes(cable, atts, 3.5e6, 8)
    assert np.all(modes.damping > 0) and np.all(modes.damping < 3.0 / (2 * 150.0))
    assert np.all(np.diff(modes.frequency) > 0)


def test_complex_mode_shapes_reduce_to_the_real_ones_and_carry_a_phase_with_a_damper():
    """As the dashpot vanishes the complex shapes are the undamped mass-normalised ones up to a complex
    factor (1e-8: the null vector's accuracy); at mode 1's optimum the shape near the damper leads or lags
    mid-span by a fraction of a right angle (45° for Krenk's η = 1), where a real shape has none."""
    from stcs_ident.forward.damped_shapes import complex_mode_shapes
    from stcs_ident.forward.shapes import mode_shapes

    x = np.linspace(0.0, STAY.length, 401)
    complex_ = complex_mode_shapes(STAY, [Damper("D1", 4.0, coefficient=1e-3)], H, 4)(x)
    real = mode_shapes(STAY, [Attachment("D1", 4.0)], H, 4)(x)
    factor = (real * complex_).sum(axis=0) / (real**2).sum(axis=0)
    np.testing.assert_allclose(complex_, real * factor, atol=1e-8)
    shapes = complex_mode_shapes(STAY, [Damper("D1", 4.0, coefficient=C_OPT)], H, 1)
    near, mid = shapes(np.array([4.0, STAY.length / 2]))[:, 0]
    lag = abs(math.degrees(np.angle(near / mid)))
    assert 10.0 < lag < 80.0, lag
    assert shapes.damping[0] == pytest.approx(complex_modes(STAY, [Damper("D1", 4.0, coefficient=C_OPT)], H, 1)
                                              .damping[0], rel=1e-12)


@pytest.mark.skipif(damped._damped_kernel is None, reason="the compiled kernel is not built")
@pytest.mark.parametrize("scale", [0.3, 1.0, 5.0])
def test_a_warm_start_finds_the_cold_solves_roots_and_refuses_what_moved_too_far(scale):
    """A fit's trial points are warm-started from the previous point's roots (forward.damped._warm): nearby,
    the same roots as the solve from the undamped ones (to 1e-9 of |s|: both stop the secant at 1e-10); far
    (tension ×1.5, every root moved by more than its spacing), refused by the checks and solved cold, so
    again the same; and a start holding a neighbour's root in place of a mode's is refused, not followed."""
    atts = [Damper("D1", 4.0, 10.0, coefficient=scale * C_OPT), Attachment("W", 61.0, 40.0, 2e3)]
    base = batch_complex_modes(STAY, atts, H, 12, certify=False)
    tensions = H * np.array([1.0, 1.0 + 1e-6, 1.003, 1.5])
    cold = batch_complex_modes(STAY, atts, tensions, 12, certify=False)
    warm = batch_complex_modes(STAY, atts, tensions, 12, certify=False, start=base)
    assert np.max(np.abs(warm / cold - 1)) < 1e-9
    ok = damped._warm(build_batch(STAY, atts, tensions)[1][0][0], np.broadcast_to(base, (4, 12)), 12)[1]
    assert ok[:3].all() and not ok[3]  # the far one went cold
    wrong = base.copy()
    wrong[4] = wrong[5]  # mode 5's start is mode 6's root: two starts at one root
    ok = damped._warm(build_batch(STAY, atts, H)[1][0][0], wrong[None, :], 12)[1]
    assert not ok.any()
    assert np.allclose(batch_complex_modes(STAY, atts, H, 12, certify=False, start=wrong), base, rtol=1e-9)


def test_a_lost_parameter_set_is_nan_when_asked_and_the_others_are_kept(monkeypatch):
    """``lost="nan"``: a fit's extreme trial point whose roots cannot be followed gives NaN roots, the other
    rows of its batch their roots (the fits used to solve such a batch again row by row)."""
    atts = [Damper("D1", 4.0, 10.0, coefficient=C_OPT)]
    tensions = H * np.array([1.0, 1.1])
    good = batch_complex_modes(STAY, atts, tensions, 6, certify=False)
    kernel = damped._damped_kernel
    if damped.use_kernel():  # the kernel reports the second parameter set's path lost
        from types import SimpleNamespace

        monkeypatch.setattr(damped, "_damped_kernel", SimpleNamespace(solve=_failing_second(kernel.solve),
                                                                      refine=kernel.refine))
    else:
        def failing(batch, config, *args, **kwargs):
            if config == 1:
                raise ComputationError("a damped mode could not be followed as the dampers grow")
            return follow_roots(batch, config, *args, **kwargs)
        monkeypatch.setattr(damped, "follow_roots", failing)
    with pytest.raises(ComputationError, match="could not be followed"):
        batch_complex_modes(STAY, atts, tensions, 6, certify=False)
    s = batch_complex_modes(STAY, atts, tensions, 6, certify=False, lost="nan")
    assert np.allclose(s[0], good[0], rtol=1e-12) and np.all(np.isnan(s[1]))


def _failing_second(solve):
    """The kernel's solve with the status of its second configuration set to a lost path."""
    def wrapped(*args):
        raw, status = solve(*args)
        status = bytearray(status)
        status[4:8] = np.array([1], dtype=np.intc).tobytes()
        return raw, bytes(status)
    return wrapped
