"""Cross-validated prediction errors of a fitted hypothesis.

Leave-one-mode-out: for each mode number (of each plane), the frequencies of that mode are
removed from every test, the hypothesis is refitted (started from the
full-data estimate) and the removed frequencies are predicted. A parameter
with no data left in a fold (the tension of a test whose only mode was
removed) keeps its nominal value: the prediction is then an honest
prediction of an unseen test.

Leave-one-test-out: each test is predicted by the hypothesis fitted to the
other tests (the honest measure of the gain on real data).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..identify.lsq import local_fit
from ..identify.problem import Measurement
from .fitting import TOL, HypothesisFit, hypothesis_problem, quietly, rms_percent

__all__ = ["cross_validate", "cross_validate_tests"]


def cross_validate(fit: HypothesisFit, measurements: Sequence[Measurement], tension_model: str,
                   max_nfev: int = 100) -> float | None:
    """Leave-one-mode-out prediction error of a fitted hypothesis, % (None if a fold cannot be fitted)."""
    if fit.result is None:
        return fit.rms_error
    hyp = fit.hypothesis
    full = hypothesis_problem(hyp, measurements, tension_model)
    x_full = fit.result.estimate
    nf = full.n_frequencies  # the frequencies (the damping ratios, when data, follow them)
    measured = full.measured[:nf]
    modes = np.concatenate([m.modes for m in measurements])
    planes = np.concatenate([m.planes for m in measurements])
    predicted = np.full(measured.size, np.nan)
    for plane, mode in sorted(set(zip(planes.tolist(), modes.tolist()))):  # a mode of one plane at a time
        kept = []
        for m in measurements:
            keep = (m.modes != mode) | (m.planes != plane)
            if keep.any():
                kept.append(Measurement(m.test, m.modes[keep], m.frequencies[keep], m.uncertainty[keep], m.source,
                                        planes=m.planes[keep]))
        used = [j for j, p in enumerate(hyp.parameters) if any(p.applies_to(m.test) for m in kept)]
        x = full.start.copy()
        n_kept = sum(m.modes.size for m in kept)
        if not used or n_kept <= len(used):
            return None
        sub = hypothesis_problem(hyp, kept, tension_model, [hyp.parameters[j] for j in used])
        x_sub, _ = quietly(lambda sub=sub, used=used: local_fit(sub, x_full[used], max_nfev, TOL), [])
        x[used] = x_sub
        left = (modes == mode) & (planes == plane)
        predicted[left] = full.predict(x)[:nf][left]
    if not np.all(np.isfinite(predicted)):
        return None
    return rms_percent(predicted, measured)


def cross_validate_tests(fit: HypothesisFit, measurements: Sequence[Measurement], tension_model: str,
                         max_nfev: int = 100) -> float | None:
    """Leave-one-test-out prediction error, %: each test predicted by the hypothesis fitted to the other
    tests (None with fewer than two tests, or when a fold cannot be fitted).

    A parameter that belongs to the left-out test alone (its tension ratio) keeps its nominal value: the
    prediction is that of an unseen test, as a user would make it, so a stated tension's own error counts.
    """
    if len(measurements) < 2:
        return None
    if fit.result is None:
        return fit.rms_error
    hyp = fit.hypothesis
    full = hypothesis_problem(hyp, measurements, tension_model)
    x_full = fit.result.estimate
    predicted, k = [], 0
    for i, left in enumerate(measurements):
        kept = [m for j, m in enumerate(measurements) if j != i]
        used = [j for j, p in enumerate(hyp.parameters) if any(p.applies_to(m.test) for m in kept)]
        x = full.start.copy()
        if used:
            if sum(m.modes.size for m in kept) <= len(used):
                return None
            sub = hypothesis_problem(hyp, kept, tension_model, [hyp.parameters[j] for j in used])
            x_sub, _ = quietly(lambda sub=sub, used=used: local_fit(sub, x_full[used], max_nfev, TOL), [])
            x[used] = x_sub
        predicted.append(full.predict(x)[k:k + left.modes.size])
        k += left.modes.size
    predicted = np.concatenate(predicted)
    if not np.all(np.isfinite(predicted)):
        return None
    return rms_percent(predicted, full.measured[:full.n_frequencies])
