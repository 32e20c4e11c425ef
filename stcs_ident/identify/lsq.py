"""Weighted least squares of any set of parameters over several tests at once.

Minimises Σ ((f_model − f_measured)/σ)² over the free variables within
their bounds (SciPy's trust-region reflective method, Jacobian by central
differences in one batch of the forward solver). Attachment
positions make the problem multimodal (a mass and its mirror image give the
same frequencies on a symmetric cable; two equal masses can trade places),
so with position parameters the fit starts from the best points of a scan
over the span as well as from the nominal values, and reports the other
minima that fit as well. The covariance comes from the Jacobian at the
estimate (:mod:`.uncertainty`).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from scipy.optimize import least_squares

from ..core.notes import Note, point
from ..core.settings import Settings
from .bounds import bound_failure
from .nuisance import propagate, tolerance_note
from .problem import Problem
from .result import IdentificationResult, TestFit
from .uncertainty import correlation, covariance, covariance_scale, identifiability, warn_identifiability

#: Candidate positions of the multi-start scan, as fractions of the length.
SCAN_FRACTIONS = np.linspace(0.025, 0.975, 20)
#: Two minima closer than this (in variable units) are one.
SAME_POINT = 1e-5
#: χ² difference (relative) below which two minima explain the data equally well.
SAME_CHI2 = 1e-6



def fit_lsq(problem: Problem, *, starts=None, n_starts: int = 6, scale_rule: str = "auto",
            max_nfev: int = 200, seed: int = 0, tol: float = 1e-14,
            settings: Settings | None = None) -> IdentificationResult:
    """Least-squares estimate of the problem's parameters with their covariance.

    Parameters
    ----------
    problem : Problem
    starts : array of shape (k, p), optional
        Starting points (variable units); default the nominal values, plus
        the ``n_starts`` best points of a scan over the span when there are
        position parameters.
    n_starts : int
        Extra starts from the scan (position parameters only).
    scale_rule : {"auto", "birge", "never"}
        When to scale the covariance by the reduced χ²
        (:func:`~stcs_ident.identify.uncertainty.covariance_scale`).
    max_nfev : int
        Function evaluations per local fit.
    seed : int
        Seed of the scan's random candidates (three or more positions).
    tol : float
        ``xtol``, ``ftol`` and ``gtol`` of each local fit (the diagnosis,
        which fits many hypotheses, uses 1e-10).
    settings : Settings, optional
        Recorded in the result (default: the problem's tension model and
        ``scale_rule``); its ``scale_rule`` then replaces ``scale_rule``.

    Returns
    -------
    IdentificationResult
        ``method="lsq"``; ``uncertainty`` is one standard deviation.

    Warns
    -----
    IdentifiabilityWarning
        Naming the parameters the data cannot determine.
    """
    starts = _starts(problem, n_starts, seed) if starts is None else np.atleast_2d(np.asarray(starts, float))
    starts = np.clip(starts, problem.lower, problem.upper)
    solutions = [local_fit(problem, x0, max_nfev, tol) for x0 in starts]
    best = min(solutions, key=lambda s: s[1])[0]
    solutions += [local_fit(problem, m, max_nfev, tol) for m in mirror_images(problem, best)]
    x, chi2, alternatives, notes = _choose(problem, solutions)
    return finish(problem, x, chi2, "lsq", scale_rule=scale_rule, alternatives=alternatives, notes=notes,
                  settings=settings)


def finish(problem: Problem, x: np.ndarray, chi2: float, method: str, *, scale_rule: str = "auto",
           alternatives=(), notes=(), uncertainty=None, sweep=None, scale=None,
           settings: Settings | None = None) -> IdentificationResult:
    """Covariance, identifiability and the before/after fits at the estimate ``x``.

    ``uncertainty`` replaces the standard deviations and ``scale`` the
    covariance scale (the contour method passes its region's extent and the
    scale it used); the covariance is still computed. ``settings`` is
    recorded in the result (default: the problem's tension model and
    ``scale_rule``; given, its ``scale_rule`` is the one applied).
    """
    if settings is None:
        settings = Settings(tension_model=problem.tension_model, scale_rule=scale_rule)
    scale_rule = settings.scale_rule
    n, p = problem.n_data, len(problem.parameters)
    dof = n - p
    notes = list(notes)
    J = problem.jacobian(x)
    typical = problem.typical(x)
    # The measurements' share (JᵀJ)⁻¹, scaled by the reduced χ² when the misfit is significant, plus the share
    # of the tolerances of what is held fixed (not scaled: a stated claim of its own; :mod:`.nuisance`).
    base, base_corr = covariance(J, 1.0, typical)
    tested_chi2, added = chi2, np.zeros_like(base)
    if problem.nuisance:
        total, tested_chi2 = propagate(J, problem.nuisance_jacobian(x), problem.residuals(x), base)
        with np.errstate(invalid="ignore"):
            added = np.where(np.isfinite(total - base), total - base, 0.0)
    if scale is None:
        scale, scale_note = covariance_scale(tested_chi2, dof, scale_rule, tolerances=bool(problem.nuisance))
        if scale_note:
            notes.insert(0, scale_note)
    cov = base * scale + added
    corr = correlation(cov) if problem.nuisance else base_corr
    sigma = np.sqrt(np.diag(cov))
    if problem.nuisance:
        with np.errstate(invalid="ignore", divide="ignore"):
            share = np.where(np.isfinite(sigma) & (sigma > 0), np.diag(added) / sigma**2, 0.0)
        notes.append(tolerance_note(problem.nuisance, float(np.max(share, initial=0.0))))
    if uncertainty is not None:  # the contour's region extent: the tolerances' share added in quadrature
        uncertainty = np.sqrt(np.asarray(uncertainty, float) ** 2 + np.maximum(np.diag(added), 0.0))
    failure, at_limit = bound_failure(problem.parameters, x, problem.lower, problem.upper)
    if at_limit:
        notes.append(Note.make("at_bound", "at a physical limit (the standard deviation there is only "
                               "indicative): {parameters}", parameters=at_limit))
    # What the data can tell apart: from the measurements' share alone (a common error of a value held fixed,
    # the length, say, correlates every tension without making them any less determined by the data).
    notes += warn_identifiability(identifiability(J, problem.names, base_corr, np.sqrt(np.diag(base) * scale),
                                                  problem.lower, problem.upper, typical),
                                  stacklevel=4)
    before = problem.predict(problem.start)
    after = problem.predict(x)
    damping = problem.damping_columns(before, after)
    tests, k = [], 0
    for i, m in enumerate(problem.measurements):
        sl = slice(k, k + m.modes.size)
        k += m.modes.size
        keys = list(zip(m.test.planes or ("in",) * len(m.test.modes or ()), m.test.modes or ()))
        reference = {label: np.array([dict(zip(keys, values)).get((str(p), int(k)), np.nan)
                                      for p, k in zip(m.planes, m.modes)])
                     for label, values in m.test.reference}
        tests.append(TestFit(m.name, m.test.setup, tuple(int(v) for v in m.modes), m.frequencies, m.uncertainty,
                             m.source, before[sl], after[sl], reference, damping[i], tuple(str(p) for p in m.planes)))
    result = IdentificationResult(
        method=method, parameters=problem.parameters, estimate=np.asarray(x, float),
        uncertainty=sigma if uncertainty is None else uncertainty,
        covariance=cov, correlation=corr, tests=tuple(tests), chi2=float(chi2), dof=dof,
        covariance_scale=scale, notes=tuple(notes), alternatives=tuple(alternatives), sweep=sweep,
        settings=settings, uncertainty_sources=_sources(problem, base * scale, added),
    )
    return result if failure is None else result.failed(failure)


def _sources(problem: Problem, measured: np.ndarray, added: np.ndarray) -> dict:
    """The two shares of each standard deviation and the tolerances held (empty without nuisances)."""
    if not problem.nuisance:
        return {}
    return {"frequencies": np.sqrt(np.diag(measured)), "tolerances": np.sqrt(np.maximum(np.diag(added), 0.0)),
            "held": {n.name: n.stated for n in problem.nuisance}}


def local_fit(problem: Problem, x0: np.ndarray, max_nfev: int, tol: float = 1e-14) -> tuple[np.ndarray, float]:
    """One bounded trust-region fit from ``x0``: (x, χ²).

    The building block of :func:`fit_lsq`'s multi-start (and of the contour
    method's χ² minimum and the diagnosis's profile scans and
    cross-validation folds): ``max_nfev`` function evaluations at most,
    ``tol`` as ``xtol``, ``ftol`` and ``gtol``; non-finite residuals count as
    a large misfit so that the fit steps back from where the model fails.
    No covariance, notes or warnings.
    """

    def residuals(x):
        r = problem.residuals(x)
        return np.where(np.isfinite(r), r, 1e8)

    def jacobian(x):
        J = problem.jacobian(x)
        return np.where(np.isfinite(J), J, 0.0)

    # Start strictly inside the bounds (the reflective method needs an interior point).
    eps = 1e-10 * (problem.upper - problem.lower)
    x0 = np.clip(x0, problem.lower + eps, problem.upper - eps)
    res = least_squares(residuals, x0, jac=jacobian, bounds=(problem.lower, problem.upper), method="trf",
                        x_scale="jac", max_nfev=max_nfev, xtol=tol, ftol=tol, gtol=tol)
    return res.x, float(2 * res.cost)


def scan_fractions(problem: Problem) -> np.ndarray:
    """Candidate positions of the multi-start scan (fractions of the length): :data:`SCAN_FRACTIONS`, or two
    per half-wave of the highest measured mode when that is finer (an attachment's effect on mode k varies
    as sin²(kπx/l): a coarser grid can miss the basin of the true position)."""
    highest = max((int(np.max(m.modes)) for m in problem.measurements if len(m.modes)), default=0)
    n = max(SCAN_FRACTIONS.size, 2 * highest + 1)
    return np.linspace(SCAN_FRACTIONS[0], SCAN_FRACTIONS[-1], n)


def scaled_chi2(problem: Problem, X: np.ndarray) -> np.ndarray:
    """χ² at the rows of ``X`` after scaling each test's predicted frequencies by its best factor.

    The scan ranks candidate positions with the other variables at their nominal values; a stated tension
    a percent off (a factor on every frequency of its test) would otherwise outweigh what the position
    changes, and the scan would rank the candidates at random.
    """
    F = problem.predict(np.atleast_2d(X))
    out = np.zeros(F.shape[0])
    k = 0
    for m in problem.measurements:
        f = F[:, k:k + m.modes.size]
        w = 1.0 / m.uncertainty**2
        with np.errstate(invalid="ignore", divide="ignore"):
            scale = np.sum(w * f * m.frequencies, axis=1) / np.sum(w * f * f, axis=1)
            out += np.sum(w * (scale[:, None] * f - m.frequencies) ** 2, axis=1)
        k += m.modes.size
    return np.where(np.isfinite(out), out, np.inf)


def _starts(problem: Problem, n_starts: int, seed: int) -> np.ndarray:
    """The nominal point, plus the best distinct points of a scan over the span for positions (ranked by
    :func:`scaled_chi2`)."""
    start = problem.start
    pos = [j for j, q in enumerate(problem.parameters) if q.kind == "position"]
    if not pos or n_starts <= 0:
        return start[None, :]
    length = problem.campaign.cable.length
    nominal = np.array([problem.parameters[j].nominal for j in pos])
    grid = scan_fractions(problem)
    if len(pos) <= 2:
        grids = np.meshgrid(*([grid] * len(pos)), indexing="ij")
        fractions = np.stack([g.ravel() for g in grids], axis=1)
    else:
        fractions = np.random.default_rng(seed).uniform(grid[0], grid[-1], (400, len(pos)))
    candidates = np.repeat(start[None, :], len(fractions), axis=0)
    candidates[:, pos] = fractions * length / nominal
    candidates = np.clip(candidates, problem.lower, problem.upper)
    chi2 = scaled_chi2(problem, candidates)
    chosen = [start]
    spacing = 1.5 * (grid[1] - grid[0]) * length
    for i in np.argsort(chi2):
        if not np.isfinite(chi2[i]) or len(chosen) > n_starts:
            break
        here = candidates[i, pos] * nominal
        if all(np.linalg.norm(here - c[pos] * nominal) > spacing for c in chosen):
            chosen.append(candidates[i])
    return np.array(chosen)


def mirror_images(problem: Problem, x: np.ndarray) -> list[np.ndarray]:
    """Every combination of mirroring the free positions x → l − x of one or more setups.

    On a symmetric cable they give the same frequencies; the fit is rerun
    from each, so on an unsymmetric one they are just more starts.
    """
    groups: dict[str, list[int]] = {}
    for j, q in enumerate(problem.parameters):
        if q.kind == "position":
            groups.setdefault(q.setup, []).append(j)
    if not groups:
        return []
    length = problem.campaign.cable.length
    out = []
    for mask in itertools.product((False, True), repeat=len(groups)):
        if not any(mask):
            continue
        m = np.array(x, float)
        for flip, cols in zip(mask, groups.values()):
            if flip:
                for j in cols:
                    q = problem.parameters[j]
                    m[j] = (length - x[j] * q.nominal) / q.nominal
        m = np.clip(m, problem.lower, problem.upper)
        if not any(np.allclose(m, y, rtol=SAME_POINT, atol=0) for y in [x, *out]):
            out.append(m)
    return out


def nearest_nominal(problem: Problem, candidates: list[np.ndarray]) -> list[np.ndarray]:
    """Candidates ordered by distance from the nominal values (relative to the bounds); ties (a
    mirror image of a midspan nominal) go to the smaller positions, that is to end A's half."""
    width = problem.upper - problem.lower
    pos = [j for j, q in enumerate(problem.parameters) if q.kind == "position"]

    def key(x):
        d = float(np.linalg.norm((x - problem.start) / width))
        return (round(d, 6), tuple(round(float(x[j] * problem.parameters[j].nominal), 6) for j in pos))

    return sorted(candidates, key=key)


