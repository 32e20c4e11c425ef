"""The events' disagreement as a variance of the record's mean frequency (spectra.wander)."""

import numpy as np
import pytest

from stcs_ident.spectra.options import FitOptions
from stcs_ident.spectra.wander import (
    between_events_addition,
    common_wander,
    with_common_wander,
)

FREQUENCIES = np.arange(1, 11) * 1.1  # Hz, ten modes of a taut string


def _draw(rng, n_events, tau_rel, sigma_rel):
    """Per mode (f, event frequencies, event variances): a common relative offset per event plus noise."""
    offsets = rng.normal(0.0, tau_rel, n_events) if tau_rel else np.zeros(n_events)
    modes = []
    for f in FREQUENCIES:
        v = (sigma_rel * f) ** 2 * rng.uniform(0.5, 2.0, n_events)
        fe = f * (1 + offsets) + rng.normal(0.0, np.sqrt(v))
        modes.append((f, fe, v))
    return modes, offsets


def _coverage(seed, tau_rel, pooled):
    """|error| <= 1σ and <= 3σ fractions of the modes' mean frequency, the truth being f (offsets average out)."""
    rng = np.random.default_rng(seed)
    z = []
    for _ in range(400):
        modes, _ = _draw(rng, 3, tau_rel, 1e-5)
        tau2 = common_wander(modes) if pooled else 0.0
        for f, fe, v in modes:
            w = 1 / v
            mean = np.sum(w * fe) / np.sum(w)
            var = 1 / np.sum(w)
            var += between_events_addition(fe, v, var)
            std = with_common_wander(np.sqrt(var), f, v, tau2)
            # The record's mean tension is the truth; the three events sample it at random instants.
            z.append((mean - f) / std)
    z = np.abs(np.array(z))
    return np.mean(z <= 1), np.mean(z <= 3)


def test_agreeing_events_add_nothing_most_of_the_time():
    rng = np.random.default_rng(1)
    fired = np.mean([common_wander(_draw(rng, 3, 0.0, 1e-5)[0]) > 0 for _ in range(400)])
    # The test's level, with the binomial scatter of 400 draws (3σ = 0.033).
    assert fired <= FitOptions().heterogeneity_level + 0.035


def test_common_wander_restores_coverage_per_mode_tests_miss():
    # A wander as large as one event's noise: each mode alone rarely rejects agreement, the ten modes together do.
    alone = _coverage(2, 1.5e-5, pooled=False)
    pooled = _coverage(2, 1.5e-5, pooled=True)
    assert alone[0] < 0.55 and alone[1] < 0.95  # too small a 1σ without pooling (the failure this guards against)
    # Near 68 % / 99.7 %, a little short: τ² from three events is itself uncertain (2 degrees of freedom), and the
    # random-effects mean does not carry that uncertainty (measured 62 % / 97.6 %).
    assert 0.58 <= pooled[0] <= 0.80 and pooled[1] >= 0.96


def test_single_event_and_missing_fits():
    assert common_wander([(1.0, np.array([1.0]), np.array([1e-8]))] * 3) == 0.0
    assert with_common_wander(1e-4, 1.0, np.array([1e-8]), 1e-8) == 1e-4  # one event: nothing to pool
    fe = np.array([1.0, np.nan, 1.001])
    v = np.array([1e-8, 1e-8, 1e-8])
    assert between_events_addition(fe, v, 5e-9) > 0  # the NaN event is left out, the two others disagree by 7σ


@pytest.mark.parametrize("tau_rel", [3e-5, 1e-4])
def test_large_wander_is_measured(tau_rel):
    rng = np.random.default_rng(3)
    est = [np.sqrt(common_wander(_draw(rng, 3, tau_rel, 1e-5)[0])) for _ in range(300)]
    # DerSimonian–Laird on 3 events: unbiased in τ², so the median of τ sits near, below, the truth.
    assert 0.4 * tau_rel < np.median(est) < 1.3 * tau_rel
