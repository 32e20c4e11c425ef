"""Coverage of the stated 1σ of the picked frequencies under field-like conditions (a fast subset).

The records and the scoring are those of ``benchmarks/calibrate_spectra.py``
(imported from the benchmarks package: one recipe for the benchmark and the test), on a
held-out seed: no constant of the spectra code was tuned on seed 3 (tuning
used seed 2). Per condition group the fraction of (record, mode) pairs
with |error| ≤ 1σ must be 68 % within three binomial standard errors, and
few errors may exceed 3σ; no mains-hum line may be reported as a mode.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmarks import calibrate_spectra as harness

pytestmark = pytest.mark.xdist_group("spectra_coverage")  # with -n, on one worker: the records are made once

HELD_OUT_SEED = 3

# (group, cable, records): the cases. Each hanger record scores 8 modes, each stay record 12.
CASES = [
    ("light_wind", "hanger", 5),  # blows under light wind: |z| reached 6 on modes 1–2, median |z| 0.08 before
    ("coloured_wind", "hanger", 5),  # the wind goes on under the blows, coloured
    ("coloured_wind", "stay", 4),  # the stay's σ was 3–5 times too large
    ("hum50", "hanger", 5),  # 50 Hz hum and harmonics among the hanger's modes (48.8, 95.6, 151 Hz)
    ("hum60", "hanger", 5),  # 60 Hz hum, 120 Hz beside mode 7 (120.4 Hz)
]


def _binomial_se(p: float, n: int) -> float:
    return math.sqrt(p * (1 - p) / n)


@pytest.fixture(scope="module")
def results():
    out = {}
    for group, cable, n in CASES:  # in order, once per test run (the tests below share the records)
        out[(group, cable)] = [harness.run_case(harness.build_case(group, cable, HELD_OUT_SEED, i)) for i in range(n)]
    return out


@pytest.mark.slow
@pytest.mark.parametrize("group,cable", [(g, c) for g, c, _ in CASES])
def test_one_sigma_covers_68_percent(results, group, cable):
    rs = results[(group, cable)]
    z = np.abs([(fe - ft) / s for r in rs for _, ft, fe, s in r["pairs"]])
    assert not any("error" in r for r in rs)
    assert z.size >= 40
    within = float(np.mean(z <= 1))
    # 68.3 % ± 3 binomial standard errors (about ± 22 % with 40 pairs): a false alarm once in 370 runs when
    # the 1σ is honest; before the fix light_wind / hanger gave 80 % with median |z| 0.08.
    se = _binomial_se(0.683, z.size)
    assert abs(within - 0.683) <= 3 * se, (group, cable, within, np.median(z))
    # Median |z| of an honest 1σ is 0.674; its sampling spread with 40 pairs is 1 / (2 f(0.674) √40) = 0.12
    # (f the half-normal density at its median): 0.35–1.0 is ± 2.6 of those.
    assert 0.35 <= np.median(z) <= 1.0, (group, cable, np.median(z))
    # Beyond 3σ: 0.3 % if Gaussian, accepted up to 1.5 % (the target ≥ 98.5 % within 3σ); with 40
    # pairs at 1.5 % one expects 0.6, and three or more once in 50 runs, so at most two.
    assert np.sum(z > 3) <= 2, (group, cable, np.sort(z)[-3:])


@pytest.mark.slow
@pytest.mark.parametrize("group", ["hum50", "hum60"])
def test_mains_hum_is_never_reported(results, group):
    reported = [h for r in results[(group, "hanger")] for h in r["hum"]]
    assert reported == []
