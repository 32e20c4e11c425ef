"""The profile of a named cause's position: where along the span could the unmodeled attachment be?

For one unmodeled mass or support of the chosen hypothesis, its position is
held at each point of a grid over the whole span and every other parameter
of that hypothesis (its amplitude, the other attachment's position and
amplitude, tensions, EI…) is refitted; the curve is χ² (the hypothesis's own,
:attr:`~.fitting.HypothesisFit.chi2`) against the held position. The
estimate is one point of the curve by construction (its χ² is the fit's).
On a configuration symmetric about midspan (:func:`~.fitting.mirror_symmetric`)
the hypothesis at x with its other attachments at y is the hypothesis at
l − x with them at l − y, the same frequencies exactly: the profile is
symmetric, and each point takes the lower of the two refits (x, and l − x
mirrored), so both minima appear whichever basin a walk stayed in.

Each point starts from its neighbour's refitted values (the scan walks out
from the estimate in both directions) and from the estimate's, the better
kept: a continuation that follows the valley without jumping to a distant
basin.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import effects as registry
from ..identify.lsq import local_fit
from .fitting import TOL, hypothesis_problem, profile_points, starts_from
from .hypotheses import build, free_positions, unmodeled_name

#: Points of the grid over the span, at least (the estimate and, when symmetric, its mirror besides).
MIN_POINTS = 25
#: Function evaluations of one point's local fit: it starts next to its solution (the neighbour's).
POINT_NFEV = 60


@dataclass(frozen=True)
class PositionProfile:
    """χ² of the named cause with one unmodeled attachment held at each position.

    Attributes
    ----------
    effect : str
        The unmodeled effect whose position is held.
    positions : ndarray
        Held positions, m from end A, ascending (the estimate among them).
    chi2 : ndarray
        The hypothesis's χ² at each position, every other parameter refitted.
    estimate : float
        The named cause's position of the attachment, m.
    estimate_chi2 : float
        The named cause's χ²: the curve's value at ``estimate``.
    """

    effect: str
    positions: np.ndarray
    chi2: np.ndarray
    estimate: float
    estimate_chi2: float


def _chi2(problem, x) -> float:
    """The hypothesis's χ² at variables ``x``: Σ ((predicted − measured)/σ)², as :mod:`.fitting` counts it."""
    predicted = problem.predict(x)
    return float(np.sum(((predicted - problem.measured) / problem.sigma) ** 2))


def cause_profile(diagnosis, effect: str, points: int | None = None) -> PositionProfile:
    """The profile of the position of ``effect`` (an unmodeled attachment of the chosen hypothesis).

    ``points``: grid points over the span (default :data:`MIN_POINTS`, or two per half-wave of the highest
    measured mode when that is finer). Raises ValueError when ``effect`` is not an unmodeled attachment of
    the chosen hypothesis.
    """
    d = diagnosis
    fit = d.corrected
    if effect not in fit.effects or not registry.get(effect).unmodeled:
        raise ValueError(f"{effect!r} is not an unmodeled attachment of the chosen hypothesis {fit.effects}")
    measurements = d.measurements
    tests = [m.test for m in measurements]
    campaign = d.campaign
    tension_model = d.settings.tension_model
    estimate = fit.values()
    member = unmodeled_name(effect)
    x_hat = estimate[("position", member)]
    positions = {e: estimate[("position", unmodeled_name(e))] for e in fit.effects
                 if unmodeled_name(e) and ("position", unmodeled_name(e)) in estimate}
    n = points or max(MIN_POINTS, profile_points(measurements))
    length = campaign.cable.length
    grid = free_positions(campaign, tests, n)
    while grid.size < n:  # points next to recorded attachments are left out: ask for more
        grid = free_positions(campaign, tests, n + (n - grid.size))
    if d.symmetric:
        grid = np.append(grid, length - x_hat)
    grid = np.unique(grid[np.abs(grid - x_hat) > 1e-9 * length])
    chi2 = np.full(grid.size, np.nan)
    # Walk out from the estimate: right of it ascending, left of it descending, each from its neighbour.
    right = np.flatnonzero(grid > x_hat)
    left = np.flatnonzero(grid < x_hat)[::-1]
    for side in (right, left):
        previous = estimate
        for i in side:
            hyp = build(campaign, tests, fit.effects, {**positions, effect: float(grid[i])}, fixed=(effect,))
            problem = hypothesis_problem(hyp, measurements, tension_model)
            best = None
            for x0 in starts_from(problem, [previous, estimate], nominal=False):
                xb, _ = local_fit(problem, x0, POINT_NFEV, TOL)
                c = _chi2(problem, xb)
                if best is None or c < best[1]:
                    best = (xb, c)
            chi2[i] = best[1]
            previous = {(p.kind, p.member): float(p.to_value(v)) for p, v in zip(problem.parameters, best[0])}
    positions_all, chi2_all = np.append(grid, x_hat), np.append(chi2, fit.chi2)
    if d.symmetric:
        gap = np.abs(positions_all[None, :] - (length - positions_all[:, None]))
        nearest = np.argmin(gap, axis=1)
        exact = gap[np.arange(gap.shape[0]), nearest] < 1e-9 * length  # the grid is symmetric: every mirror is in it
        chi2_all = np.where(exact, np.minimum(chi2_all, chi2_all[nearest]), chi2_all)
        # The estimate's point and its mirror image's: the fit's χ² (the mirrored estimate has the same exactly).
        chi2_all[-1] = fit.chi2
        chi2_all[np.abs(positions_all - (length - x_hat)) < 1e-9 * length] = fit.chi2
    order = np.argsort(positions_all)
    return PositionProfile(effect, positions_all[order], chi2_all[order], float(x_hat), float(fit.chi2))


def cause_profiles(diagnosis, points: int | None = None) -> dict[str, PositionProfile]:
    """:func:`cause_profile` of every unmodeled attachment of the named cause, by effect (empty: none)."""
    return {e: cause_profile(diagnosis, e, points) for e in diagnosis.selection.effects
            if registry.get(e).unmodeled and e in diagnosis.corrected.effects}
