"""Coverage of the stated 1σ of the picked damping ratios, with and without a damper (a fast subset).

The records and the scoring are those of ``benchmarks/calibrate_damping.py``
(imported from the benchmarks package: one recipe for the benchmark and the test), on a
held-out seed: the spectra code was examined and mended on seed 1, the
benchmark's report is seed 2, this test is seed 3. The truth is the modal ζ
given to the simulator or, with a damper, the complex mode's −Re(s)/|s|.

The (record, mode) pairs are pooled over the cases below (about 64): the
fraction with |error| ≤ 1σ must be 68.3 % within three binomial standard
errors (± 17 % here: a false alarm once in 370 runs when the 1σ is honest),
and at most 3 pairs may lie beyond 3σ (0.3 % if Gaussian, accepted up to
1.5 % as for the frequencies: with 64 pairs one expects 1.0, and four or
more once in 60 runs). Per kind of record (blows, wind only) the median
|z| must lie within 0.674 ± 3 of its sampling spreads.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmarks import calibrate_damping as harness

# a statistical set; with -n, on one worker: the records (the module fixture) are made once
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("damping_coverage")]

HELD_OUT_SEED = 3

# (group, case, records): each scores 8 modes. The dampers' records span ζ 0.3–1.2 %, the bare ones 0.2–5 %.
CASES = [
    ("impulse", "stay+damper", 2),  # blows on the 200 m stay with its damper
    ("impulse_wind", "stay+damper", 2),  # the same under light wind
    ("ambient", "stay+damper", 2),  # wind only
    ("impulse", "short", 1),  # a 60 m cable at 128 Hz without a damper, its modal ζ up to 5 %
    ("ambient", "short", 1),
]


@pytest.fixture(scope="module")
def pairs():
    out = []
    for group, case, n in CASES:
        for i in range(n):
            result = harness.run_case(harness.build_case(group, case, HELD_OUT_SEED, i))
            assert "error" not in result, result
            out += [(group, true, estimate, sigma) for _, true, estimate, sigma, *_ in result["pairs"]]
    return out


def _z(pairs) -> np.ndarray:
    return np.abs([(estimate - true) / sigma for _, true, estimate, sigma in pairs])


def test_one_sigma_of_the_damping_covers_68_percent(pairs):
    z = _z(pairs)
    assert z.size >= 56  # 8 records × 8 modes, a few may be missed
    within = float(np.mean(z <= 1))
    se = math.sqrt(0.683 * 0.317 / z.size)
    assert abs(within - 0.683) <= 3 * se, (within, np.median(z))
    assert np.sum(z > 3) <= 3, np.sort(z)[-4:]


@pytest.mark.parametrize("kind", ["blows", "wind"])
def test_median_damping_error_is_two_thirds_of_a_sigma(pairs, kind):
    """An honest 1σ gives median |z| = 0.674; its sampling spread is 1 / (2 f(0.674) √n) with f the
    half-normal density at its median (0.636): 0.12 for the 40 pairs of blows (0.674 ± 0.37), 0.16 for
    the 23 of wind (± 0.49). Measured on seed 3: 0.59 and 0.59."""
    z = _z([p for p in pairs if (p[0] == "ambient") == (kind == "wind")])
    spread = 1 / (2 * 0.636 * math.sqrt(z.size))
    assert abs(np.median(z) - 0.674) <= 3 * spread, (kind, np.median(z), z.size)
