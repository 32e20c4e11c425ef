"""The tolerances of the parameters held fixed, carried into the uncertainty of those fitted.

A fit that frees the tensions and holds EI at its nominal value is only as
good as that nominal value: with one mode per test, a 30 % error in EI moves
a stiff cable's tension by several percent, while the frequencies alone say
nothing of it (there is no residual left to show it). Each parameter held
fixed whose nominal value has a tolerance (the campaign's ``[tolerance]``,
or the kind's default: EI 30 %, length 0.2 %, positions 2 cm, attachment
masses 2 %, damper coefficients 20 %, a test's tension 2 % when it is not
fitted) is a *nuisance* φ with a standard deviation w (the tolerance, taken
as one standard deviation, as the diagnosis's priors take it).

To first order, with the weighted residuals r = (f_model − f_measured)/σ,
their Jacobians J (fitted variables) and A = ∂r/∂φ · w (nuisances, scaled by
their widths), the estimate moves by −G A δ for a nuisance error w δ, with
G = (JᵀJ)⁻¹Jᵀ. The covariance of the estimate is therefore

    C = (JᵀJ)⁻¹ + G A Aᵀ Gᵀ  =  G (I + A Aᵀ) Gᵀ,

the sandwich of the data's covariance I + A Aᵀ (in units of σ). The misfit
test that decides whether to scale the measurements' share by the reduced χ²
uses the same data covariance V = I + A Aᵀ (the χ² of the generalised least
squares under V): a misfit that the tolerances explain (a wrong EI seen
across many modes) is not counted twice.

The estimate itself is the ordinary weighted least squares one (unchanged);
only its uncertainty is made honest.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..core import kinds
from ..core.errors import InputError
from ..core.model import Campaign, Test
from ..core.notes import Note
from ..core.parameters import Parameter, parse_parameters

__all__ = ["Nuisance", "nuisance_parameters", "propagate", "tolerance_note"]


@dataclass(frozen=True)
class Nuisance:
    """One parameter held fixed, with the standard deviation of its variable.

    Attributes
    ----------
    parameter : Parameter
        As :func:`~stcs_ident.core.parameters.parse_parameters` makes it (its nominal value is the one used).
    width : float
        One standard deviation of the variable (a ratio's relative tolerance; an absolute tolerance
        over the variable's scale).
    tolerance : float
        The tolerance as the campaign states it (relative, or in ``unit``).
    unit : str
        ``""`` for a relative tolerance, else its unit.
    """

    parameter: Parameter
    width: float
    tolerance: float
    unit: str = ""

    @property
    def name(self) -> str:
        """``EI``, ``position[W1]``: the parameter's name without ``_ratio``."""
        return self.parameter.name.replace("_ratio", "")

    @property
    def stated(self) -> str:
        """The tolerance as the campaign states it: ``30 %`` or ``0.02 m``."""
        return f"{self.tolerance:g} {self.unit}" if self.unit else f"{100 * self.tolerance:g} %"

    @property
    def label(self) -> str:
        """``EI 30 %`` or ``position[W1] 0.02 m``."""
        return f"{self.name} {self.stated}"


def nuisance_parameters(campaign: Campaign, tests: Sequence[Test], fitted: Sequence[Parameter]) -> list[Nuisance]:
    """Every parameter of ``tests`` that is held fixed and has a tolerance, with its width.

    A kind that does not apply (no attachment, a zero nominal value with a relative tolerance, a
    zero tolerance) gives nothing.
    """
    fitted_names = {q.name for q in fitted}
    tolerances = dict(campaign.tolerance)
    out = []
    for kind in kinds.names():
        declared = kinds.get(kind).tolerance
        if declared is None:
            continue
        tolerance = float(tolerances.get(declared.key, declared.default))
        if tolerance <= 0:
            continue
        try:
            candidates = parse_parameters(campaign, tests, kind)
        except InputError:  # nothing of this kind here (no attachment), or a zero nominal value
            continue
        for q in candidates:
            if q.name in fitted_names or q.is_fixity:
                continue
            if declared.relative:
                if not q.is_ratio or q.nominal == 0:
                    continue
                width = tolerance
            else:
                width = tolerance / abs(q.scale)
            out.append(Nuisance(q, float(width), tolerance, "" if declared.relative else declared.unit))
    return out


def propagate(J: np.ndarray, A: np.ndarray, residuals: np.ndarray, base: np.ndarray) -> tuple[np.ndarray, float]:
    """The covariance with the nuisances' share, and χ² under the data covariance I + A Aᵀ.

    Parameters
    ----------
    J : ndarray (n, p)
        Weighted residuals' Jacobian in the fitted variables.
    A : ndarray (n, q)
        Their Jacobian in the nuisances, each column times its width.
    residuals : ndarray (n,)
        Weighted residuals at the estimate.
    base : ndarray (p, p)
        (JᵀJ)⁻¹ as :func:`~stcs_ident.identify.uncertainty.covariance` gives it (unscaled; NaN/inf for a
        variable the data do not see, which keeps them).

    Returns
    -------
    covariance : ndarray (p, p)
        ``base`` + G A Aᵀ Gᵀ (unscaled).
    chi2 : float
        χ² of the generalised least squares under the data covariance I + A Aᵀ (first order).
    """
    J = np.asarray(J, float)
    A = np.where(np.isfinite(A), A, 0.0)
    seen = np.isfinite(np.diag(base)) & np.all(np.isfinite(J), axis=0)
    out = np.array(base, float)
    if seen.any():
        sub = base[np.ix_(seen, seen)]
        G = sub @ J[:, seen].T
        GA = G @ A
        out[np.ix_(seen, seen)] = sub + GA @ GA.T
    # χ² of the generalised least-squares fit under the data covariance V = I + A Aᵀ, to first order from
    # here: whitened by V's Cholesky factor, the residuals left after the best step of the fitted variables.
    # (The residuals of this weighted fit would give rᵀV⁻¹r, which is not χ²-distributed with n − p
    # degrees of freedom: it scaled the covariance too often where many modes see a nominal EI off.)
    # V^(-1/2) = I + U (1/√(1 + s²) − 1) Uᵀ from the thin SVD A = U S Wᵀ: stable when A is huge (a table printed
    # to 1e-15 Hz makes σ tiny and A ~ 1e14, where a Cholesky factor of V fails).
    r = np.where(np.isfinite(residuals), residuals, 0.0)
    U, s, _ = np.linalg.svd(A, full_matrices=False)

    def whiten(v):
        shrink = (1.0 / np.sqrt(1.0 + s**2) - 1.0)[:, None] * (U.T @ v.reshape(r.size, -1))
        return v + (U @ shrink).reshape(v.shape)

    r_w = whiten(r)
    if seen.any():
        J_w = whiten(J[:, seen])
        step = np.linalg.lstsq(J_w, r_w, rcond=None)[0]
        r_w = r_w - J_w @ step
    return out, float(r_w @ r_w)


def tolerance_note(nuisances: Sequence[Nuisance], share: float) -> Note:
    """The note that says which tolerances are in the standard deviations (``value``: the largest share
    of a fitted variable's variance that they make, 0-1)."""
    return Note.make("tolerances_propagated",
                     "the standard deviations include the tolerances of the parameters held fixed ({tolerances}; "
                     "up to {percent:.0f} % of a variance)",
                     tolerances=", ".join(n.label for n in nuisances), value=float(share), percent=100 * share)
