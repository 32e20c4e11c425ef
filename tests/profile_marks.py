"""The check that a profile figure's marks agree with its curves (tests of the report and of docs/api.md)."""

from __future__ import annotations

import numpy as np


def assert_marks_on_curves(d, drawn):
    """The named cause's stars lie on its profiles (the estimate and, when symmetric, its mirror image), each
    profile of the cause's own hypothesis over the span with at least 25 positions, and no point of a curve
    below the star: the estimate is the minimum along its profile (a lower point would be a better fit the
    diagnosis missed)."""
    length = d.campaign.cable.length
    for effect, panel in drawn["panels"].items():
        x, y = panel["profile"].get_xdata(), panel["profile"].get_ydata()
        assert len(x) >= 25 and x.min() < 0.1 * length and x.max() > 0.9 * length  # the whole span
        stars_x, stars_y = panel["estimate"].get_xdata(), panel["estimate"].get_ydata()
        assert len(stars_x) == (2 if d.symmetric else 1)
        for xs, ys in zip(stars_x, stars_y):
            i = int(np.argmin(np.abs(x - xs)))
            assert abs(x[i] - xs) < 1e-9 * length and y[i] == ys == d.corrected.chi2, effect
        assert y.min() >= d.corrected.chi2 * (1 - 1e-9), effect  # 1e-9: the local fits' tolerance is 1e-10
        if d.symmetric:  # both minima of the symmetric setup: the curve is symmetric
            gap = np.abs(x[None, :] - (length - x[:, None]))
            mirror = np.argmin(gap, axis=1)
            assert np.all(gap[np.arange(x.size), mirror] < 1e-9 * length)  # each position's mirror image scanned
            np.testing.assert_array_equal(y, y[mirror])
