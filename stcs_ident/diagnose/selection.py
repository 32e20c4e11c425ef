"""Model selection: from ranked hypotheses to a named cause.

1. **Does the nominal model explain the data?** Its χ² is compared with the
   χ² distribution of n degrees of freedom (n measured frequencies, no
   parameter fitted). Below the 1 − :data:`ALPHA` quantile the misfit is
   what the measurement uncertainties lead one to expect and the cause is
   empty: no effect is invented. ALPHA = 0.001 keeps false alarms at about
   one in a thousand data sets with honest uncertainties, while a hidden
   effect worth naming raises χ² by orders of magnitude.
2. **Ranking**: by AICc (:func:`~.fitting.aicc`), best first.
3. **Parsimony**: a hypothesis nested in the best one (a subset of its
   effects) that is within :data:`AMBIGUITY` of it in AICc explains the data
   as well with fewer effects and is preferred (Burnham & Anderson: an
   added parameter that lowers χ² by less than 2 is not supported). So is a
   nested hypothesis that already explains the data within their
   uncertainty (its χ² below the 1 − ALPHA quantile for n − k degrees of
   freedom): as for the nominal model in step 1, an effect is added only
   when the simpler model fails, never to absorb the noise.
4. **Principal effect**: of the chosen effects, the one whose removal
   raises AICc most.
5. **Ambiguity**: every other hypothesis within :data:`AMBIGUITY` of the
   chosen one's AICc and not merely the chosen effects plus another is
   reported as ambiguous, never hidden.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.stats import chi2 as chi2_distribution

from .. import effects
from .fitting import HypothesisFit

#: False-alarm probability of the test "the nominal model explains the data".
ALPHA = 1e-3
#: AICc difference below which two hypotheses are not told apart.
AMBIGUITY = 2.0
#: The baseline hypothesis: the source paper's correction of tension and EI.
BASELINE = effects.baseline()


@dataclass(frozen=True)
class Selection:
    """The named cause.

    Attributes
    ----------
    effects : tuple of str
        The cause (empty when the nominal model explains the data).
    principal : str or None
    ambiguous_with : tuple of tuple of str
    explained : bool
        True when the nominal model explains the data within the noise.
    p_value : float
        Probability of a χ² at least the nominal's if the nominal model
        were right.
    removal_cost : dict
        ΔAICc when each effect of the cause is removed.
    statement : str
        One sentence on what was decided and why.
    """

    effects: tuple[str, ...]
    principal: str | None
    ambiguous_with: tuple[tuple[str, ...], ...]
    explained: bool
    p_value: float
    removal_cost: dict[str, float]
    statement: str


def explains(nominal: HypothesisFit, n: int) -> bool:
    """Whether the nominal model explains ``n`` frequencies within their uncertainty (step 1)."""
    return _p_value(nominal.chi2, n) >= ALPHA


def _within_noise(fit: HypothesisFit, n: int) -> bool:
    """Whether a fitted hypothesis leaves a χ² the measurement uncertainty explains (n − k dof)."""
    dof = n - fit.n_parameters
    return dof > 0 and _p_value(fit.chi2, dof) >= ALPHA


def _p_value(chi2: float, dof: int) -> float:
    """Probability of a χ² at least ``chi2`` for ``dof`` degrees of freedom."""
    return float(chi2_distribution.sf(chi2, dof))


def ranking(fits: dict[tuple[str, ...], HypothesisFit]) -> list[HypothesisFit]:
    """Fits sorted by AICc (ties: fewer parameters first)."""
    return sorted(fits.values(), key=lambda f: (f.aicc, f.n_parameters, len(f.effects)))


def select(fits: dict[tuple[str, ...], HypothesisFit], n: int, max_effects: int = 2) -> Selection:
    """Name the cause from the fitted hypotheses (see the module docstring); a cause has at most
    ``max_effects`` effects (the baseline is fitted as a reference even when it has more)."""
    nominal = fits[()]
    p_value = _p_value(nominal.chi2, n)
    if p_value >= ALPHA:
        return Selection((), None, (), True, p_value, {},
                         f"The nominal model explains the data within their uncertainty: chi2 = {nominal.chi2:.1f} "
                         f"for {n} frequencies (p = {p_value:.3g} >= {ALPHA:g}); no effect is named.")
    ranked = [f for f in ranking(fits) if f.effects and len(f.effects) <= max_effects and math.isfinite(f.aicc)]
    if not ranked or ranked[0].aicc >= nominal.aicc:
        return Selection((), None, (), False, p_value, {},
                         f"The nominal model does not explain the data (chi2 = {nominal.chi2:.1f} for {n} "
                         f"frequencies, p = {p_value:.2g}), but no hypothesis improves on it.")
    best = ranked[0]
    while True:
        nested = [f for f in ranked if f.effects and set(f.effects) < set(best.effects)
                  and (f.aicc - best.aicc < AMBIGUITY or _within_noise(f, n))]
        if not nested:
            break
        best = min(nested, key=lambda f: (len(f.effects), f.aicc))
    cost = {}
    for e in best.effects:
        rest = tuple(x for x in best.effects if x != e)
        other = fits.get(rest)
        cost[e] = (other.aicc - best.aicc) if other is not None else math.inf
    principal = max(cost, key=lambda e: cost[e])
    ambiguous = tuple(f.effects for f in ranked if f is not best and f.aicc - best.aicc < AMBIGUITY
                      and not set(f.effects) > set(best.effects))
    delta = nominal.aicc - best.aicc
    statement = (f"The nominal model does not explain the data (chi2 = {nominal.chi2:.1f} for {n} frequencies, "
                 f"p = {p_value:.2g}); {' + '.join(best.effects)} explains them best "
                 f"(AICc {delta:.1f} below the nominal model's)")
    if ambiguous:
        statement += f", but {'; '.join(' + '.join(a) for a in ambiguous)} explain them about as well (ΔAICc < 2)"
    return Selection(best.effects, principal, ambiguous, False, p_value, cost, statement + ".")
