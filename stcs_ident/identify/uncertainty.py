"""Covariance from the Jacobian, its scaling, and the identifiability check.

With weighted residuals r = (f_model − f_measured)/σ and their Jacobian J
at the estimate, the covariance of the estimate is (JᵀJ)⁻¹ when the σ are
right. Real data rarely fit a few-parameter model to within the stated σ
(a table's rounding, say): then the covariance is multiplied by the reduced
χ² (Birge ratio squared), which takes the scatter of the residuals as the
measure of the frequencies' real uncertainty. By default this is done only
when the misfit is significant (χ² above its 95 % quantile for the degrees
of freedom): when the stated σ are right, an unconditional
``max(1, χ²/dof)`` would widen the intervals in about half the data sets and
make the 1σ intervals cover the truth ~72 % of the time instead of 68 %.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from scipy import stats

from ..core.errors import StcsWarning
from ..core.notes import Note
from ..core.settings import SCALE_RULES

#: |correlation| above which two parameters are reported as not separately identifiable.
CORRELATION_LIMIT = 0.995
#: Condition number of the column-normalised Jacobian above which the fit is ill-conditioned.
CONDITION_LIMIT = 1e3
#: A column this small relative to the largest has no effect on the data. The Jacobian is a central
#: difference with a relative step of 1e-6 on frequencies refined to about 1e-12 relative, so a
#: parameter without effect still shows a column of order 1e-12 / 1e-6 = 1e-6 of a real one's
#: (observed 8e-9 for a massless attachment's position).
NO_EFFECT = 1e-6

#: Sentence of the ``covariance_scaled`` note (the contour method says what it widens instead).
SCALED = ("the misfit is {misfit:.3g} times the stated frequency uncertainties (reduced chi2 {value:.3g}, {dof} "
          "degrees of freedom): the covariance is scaled by the reduced chi2")


class IdentifiabilityWarning(StcsWarning):
    """Some parameters are not identifiable from the data; ``.parameters`` names them."""

    def __init__(self, message: str, parameters: Sequence[str] = ()):
        super().__init__(message)
        self.parameters = tuple(parameters)


def covariance_scale(chi2: float, dof: int, rule: str = "auto", *, tolerances: bool = False) -> tuple[float, Note | None]:
    """Factor for the covariance and a note saying why it is applied.

    The note is ``no_degrees_of_freedom`` or ``covariance_scaled`` (its
    ``value`` the reduced χ², its data ``misfit`` = √value and ``dof``).

    Parameters
    ----------
    chi2 : float
    dof : int
    rule : {"auto", "birge", "never"}
        ``auto``: scale by χ²/dof when χ² exceeds its 95 % quantile;
        ``birge``: whenever χ²/dof > 1; ``never``.
    tolerances : bool
        Whether the tolerances of parameters held fixed are in the uncertainties too (said in the notes: the
        scale then applies to the frequencies' share alone).
    """
    if rule not in SCALE_RULES:
        raise ValueError(f"scale rule must be one of {SCALE_RULES}, got {rule!r}")
    if dof <= 0:
        rest = ("the stated frequency uncertainties and the tolerances of the parameters held fixed" if tolerances
                else "the stated frequency uncertainties alone")
        return 1.0, Note.make("no_degrees_of_freedom", "no degrees of freedom left: the uncertainties rest on "
                              + rest)
    reduced = chi2 / dof
    significant = chi2 > stats.chi2.ppf(0.95, dof)
    if rule == "never" or reduced <= 1 or (rule == "auto" and not significant):
        return 1.0, None
    template = SCALED.replace("the covariance is", "the frequencies' share of the covariance is") if tolerances else SCALED
    return reduced, Note.make("covariance_scaled", template, value=float(reduced), misfit=float(np.sqrt(reduced)),
                              dof=int(dof))


def covariance(J: np.ndarray, scale: float = 1.0, typical: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Covariance (JᵀJ)⁻¹ × scale and the correlation matrix (pseudo-inverse: a
    direction the data do not see gets infinite variance).

    ``typical``: the size of each variable (:meth:`Problem.typical`, default 1); a column without effect is
    one whose change of the data for a relative change of its variable is negligible (:data:`NO_EFFECT`),
    whatever the variable's unit.

    A column that is not finite (the model could not be evaluated on either
    side of the estimate) gets infinite variance and NaN covariances; the
    others are computed from the finite columns.
    """
    J = np.asarray(J, float)
    lost = ~np.all(np.isfinite(J), axis=0)
    if lost.any():
        cov = np.full((J.shape[1], J.shape[1]), np.nan)
        corr = np.full_like(cov, np.nan)
        keep = np.flatnonzero(~lost)
        if keep.size:
            sub_cov, sub_corr = covariance(J[:, keep], scale, None if typical is None else np.asarray(typical)[keep])
            cov[np.ix_(keep, keep)], corr[np.ix_(keep, keep)] = sub_cov, sub_corr
        cov[np.flatnonzero(lost), np.flatnonzero(lost)] = np.inf
        np.fill_diagonal(corr, 1.0)
        return cov, corr
    norms = np.linalg.norm(J, axis=0)
    effect = norms * (1.0 if typical is None else np.asarray(typical, float))
    safe = np.where(norms > 0, norms, 1.0)
    Jn = J / safe
    _U, s, Vt = np.linalg.svd(Jn, full_matrices=False)
    small = s <= NO_EFFECT * max(s.max(initial=0.0), 1e-300)
    inv = np.where(small, 0.0, 1.0 / np.where(small, 1.0, s) ** 2)
    cov_n = (Vt.T * inv) @ Vt
    cov = cov_n / np.outer(safe, safe) * scale
    blind = (effect <= NO_EFFECT * max(effect.max(initial=0.0), 1e-300)) | (np.abs(Vt[small]) > 0.1).any(axis=0)
    for i in np.flatnonzero(blind):
        cov[i, :] = np.nan
        cov[:, i] = np.nan
        cov[i, i] = np.inf
    d = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(d, d)
    np.fill_diagonal(corr, 1.0)
    return cov, corr


def correlation(cov: np.ndarray) -> np.ndarray:
    """The correlation matrix of a covariance (NaN where a variance is infinite or zero; 1 on the diagonal)."""
    d = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(d, d)
    np.fill_diagonal(corr, 1.0)
    return corr


def identifiability(J: np.ndarray, names: Sequence[str], corr: np.ndarray, sigma: np.ndarray,
                    lower: np.ndarray, upper: np.ndarray, typical: np.ndarray | None = None) -> list[Note]:
    """Problems that make parameters not identifiable, as notes naming the parameters.

    - ``no_effect``: a parameter that does not change any measured frequency;
    - ``correlated``: two parameters correlated beyond
      :data:`CORRELATION_LIMIT` (``value``: the correlation);
    - ``ill_conditioned``: the Jacobian's column-normalised form has a
      condition number (``value``) above :data:`CONDITION_LIMIT`; the
      parameters of the weakest direction are named;
    - ``not_located``: a standard deviation (``value``) wider than half the
      bounds: the data do not locate the parameter within them.
    """
    names = list(names)
    problems = []
    lost = ~np.all(np.isfinite(J), axis=0)
    for i in np.flatnonzero(lost):
        problems.append(Note.make("not_evaluated", "the model cannot be evaluated on either side of {parameter}'s "
                                  "estimate (its derivative is unknown)", parameters=(names[i],)))
    J = np.where(lost, 0.0, J)
    norms = np.linalg.norm(J, axis=0)
    effect = norms * (1.0 if typical is None else np.asarray(typical, float))
    dead = (effect <= NO_EFFECT * max(effect.max(initial=0.0), 1e-300)) & ~lost
    for i in np.flatnonzero(dead):
        problems.append(Note.make("no_effect", "{parameter} does not change any measured frequency",
                                  parameters=(names[i],)))
    live = np.flatnonzero(~dead & ~lost)
    for a, i in enumerate(live):
        for j in live[a + 1:]:
            if abs(corr[i, j]) > CORRELATION_LIMIT:
                problems.append(Note.make("correlated", "{names[0]} and {names[1]} are correlated at {value:+.4f}: "
                                          "the data determine only a combination of them",
                                          parameters=(names[i], names[j]), value=float(corr[i, j])))
    if live.size > 1:
        Jn = J[:, live] / norms[live]
        _, s, Vt = np.linalg.svd(Jn, full_matrices=False)
        cond = s[0] / s[-1] if s[-1] > 0 else np.inf
        if cond > CONDITION_LIMIT:
            weak = tuple(names[live[k]] for k in np.flatnonzero(np.abs(Vt[-1]) > 0.25))
            problems.append(Note.make("ill_conditioned", "the Jacobian is ill-conditioned (condition number "
                                      "{value:.3g}); weakest direction: {parameters}", parameters=weak,
                                      value=float(cond)))
    for i in live:
        if np.isfinite(sigma[i]) and sigma[i] > 0.5 * (upper[i] - lower[i]):
            problems.append(Note.make("not_located", "{parameter} is not located within its bounds [{lower:g}, "
                                      "{upper:g}] (standard deviation {value:.3g})", parameters=(names[i],),
                                      value=float(sigma[i]), lower=float(lower[i]), upper=float(upper[i])))
    return problems


#: What the notes of :func:`warn_identifiability` say before each problem.
NOT_IDENTIFIABLE = "not identifiable from the data: "


def warn_identifiability(problems: list[Note], stacklevel: int = 3) -> list[Note]:
    """Issue one :class:`IdentifiabilityWarning` naming every affected parameter; return the notes
    (the problems, each said as ``not identifiable from the data: ...``)."""
    if not problems:
        return []
    affected = tuple(dict.fromkeys(n for p in problems for n in p.parameters))
    message = f"parameters not identifiable from the data: {', '.join(affected)} ({'; '.join(map(str, problems))})"
    warnings.warn(IdentifiabilityWarning(message, affected), stacklevel=stacklevel)
    return [replace(p, template=NOT_IDENTIFIABLE + p.template) for p in problems]
