"""The finite-element reference of cables with dampers (complex modes): against the undamped model and Krenk.

Krenk (2000, J. Appl. Mech. 67, 772-776): a taut string with a viscous damper of coefficient c at x_d near an
end, x_d/l small: ζ_n ≈ (x_d/l) η/(1 + η²), η = (c/√(H m)) π n x_d/l, the "universal curve" with its maximum
x_d/(2l) at η = 1. The asymptote differs from the exact model by O(x_d/l): 2-4 % of ζ at x_d/l = 0.02.
"""

from __future__ import annotations

import numpy as np
import pytest

from stcs_ident.errors import ModelError
from stcs_ident.forward.fem import fe_frequencies
from stcs_ident.forward.fem_damped import fe_complex_modes
from stcs_ident.model import Attachment, Cable, Damper

L, M, H = 100.0, 50.0, 2.0e6
XD = 0.02 * L


@pytest.mark.parametrize("n", [1, 2, 3])
@pytest.mark.parametrize("eta", [0.3, 1.0, 3.0])
def test_a_string_with_a_damper_near_an_end_follows_krenk_s_universal_curve(n, eta):
    c = eta * np.sqrt(H * M) / (np.pi * n * XD / L)
    modes = fe_complex_modes(Cable(L, M, 0.0), [], [Damper("D", XD, coefficient=c)], H, 4, n_elements=80)
    krenk = (XD / L) * eta / (1 + eta**2)
    assert modes.damping[n - 1] == pytest.approx(krenk, rel=0.04)  # O(x_d/l) = 2 % of the asymptote, and more
    assert modes.frequency[n - 1] == pytest.approx(n * np.sqrt(H / M) / (2 * L), rel=0.03)  # shifted by < x_d/l


def test_the_largest_damping_is_half_the_damper_s_relative_position():
    etas = np.geomspace(0.2, 5.0, 25)
    zeta = [fe_complex_modes(Cable(L, M, 0.0), [], [Damper("D", XD, coefficient=e * np.sqrt(H * M) / (np.pi * XD / L))], H, 1,
                             n_elements=60).damping[0] for e in etas]
    best = int(np.argmax(zeta))
    assert 0.7 <= etas[best] <= 1.4
    assert max(zeta) == pytest.approx(XD / (2 * L), rel=0.05)


def test_a_vanishing_damper_leaves_the_undamped_modes():
    """A dashpot of 1e-6 N s/m with its parallel spring and mass: the undamped model with an attachment of
    that spring and mass, and no damping. To 1e-7: the companion form, solved by QZ as a non-symmetric
    problem of twice the size, keeps about 8 digits where the symmetric undamped solver keeps 12."""
    cable = Cable(30.0, 12.0, 5.0e4, EA=3.0e9, inclination=0.4)
    damper = Damper("D", 1.2, coefficient=1e-6, stiffness=2.0e3, mass=4.0)
    modes = fe_complex_modes(cable, [Attachment("W", 11.0, 20.0)], [damper], 1.5e6, 5, n_elements=120)
    undamped = fe_frequencies(cable, [Attachment("W", 11.0, 20.0), Attachment("D", 1.2, 4.0, 2.0e3)], 1.5e6, 5,
                              n_elements=120)
    np.testing.assert_allclose(modes.frequency, undamped, rtol=1e-7)
    assert np.all(np.abs(modes.damping) < 1e-9)


def test_a_damper_outside_the_span_is_refused():
    with pytest.raises(ModelError, match="damper"):
        fe_complex_modes(Cable(L, M, 0.0), [], [Damper("D", 120.0, coefficient=1.0)], H, 2)
