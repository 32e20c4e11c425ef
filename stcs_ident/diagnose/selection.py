"""Model selection: from ranked hypotheses to a named cause.

1. **Does the nominal model explain the data?** Its χ² is compared with the
   χ² distribution of n degrees of freedom (n measured frequencies, no
   parameter fitted). Below the 1 − :data:`ALPHA` quantile the misfit is
   what the measurement uncertainties lead one to expect and the cause is
   empty: no effect is invented. ALPHA = 0.001 keeps false alarms at about
   one in a thousand data sets with honest uncertainties, while a hidden
   effect worth naming raises χ² by orders of magnitude.
2. **Ranking**: by AICc (:func:`~.fitting.aicc`), best first. Parameters
   whose nominal value has a tolerance (:mod:`stcs_ident.effects`: a
   stated tension, the nominal EI, a recorded position or mass, the
   length) carry a Cauchy prior of that scale, an unmodeled attachment's
   position the Occam factor of a search over the span
   (:func:`~.fitting.prior_penalty`), and the penalty counts in AICc: of
   two hypotheses the frequencies cannot tell apart (tension + length
   reproduce any EI change exactly), the one that needs the more plausible
   departures wins. When no hypothesis reaches the measurement
   uncertainty (step 3's gate fails for all), every hypothesis gets a
   relative model error ε per frequency (:mod:`.model_error`) and AICc is
   that of the likelihood with it, one more parameter each. A
   hypothesis with an effect without a tolerance whose size the data do
   not establish (:func:`insignificant`), or whose gain rests on a single
   frequency (:func:`single_frequency`), is not ranked; nor is one whose
   final fit stopped at a bound of the search (a failed hypothesis: the
   report says which parameter and which bound).
3. **Parsimony**: a hypothesis with fewer parameters than the best one
   that is within :data:`AMBIGUITY` of it in AICc explains the data as well
   more simply and is preferred (Burnham & Anderson: an added parameter
   that lowers χ² by less than 2 is not supported; on a stay, a 50 kg
   damper moved to the far end with 30 kg beside it, three parameters,
   fitted 0.4 better than the damper 30 kg heavier, one). So is a nested
   hypothesis (a subset of the best one's effects) that already explains
   the data within their uncertainty (its χ² below the 1 − ALPHA quantile
   for n − k degrees of freedom): as for the nominal model in step 1, an
   effect is added only when the simpler model fails, never to absorb the
   noise. Of those, the one with the fewest effects, then the lowest AICc,
   is taken, and the rule applied again from it. Where none qualifies, a
   hypothesis with no more parameters, within the noise as well and more
   than AMBIGUITY lower in AICc, replaces the chosen one (and the rule goes
   on from it): a 125 kg damper recorded as 50 kg at 3 m of a 120 m stay
   was fitted best as 115 kg unrecorded at the far end with EI 11 % up
   (5 parameters), the nested rule then took 75 kg unrecorded beside the
   damper (χ² 42.2, 4 parameters, AICc 18.5 above the best), while the
   damper's own mass explains the data with 3 (χ² 28.4, AICc 3.1 above;
   validate_diagnosis stay seed 9503).
4. **Principal effect**: of the chosen effects, the one whose removal
   raises AICc most, of those whose removal cost is known. A cost is not
   known when the hypothesis without the effect was not fitted or its fit
   failed (it stopped at a bound: no estimate, so no AICc); such an effect
   is principal only when no cost is known, and ``removal_unknown`` says
   why (an unknown cost is never read as an infinite one).
5. **Ambiguity**: every other hypothesis within :data:`AMBIGUITY` of the
   chosen one's AICc and not merely the chosen effects plus another is
   reported as ambiguous, never hidden; so are those that explain the
   frequencies as well (within their uncertainty, or χ² within AMBIGUITY of
   the chosen one's) but need less plausible departures (``implausible``).
6. **Corrections or causes**: an effect with a tolerance is a *cause* only
   when the data require a departure beyond it: for some parameter,
   (|x − nominal| − tolerance) > :data:`BEYOND` σ. Otherwise it is a
   *correction* (reported with its value, never as a cause). Effects
   without a tolerance (an unmodeled mass or support, an end restraint)
   are causes when chosen. The corrected model is the chosen hypothesis,
   corrections included.
7. **Plausibility first**: when a hypothesis of corrections alone (every
   effect within its tolerance, and all of them at once: the nearest point
   of the tolerance box lies within BEYOND² in χ², :func:`joint_excess`)
   is within :data:`AMBIGUITY` of the chosen
   one, it is chosen instead: the frequencies cannot tell the two apart,
   and stated values within their tolerance are the more plausible
   explanation. On a string-like stay (ξ ≈ 170) a tension within its 2 %
   tolerance, a length change or an end restraint reproduce one another;
   without this step such records were diagnosed as `end_restraint` or
   `length` (benchmarks/validate_diagnosis.py, healthy stays).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize
from scipy.stats import chi2 as chi2_distribution

from .. import effects
from ..core import kinds
from .fitting import HypothesisFit, prior_widths

#: False-alarm probability of the test "the nominal model explains the data".
ALPHA = 1e-3
#: AICc difference below which two hypotheses are not told apart.
AMBIGUITY = 2.0
#: The baseline hypothesis: the source paper's correction of tension and EI.
BASELINE = effects.baseline()
#: A departure is beyond tolerance when it exceeds it by more than this many standard deviations
#: (one-sided 97.7 %: the data require it).
BEYOND = 2.0


@dataclass(frozen=True)
class Selection:
    """The named cause.

    Attributes
    ----------
    effects : tuple of str
        The cause (empty when the nominal model explains the data, or
        needs only corrections within tolerance).
    principal : str or None
    ambiguous_with : tuple of tuple of str
    explained : bool
        True when the nominal model explains the data within the noise.
    p_value : float
        Probability of a χ² at least the nominal's if the nominal model
        were right.
    removal_cost : dict
        ΔAICc when each effect of the chosen hypothesis is removed (NaN where
        not known: see ``removal_unknown``).
    statement : str
        One sentence on what was decided and why.
    fitted : tuple of str
        The chosen hypothesis (the cause and the corrections): the
        corrected model.
    corrections : tuple of str
        Effects of the chosen hypothesis whose departures stay within the
        tolerance of the nominal values.
    implausible : tuple of tuple of str
        Hypotheses the frequencies alone do not separate from the chosen
        one, that lose on the plausibility of their departures.
    model_error : bool
        Whether no hypothesis reaches the measurement uncertainty, so that
        AICc includes a model error ε.
    removal_unknown : dict
        {effect: why its removal cost is not known} (the hypothesis without
        it was not fitted, or its fit failed, with the failure's reason).
    """

    effects: tuple[str, ...]
    principal: str | None
    ambiguous_with: tuple[tuple[str, ...], ...]
    explained: bool
    p_value: float
    removal_cost: dict[str, float]
    statement: str
    fitted: tuple[str, ...] = ()
    corrections: tuple[str, ...] = ()
    implausible: tuple[tuple[str, ...], ...] = ()
    model_error: bool = False
    removal_unknown: dict[str, str] = field(default_factory=dict)


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


def baseline_fit(fits: dict[tuple[str, ...], HypothesisFit]) -> HypothesisFit | None:
    """The gain's reference: tension and EI re-estimated (the paper's correction), or what of it was fitted
    (a tolerance of 0 leaves one out); None when neither was fitted successfully."""
    for key in (BASELINE, *((e,) for e in BASELINE)):
        if key in fits and fits[key].failure is None:
            return fits[key]
    return None


def allowed(effects_: tuple[str, ...], max_effects: int) -> bool:
    """Whether a hypothesis may be chosen: at most ``max_effects`` effects, or the baseline (tension and EI)
    plus at most ``max_effects`` − 1 further ones."""
    if len(effects_) <= max_effects:
        return True
    return set(BASELINE) <= set(effects_) and len(effects_) <= len(BASELINE) + max_effects - 1


def needs_model_error(fits: dict[tuple[str, ...], HypothesisFit], n: int) -> bool:
    """Whether no fitted hypothesis (the nominal model included) explains the data within their uncertainty:
    the ranking then needs a model error (:mod:`.model_error`)."""
    fitted = [f for f in fits.values() if f.failure is None and math.isfinite(f.chi2)]
    return bool(fitted) and not any(_within_noise(f, n) for f in fitted)


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
    ranked = [f for f in ranking(fits) if f.effects and allowed(f.effects, max_effects) and math.isfinite(f.aicc)
              and not insignificant(f) and not single_frequency(f, fits)]
    model_error = needs_model_error(fits, n)
    if not ranked or ranked[0].aicc >= nominal.aicc:
        return Selection((), None, (), False, p_value, {},
                         f"The nominal model does not explain the data (chi2 = {nominal.chi2:.1f} for {n} "
                         f"frequencies, p = {p_value:.2g}), but no hypothesis improves on it.", model_error=model_error)
    best = ranked[0]
    while True:
        nested = [f for f in ranked if f.effects and f.n_parameters < best.n_parameters
                  and (f.aicc - best.aicc < AMBIGUITY or (set(f.effects) < set(best.effects) and _within_noise(f, n)))]
        if not nested:
            # No more parameters, within the noise too, and clearly better: the nested rule must not stop
            # at a hypothesis another explanation of its size beats.
            nested = [f for f in ranked if f.n_parameters <= best.n_parameters and _within_noise(f, n)
                      and f.aicc < best.aicc - AMBIGUITY]
        if not nested:
            break
        best = min(nested, key=lambda f: (len(f.effects), f.aicc))
    beyond = beyond_tolerance(best)
    if any(beyond.get(e) is not False for e in best.effects):
        # Step 7: a cause is named only when no hypothesis of corrections alone explains the data as well.
        plain = [f for f in ranked if f.aicc - best.aicc < AMBIGUITY and _corrections_only(f)]
        if plain:
            best = min(plain, key=lambda f: (len(f.effects), f.aicc))
            beyond = beyond_tolerance(best)
    corrections = tuple(e for e in best.effects if beyond.get(e) is False)
    cause = tuple(e for e in best.effects if e not in corrections)
    cost, unknown = removal_costs(best, fits)
    known = [e for e in cause if e not in unknown]
    principal = max(known, key=lambda e: cost[e]) if known else (cause[0] if cause else None)
    ambiguous = tuple(f.effects for f in ranked if f is not best and f.aicc - best.aicc < AMBIGUITY
                      and not set(f.effects) > set(best.effects))
    implausible = tuple(f.effects for f in ranked if f is not best and f.effects not in ambiguous
                        and not set(f.effects) > set(best.effects) and f.penalty > best.penalty + AMBIGUITY
                        and (_within_noise(f, n) or f.chi2 - best.chi2 < AMBIGUITY))
    delta = nominal.aicc - best.aicc
    head = (f"The nominal model does not explain the data (chi2 = {nominal.chi2:.1f} for {n} frequencies, "
            f"p = {p_value:.2g}); ")
    shown = " + ".join(best.effects)
    if cause:
        statement = head + f"{shown} explains them best (AICc {delta:.1f} below the nominal model's)"
        if corrections:
            statement += f"; {', '.join(corrections)} within tolerance (a correction, not a cause)"
    else:
        statement = (head + f"corrections within the tolerances of the nominal values ({shown}) explain them "
                     f"(AICc {delta:.1f} below the nominal model's); no effect is named")
    if ambiguous:
        statement += f", but {'; '.join(' + '.join(a) for a in ambiguous)} explain them about as well (ΔAICc < 2)"
    return Selection(cause, principal, ambiguous, False, p_value, cost, statement + ".", best.effects, corrections,
                     implausible, model_error, unknown)


def removal_costs(best: HypothesisFit, fits: dict) -> tuple[dict[str, float], dict[str, str]]:
    """The AICc rise when each effect of ``best`` is dropped ({effect: ΔAICc}, NaN where not known) and why a
    cost is not known ({effect: reason}): the hypothesis without the effect was not fitted, or failed."""
    cost: dict[str, float] = {}
    unknown: dict[str, str] = {}
    for e in best.effects:
        rest = tuple(x for x in best.effects if x != e)
        other = fits.get(rest)
        label = " + ".join(rest) or "the nominal model"
        if other is None:
            cost[e], unknown[e] = math.nan, f"{label} was not fitted"
        elif other.failure is not None or not math.isfinite(other.aicc):
            reason = (other.failure or "its AICc is not finite").split(":", 1)[0].split(", so ")[0]
            cost[e], unknown[e] = math.nan, f"{label} failed ({reason})"
        else:
            cost[e] = other.aicc - best.aicc
    return cost, unknown


def insignificant(fit: HypothesisFit) -> tuple[str, ...]:
    """Effects of ``fit`` without a tolerance (an unmodeled mass or support, an end restraint) whose size the
    data do not establish: no amplitude (a parameter of a kind with ``amplitude`` set, :mod:`stcs_ident.core.kinds`)
    departs from its nominal value by more than :data:`BEYOND` σ. A fit whose amplitude stopped at the
    upper bound of its search is a failed hypothesis (:mod:`stcs_ident.identify.bounds`), never ranked.
    Such a hypothesis is never chosen (step 2).

    A support of 452 N/m found at mid-span of a 4 MN stay, its stiffness and position without a finite σ,
    had absorbed one mode's misfit and was named beside an EI change (validate_diagnosis stay seed 1501).
    """
    res = fit.result
    if res is None:
        return ()
    widths = prior_widths(fit.hypothesis.campaign, fit.hypothesis)
    shown: dict[str, bool] = {}
    for p, owner, x, sigma, width in zip(res.parameters, fit.hypothesis.owners, res.estimate, res.uncertainty,
                                         widths):
        if width is not None or not kinds.get(p.kind).amplitude:
            continue
        # (An amplitude pushed to its upper bound no longer reaches here: that fit failed, fitting.fit_hypothesis.)
        sized = math.isfinite(sigma) and sigma > 0 and abs(float(x) - p.start) > BEYOND * sigma
        shown[owner] = shown.get(owner, False) or sized
    return tuple(e for e, sized in shown.items() if not sized)


def single_frequency(fit: HypothesisFit, fits: dict[tuple[str, ...], HypothesisFit]) -> tuple[str, ...]:
    """Effects of ``fit`` without a tolerance whose gain rests on one measured frequency: the fall in χ² from
    the hypothesis without the effect, less the fall at the single frequency that gains most, is no more
    than 2 per parameter the effect adds (what AICc charges for them). Such a hypothesis is never chosen
    (step 2): one frequency off by 4 σ is an outlier of the spectra, not a point attachment at the node
    of every other mode.

    A 452 N/m support at mid-span of a 4 MN stay lowered χ² by 18.0, 17.4 of it at mode 1 of one test
    (z = 4.1 against the truth), and was named beside an EI change (validate_diagnosis stay seed 1501).
    With a model error (step 2) the terms are those of its likelihood, at the larger ε of the two fits.
    """
    if fit.terms is None:
        return ()
    widths = prior_widths(fit.hypothesis.campaign, fit.hypothesis)
    free = {}
    for owner, width in zip(fit.hypothesis.owners, widths):
        if width is None:
            free[owner] = free.get(owner, 0) + 1
    out = []
    for effect, k in free.items():
        other = fits.get(tuple(e for e in fit.effects if e != effect))
        if other is None or other.terms is None or other.terms.shape != fit.terms.shape:
            continue
        epsilon = max(fit.epsilon, other.epsilon)  # with a model error, both at the larger one
        gain = other.terms_with(epsilon) - fit.terms_with(epsilon)
        if float(np.sum(gain) - np.max(gain)) <= 2.0 * k:
            out.append(effect)
    return tuple(out)


def _corrections_only(fit: HypothesisFit) -> bool:
    """Whether every effect of ``fit`` has a tolerance and the data allow all of them within it at once
    (steps 6 and 7): nothing to name."""
    beyond = beyond_tolerance(fit)
    if not fit.effects or any(beyond.get(e) is not False for e in fit.effects):
        return False
    return joint_excess(fit) <= BEYOND**2


def joint_excess(fit: HypothesisFit) -> float:
    """Δχ² from the estimate to the nearest point with every parameter within its tolerance at once.

    min (y − x)ᵀ C⁻¹ (y − x) over |y_i − nominal_i| ≤ tolerance_i (C the
    estimate's covariance; parameters without a tolerance free), solved as
    a bounded linear least-squares problem. For one parameter it is
    (excess / σ)², so ≤ BEYOND² is step 6's test; with several it also
    catches a departure spread over parameters the frequencies cannot
    separate, each of which alone seems allowed by its wide σ (a stay 3 %
    longer: tension −2.0 %, length +1.7 %, EI −5 %, each "not required"
    beyond its 2 %, 0.2 %, 30 %; together 40 σ² outside). 0 without a
    covariance.
    """
    res = fit.result
    if res is None or res.covariance is None:
        return 0.0
    widths = prior_widths(fit.hypothesis.campaign, fit.hypothesis)
    x = np.asarray(res.estimate, float)
    start = np.array([p.start for p in res.parameters], float)
    lo = np.array([s - w if w is not None else -np.inf for s, w in zip(start, widths)])
    hi = np.array([s + w if w is not None else np.inf for s, w in zip(start, widths)])
    if np.all((x >= lo) & (x <= hi)):
        return 0.0
    cov = np.asarray(res.covariance, float)
    if cov.shape != (x.size, x.size):
        return 0.0
    # A parameter the fit could not give a variance (an unmodeled stiffness at its bound) is left out.
    known = np.all(np.isfinite(cov), axis=0) & np.all(np.isfinite(cov), axis=1)
    if not np.any(known):
        return 0.0
    cov, x, lo, hi = cov[np.ix_(known, known)], x[known], lo[known], hi[known]
    values, vectors = np.linalg.eigh(0.5 * (cov + cov.T))
    keep = values > max(values.max(), 0.0) * 1e-12
    if not np.any(keep):
        return 0.0
    whiten = (vectors[:, keep] / np.sqrt(values[keep])).T  # W with Wᵀ W = C⁺
    solution = optimize.lsq_linear(whiten, whiten @ x, bounds=(lo, hi))
    return float(2.0 * solution.cost)


def beyond_tolerance(fit: HypothesisFit) -> dict[str, bool]:
    """For each effect of ``fit`` whose parameters have a tolerance: whether the data require a departure
    beyond it (step 6 of the module docstring)."""
    if fit.result is None:
        return {}
    widths = prior_widths(fit.hypothesis.campaign, fit.hypothesis)
    res = fit.result
    out: dict[str, bool] = {}
    for p, owner, x, sigma, width in zip(res.parameters, fit.hypothesis.owners, res.estimate, res.uncertainty,
                                         widths):
        if width is None:
            continue
        excess = abs(float(x) - p.start) - width
        required = bool(excess > 0 and math.isfinite(sigma) and excess > BEYOND * sigma)
        out[owner] = out.get(owner, False) or required
    return out
