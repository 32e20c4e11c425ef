"""Nearly coincident attachments and failing fits: the crash found on a fresh install, at its root.

A fit once put an unmodeled mass 2.5e-8 m from a recorded damper; the
segment between them lost its antisymmetric denominator to cancellation,
the dynamic stiffness went NaN and LAPACK failed inside a worker process,
aborting the whole diagnosis. These tests pin each layer of the fix.
"""

from __future__ import annotations

import numpy as np
import pytest

from stcs_ident.core.errors import ComputationError
from stcs_ident.core.model import Attachment, Cable, Campaign, Setup, Test
from stcs_ident.core.parameters import parse_parameters
from stcs_ident.diagnose import api, diagnose
from stcs_ident.diagnose.tables import ranking_table
from stcs_ident.forward import batch_frequencies
from stcs_ident.forward.assembly import negative_pivots
from stcs_ident.forward.elements import BeamSegment
from stcs_ident.identify.problem import MIN_GAP, Measurement, Problem
from stcs_ident.identify.uncertainty import covariance

EI, H, M = 2.0e6, 4.0e6, 60.0


@pytest.mark.parametrize("length", [1e-4, 1e-6, 1e-8, 1e-10, 1e-12])
def test_a_short_segment_tends_to_the_static_tensioned_beam(length):
    """Closed form for L → 0: 12EI/L³ + 6H/(5L), 4EI/L + 2HL/15, 6EI/L² + H/10. The next terms are of
    relative order H L²/EI and m ω² L⁴/EI (below 1e-8 at L = 1e-4 m); the old form lost every digit
    below L ≈ 1e-8 m."""
    seg = BeamSegment(np.array([length]), np.array([EI]), np.array([H]), np.array([M]), np.array([109.0]))
    K = seg.matrix()[0]
    assert np.all(np.isfinite(K))
    np.testing.assert_allclose(K[0, 0], 12 * EI / length**3 + 6 * H / (5 * length), rtol=1e-8)
    np.testing.assert_allclose(K[1, 1], 4 * EI / length + 2 * H * length / 15, rtol=1e-8)
    np.testing.assert_allclose(K[0, 1], 6 * EI / length**2 + H / 10, rtol=1e-8)


def test_a_matrix_that_is_not_finite_is_a_computation_error_not_a_lapack_failure():
    K = np.eye(3)[None].repeat(2, axis=0)
    K[1, 0, 0] = np.nan
    with pytest.raises(ComputationError, match="not finite"):
        negative_pivots(K)


def _problem(params="position,tension"):
    cable = Cable(length=120.0, mass_per_length=M, EI=EI, EA=3.0e9)
    setup = Setup("S", (Attachment("damper", 3.0, 50.0), Attachment("clamp", 60.0, 10.0)))
    test = Test("T1", "S", H)
    campaign = Campaign("c", cable, (setup,), (test,))
    f = batch_frequencies(cable, setup.attachments, H, 6)
    m = Measurement(test, np.arange(1, 7), f, 1e-4 * f, "given")
    return Problem(campaign, [m], parse_parameters(campaign, [test], params))


def test_trial_rows_keep_attachments_apart():
    problem = _problem()
    names = problem.names
    x = problem.start.copy()
    clamp = names.index("position_ratio[clamp]")
    too_close = x.copy()
    too_close[clamp] = (3.0 + 0.5 * MIN_GAP * 120.0) / 60.0
    far_enough = x.copy()
    far_enough[clamp] = (3.0 + 2.0 * MIN_GAP * 120.0) / 60.0
    F = problem.predict(np.array([too_close, far_enough]))
    assert np.all(np.isnan(F[0])) and np.all(np.isfinite(F[1]))


def test_the_jacobian_steps_away_from_a_position_the_model_cannot_take():
    problem = _problem()
    x = problem.start.copy()
    clamp = problem.names.index("position_ratio[clamp]")
    # Just outside the excluded gap: the step towards the damper is refused, the other side is not.
    x[clamp] = (3.0 + MIN_GAP * 120.0 * (1 + 1e-7)) / 60.0
    J = problem.jacobian(x)
    assert np.all(np.isfinite(J))
    reference = problem.jacobian(x + np.eye(x.size)[clamp] * 1e-3)
    np.testing.assert_allclose(J[:, clamp], reference[:, clamp], rtol=0.05)  # a smooth function, 1e-3 apart


