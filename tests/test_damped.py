"""The exact complex modes of a cable with dampers (issue 13): the undamped limit and Krenk's curve.

forward/damped.py evaluates the exact segment stiffnesses at a complex eigenvalue and follows each mode from
its undamped (Wittrick-Williams certified) root as the dashpots grow. Its comparison with the finite-element
reference on random cables, and with the asymptotes, is in test_damped_reference.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from stcs_ident.core.model import Attachment, Cable, Damper
from stcs_ident.forward.damped import complex_modes
from stcs_ident.forward.dsm import natural_frequencies


def test_without_a_damper_the_modes_are_the_undamped_solver_s():
    cable = Cable(40.0, 12.0, 5.0e4)
    atts = [Attachment("W", 11.0, 20.0, 3.0e3)]
    modes = complex_modes(cable, atts, 1.5e6, 6)
    np.testing.assert_allclose(modes.frequency, natural_frequencies(cable, atts, 1.5e6, 6, tension_model="none"),
                               rtol=1e-11)
    assert np.all(modes.damping == 0)


@pytest.mark.parametrize("eta", [0.3, 1.0, 3.0])
def test_the_exact_solver_follows_krenk_s_universal_curve(eta):
    L, m, H, xd = 100.0, 50.0, 2.0e6, 2.0
    c = eta * np.sqrt(H * m) / (np.pi * xd / L)
    modes = complex_modes(Cable(L, m, 0.0), [Damper("D", xd, coefficient=c)], H, 3)
    eta_n = eta * np.arange(1, 4)  # η grows with the mode number
    krenk = (xd / L) * eta_n / (1 + eta_n**2)
    np.testing.assert_allclose(modes.damping, krenk, rtol=0.04)  # the asymptote's O(x_d/l) error: 2-3 %