def _choose(problem: Problem, solutions: list[tuple[np.ndarray, float]]):
    """Best minimum; among minima that fit equally well, the one nearest the nominal values.

    Returns (x, χ², alternatives, notes); the notes (``equally_well``, ``almost_as_well``) quote the
    other minima as points.
    """
    distinct: list[tuple[np.ndarray, float]] = []
    for x, c in sorted(solutions, key=lambda s: s[1]):
        if not math.isfinite(c):
            continue
        if all(np.max(np.abs(x - y) / np.maximum(1.0, np.abs(y))) > SAME_POINT for y, _ in distinct):
            distinct.append((x, c))
    best_chi2 = distinct[0][1]
    tol = SAME_CHI2 * max(best_chi2, 1.0)
    equal = {id(x): (x, c) for x, c in distinct if c - best_chi2 <= tol}
    order = nearest_nominal(problem, [x for x, _ in equal.values()])
    x, chi2 = equal[id(order[0])]
    alternatives = order[1:]
    notes = []
    names = problem.names
    if alternatives:
        notes.append(Note.make("equally_well", "{value} other estimate(s) explain the data equally well (the one "
                               "nearest the nominal values is reported): {points}", value=len(alternatives),
                               points=[point(names, a) for a in alternatives]))
    # "almost as well": within one unit of χ² (scaled like the covariance when the misfit is large)
    unit = max(1.0, best_chi2 / max(problem.n_data - len(names), 1))
    close = [(y, c) for y, c in distinct if tol < c - best_chi2 < unit]
    for y, c in close:
        notes.append(Note.make("almost_as_well", "another minimum fits almost as well (chi2 {value:.4g} against "
                               "{best:.4g}): {points}", value=float(c), best=float(best_chi2),
                               points=[point(names, y)]))
    return x, chi2, alternatives, notes