def test_a_jacobian_column_that_cannot_be_evaluated_gets_infinite_variance():
    rng = np.random.default_rng(0)
    J = rng.normal(size=(8, 3))
    J[2, 1] = np.nan
    cov, _ = covariance(J)
    assert np.isinf(cov[1, 1]) and np.all(np.isfinite(cov[np.ix_([0, 2], [0, 2])]))
    np.testing.assert_allclose(cov[np.ix_([0, 2], [0, 2])], np.linalg.inv(J[:, [0, 2]].T @ J[:, [0, 2]]),
                               rtol=1e-10)


def test_a_hypothesis_whose_fit_fails_is_reported_and_the_diagnosis_goes_on(monkeypatch):
    cable = Cable(length=8.0, mass_per_length=30.0, EI=2.0e5)
    setup = Setup("S", (Attachment("clamp", 2.7, 15.0),))
    tests = (Test("T1", "S", 4.0e5), Test("T2", "S", 5.0e5))
    campaign = Campaign("c", cable, (setup,), tests)
    picked = {}
    for t in tests:
        f = batch_frequencies(cable, setup.attachments, 1.03 * t.tension, 6)
        picked[t.name] = Measurement(t, np.arange(1, 7), f, 5e-5 * f, "given")
    real = api.fit_hypothesis

    def flaky(campaign, measurements, effects, **kwargs):
        if "length" in effects:
            raise np.linalg.LinAlgError("SVD did not converge")
        return real(campaign, measurements, effects, **kwargs)

    monkeypatch.setattr(api, "fit_hypothesis", flaky)
    d = diagnose(campaign, picked=picked, effects="tension,bending_stiffness,length", workers=1)
    s = d.summary()
    failed = [h for h in s["hypotheses"] if h["failed"]]
    assert {tuple(h["effects"]) for h in failed} == {("length",), ("tension", "length"), ("bending_stiffness", "length"),
                                                     ("tension", "bending_stiffness", "length")}
    assert all(h["failed"] == "LinAlgError: SVD did not converge" and h["aicc"] is None for h in failed)
    assert s["hypotheses"][-1]["failed"]  # failures rank last
    assert s["cause"]["effects"] == ["tension"]
    table = ranking_table(d)
    assert table["failure"].str.startswith("LinAlgError").sum() == 4 and table.loc[table["failure"] != "", "chi2"].isna().all()


def test_every_cable_within_the_model_s_bands_solves():
    """Random cables across the model's value bands (log-uniform, half of them at the bands' corners): every
    solve ends with positive, finite, increasing frequencies. Together with the bands' refusal of what lies
    outside (tests/test_refusals.py), no campaign value reaches the solver that it cannot carry."""
    from stcs_ident.core.model import BANDS, Boundary

    rng = np.random.default_rng(11)

    def pick(quantity, corner):
        low, high, _ = BANDS[quantity]
        return (low, high)[corner] if corner is not None else 10 ** rng.uniform(np.log10(low), np.log10(high))

    for i in range(400):
        corner = [int(c) for c in rng.integers(0, 2, 8)] if i % 2 else [None] * 8
        length = pick("length", corner[0])
        cable = Cable(length, pick("mass_per_length", corner[1]), 0.0 if i % 5 == 0 else pick("EI", corner[2]),
                      EA=None if i % 3 == 0 else pick("EA", corner[3]),
                      gravity=0.0 if i % 7 == 0 else pick("gravity", corner[4]), inclination=0.3,
                      boundary_a=Boundary(float(rng.choice([0.0, np.inf, 1e-300, 1e300, 1.0]))))
        attachments = (Attachment("W", 0.3 * length, pick("mass", corner[6]), pick("stiffness", corner[7])),)
        f = np.asarray(batch_frequencies(cable, attachments if i % 4 else (), pick("tension", corner[5]), 4)).ravel()
        assert np.all(np.isfinite(f)) and np.all(f > 0) and np.all(np.diff(f) >= 0), (i, cable, f)
