"""The exact solver against the independent finite-element model.

200 random configurations (tests/random_cables.py): 0–4 attachments with
masses and springs; clamped, pinned and rotational-spring ends; λ² from 0
to 200, so symmetric and antisymmetric modes cross; inclinations 0–45°.
The first 12 frequencies must agree to 2e-5 relative: a missed or
duplicated root would shift the whole sequence by a mode, far more than
that. The FE model converges as h⁴ (tests/test_fem.py); where 600 elements
are not yet within 1e-5, the mesh is doubled and must move towards the
exact answer.
"""

import numpy as np
import pytest

from stcs_ident.core.model import Attachment, Cable
from stcs_ident.forward import natural_frequencies
from stcs_ident.forward.fem import fe_frequencies, fe_modes
from stcs_ident.forward.shapes import modal_masses, mode_shapes
from tests.random_cables import random_configuration

N_CONFIGS = 200
N_MODES = 12
RTOL = 2e-5  # the acceptance


def configurations(seed, n):
    rng = np.random.default_rng(seed)
    return [random_configuration(rng) for _ in range(n)]


def test_configurations_span_the_acceptance_ranges():
    configs = configurations(2026, N_CONFIGS)
    n_att = [len(a) for _, a, _ in configs]
    kinds = {c.boundary_a.kind for c, _, _ in configs} | {c.boundary_b.kind for c, _, _ in configs}
    assert set(n_att) == {0, 1, 2, 3, 4}
    assert kinds == {"clamped", "pinned", "spring"}
    assert any(any(x.stiffness > 0 for x in a) for _, a, _ in configs)
    assert max(np.degrees(c.inclination) for c, _, _ in configs) > 40


@pytest.mark.slow
def test_frequencies_agree_with_finite_elements():
    worst = 0.0
    for i, (cable, atts, H) in enumerate(configurations(2026, N_CONFIGS)):
        exact = natural_frequencies(cable, atts, H, N_MODES)
        assert np.all(np.diff(exact) >= 0)
        fe = fe_frequencies(cable, atts, H, N_MODES, n_elements=600, grading=2.0, solver="sparse")
        err = np.abs(fe / exact - 1).max()
        if err > 1e-5:
            finer = fe_frequencies(cable, atts, H, N_MODES, n_elements=1200, grading=2.0, solver="sparse")
            err_finer = np.abs(finer / exact - 1).max()
            assert err_finer < err, f"configuration {i}: FE does not converge towards the exact solver"
            err = err_finer
        assert err <= RTOL, f"configuration {i}: {err:.2e}"
        worst = max(worst, err)
    print(f"largest relative difference over {N_CONFIGS} configurations: {worst:.2e}")


@pytest.mark.slow
def test_mode_shapes_are_mass_orthogonal_and_match_finite_elements():
    """Mass orthogonality to 1e-8 (quadrature good to ~1e-13), and the shapes
    agree with the FE eigenvectors at the FE nodes (MAC > 0.9999)."""
    for cable, atts, H in configurations(77, 30):
        shapes = mode_shapes(cable, atts, H, 8)
        M = modal_masses(shapes, cable, atts)
        np.testing.assert_allclose(M, np.eye(8), atol=1e-8, rtol=0)
        _, x, disp, _ = fe_modes(cable, atts, H, 8, n_elements=400, grading=2.0)
        phi = shapes(x)
        for k in range(8):
            if k + 1 < 8 and abs(shapes.frequencies[k + 1] / shapes.frequencies[k] - 1) < 1e-4:
                continue  # (nearly) repeated root: the basis of the pair is arbitrary
            if k > 0 and abs(shapes.frequencies[k] / shapes.frequencies[k - 1] - 1) < 1e-4:
                continue
            mac = (phi[:, k] @ disp[:, k]) ** 2 / ((phi[:, k] @ phi[:, k]) * (disp[:, k] @ disp[:, k]))
            assert mac > 0.9999


@pytest.mark.parametrize("EI,atts", [(1e4, []), (0.0, [Attachment("M", 10.0, 5.0)]),
                                      (0.0, [Attachment(f"M{i}", 5.0 * i, 8.0) for i in (1, 2, 3)])])
def test_mode_shapes_when_every_node_is_at_rest(EI, atts):
    """A bare clamped cable has no nodal unknowns; a string with a mass at
    midspan (or equal spacing) has modes whose nodes are all at rest. The
    shapes are still found, mass-orthogonal, and equal to sin(kπx/l) for
    the taut-string modes that the masses do not see."""
    cable = Cable(length=20.0, mass_per_length=10.0, EI=EI)
    shapes = mode_shapes(cable, atts, 1e5, 6)
    np.testing.assert_allclose(modal_masses(shapes, cable, atts), np.eye(6), atol=1e-8, rtol=0)
    if EI == 0:
        x = np.linspace(0, 20, 41)
        k = 2 if len(atts) == 1 else 4  # a mode with nodes at every attachment
        f_k = k / 40 * np.sqrt(1e5 / 10)
        i = int(np.argmin(np.abs(shapes.frequencies - f_k)))
        phi = shapes(x)[:, i]
        exact = np.sin(k * np.pi * x / 20) * np.sqrt(2 / (10 * 20))
        assert np.allclose(phi, exact, atol=1e-9) or np.allclose(phi, -exact, atol=1e-9)
