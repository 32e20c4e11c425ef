"""Model error: a relative term ε per frequency when no hypothesis reaches the measurement uncertainty.

Real tables (han2020) are not fitted to within their stated uncertainty by
any model of the vocabulary; χ² values of 10⁵ then make AICc differences
meaningless. The likelihood with a model error gives every frequency the
variance

    s_i² = σ_i² + (ε f_i)²,

with one ε ≥ 0 per hypothesis (the relative error the model makes, on top
of the measurement's own). Its −2 log-likelihood, up to a constant that is
the same for every hypothesis,

    D(ε) = Σ r_i² / s_i² + Σ log(s_i² / σ_i²),      r_i = f_model,i − f_measured,i,

equals χ² at ε = 0. ε is found by minimising D at the hypothesis's
estimate (a profile: the parameters are not refitted with the new weights,
which changes them little when σ_i is about proportional to f_i) and it
counts as one more parameter in AICc.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import minimize_scalar

__all__ = ["deviance", "fit_epsilon"]


def deviance(residuals: np.ndarray, sigma: np.ndarray, frequencies: np.ndarray, epsilon: float) -> float:
    """D(ε) of the module docstring (χ² at ε = 0)."""
    s2 = sigma**2 + (epsilon * frequencies) ** 2
    return float(np.sum(residuals**2 / s2) + np.sum(np.log(s2 / sigma**2)))


def fit_epsilon(residuals: np.ndarray, sigma: np.ndarray, frequencies: np.ndarray) -> tuple[float, float]:
    """(ε, D(ε)) minimising the deviance over ε ≥ 0 (ε = 0 when the residuals need no model error).

    Raises
    ------
    ValueError
        For non-finite residuals.
    """
    r, sigma, f = (np.asarray(a, float) for a in (residuals, sigma, frequencies))
    if not np.all(np.isfinite(r)):
        raise ValueError("the residuals are not finite")
    top = float(np.max(np.abs(r) / f, initial=0.0))
    d0 = deviance(r, sigma, f, 0.0)
    if top == 0.0:
        return 0.0, d0
    # Search log ε over a range wide enough for any relative misfit (1e-8 .. 10 × the largest); ε = 0
    # wins when the residuals are within their uncertainty.
    res = minimize_scalar(lambda u: deviance(r, sigma, f, math.exp(u)),
                          bounds=(math.log(1e-8 * top + 1e-300), math.log(10.0 * top)), method="bounded",
                          options={"xatol": 1e-6})
    eps, d = math.exp(res.x), float(res.fun)
    if d0 <= d:
        return 0.0, d0
    return eps, d
