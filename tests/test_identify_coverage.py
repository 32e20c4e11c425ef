"""Statistical check of the least-squares uncertainties: over 200 noisy data sets
the 1σ intervals cover the truth 68 ± 7 % of the time, and the normalised errors
are standard normal (Kolmogorov–Smirnov)."""

import numpy as np
import pytest
from scipy import stats

from stcs_ident.identify import identify
from tests.test_identify import synthetic

TRIALS = 200
NOISE = 0.01  # Hz, one standard deviation, equal to the stated uncertainty
# 68.3 % expected; the binomial standard deviation over 200 trials is 3.3 %, and the
# acceptance band 61-75 % is about ±2σ of it.
COVERAGE_BAND = (0.61, 0.75)
KS_P_MIN = 0.01

# (params, setup, tension ratio, EI ratio, positions (m), truth)
CASES = {
    "tension+EI": ("tension,EI", "bare", 1.02, 0.9, None, [1.02, 0.9]),
    "tension+EI+position": ("tension,EI,position", "one", 1.02, 0.9, [7.3], [1.02, 0.9, 7.3 / 7.0]),
}


def _normalised_error(trial):
    """(estimate − truth) / 1σ of one noisy data set."""
    campaign, picked, params, truth = trial
    # One start at the nominal values: the noise is far too small to move the
    # estimate to the mirror image, and the 200 scans would take a minute.
    # The values held fixed (length, the attachment's mass) are exact in these data sets: their tolerances stay
    # out (tests/test_tolerance_coverage.py checks the intervals with them, on data whose values held fixed are off).
    result = identify(campaign, ["T1"], params, picked=picked, starts=[np.ones(len(truth))], tolerances=False)
    return (result.estimate - truth) / result.uncertainty


@pytest.mark.slow
@pytest.mark.parametrize("case", list(CASES))
def test_one_sigma_intervals_cover_the_truth(case):
    params, setup, h, ei, pos, truth = CASES[case]
    truth = np.array(truth)
    rng = np.random.default_rng(20240604)
    trials = []
    for _ in range(TRIALS):  # the data sets drawn here, in turn, from one stream
        campaign, picked = synthetic(setup, h, ei, pos, n_modes=6, noise=NOISE, rng=rng)
        m = picked["T1"]
        picked["T1"] = type(m)(m.test, m.modes, m.frequencies, NOISE, "given")
        trials.append((campaign, picked, params, truth))
    # One test over all data sets, in order: the coverage and the KS test are statistics of them all.
    z = np.array([_normalised_error(trial) for trial in trials])
    coverage = np.mean(np.abs(z) <= 1, axis=0)
    print(f"{case}: coverage of the 1-sigma intervals {np.round(100 * coverage, 1)} %")
    for name, c in zip(params.split(","), coverage):
        assert COVERAGE_BAND[0] <= c <= COVERAGE_BAND[1], f"{name}: {c:.1%}"
    for k in range(z.shape[1]):
        assert stats.kstest(z[:, k], "norm").pvalue > KS_P_MIN
