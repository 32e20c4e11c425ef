"""Fitting one hypothesis: estimate, AICc and the plausibility of its departures.

The estimate is the weighted least-squares fit of :mod:`stcs_ident.identify.lsq`
(χ² with the frequency uncertainties as weights). A free position of an
unmodeled mass or support is found by a profile scan first: the amplitude
(and every other parameter) is fitted with the attachment held at each point
of a grid over the span (half the span when the configuration is symmetric
about midspan), and the best points start the full fit. Pairs of effects
also start from the estimates of their single effects.

AICc (Hurvich & Tsai) with known measurement uncertainties:

    AICc = χ² + 2k + 2k(k + 1) / (n − k − 1)

(n measured frequencies, k free parameters; χ² is −2 log L up to a constant).

The cross-validated prediction errors of a fitted hypothesis are in
:mod:`.cross_validation`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from .. import effects as registry
from ..core.model import Attachment, Campaign, Test
from ..core.notes import Assignment, Note
from ..core.parameters import parse_parameters
from ..forward import batch_frequencies
from ..identify.lsq import fit_lsq, local_fit
from ..identify.problem import Measurement, Problem
from ..identify.result import IdentificationResult
from .hypotheses import Hypothesis, applicable, build, clear_position, free_positions, unmodeled_name

#: Unmodeled attachments kept from the profile scan as starts of the full fit.
PROFILE_STARTS = 3
#: Points of the profile scan over the span (about half of them on a symmetric configuration), at least;
#: more where high modes are measured (profile_points).
PROFILE_POINTS = 17
#: Function evaluations of one local fit of the profile scan (a start, not an estimate).
PROFILE_NFEV = 30
#: Tolerance of the local fits: parameters to 1e-10 relative, far below their uncertainty.
TOL = 1e-10


@dataclass
class HypothesisFit:
    """One fitted hypothesis.

    Attributes
    ----------
    hypothesis : Hypothesis
    result : IdentificationResult or None
        None for the nominal model (nothing fitted).
    predicted : ndarray
        Model frequencies of every measured frequency (tests in order), Hz.
    chi2 : float
    aicc : float
    rms_error : float
        Root mean square of the relative errors, %.
    cv_rms_error : float or None
        Leave-one-mode-out prediction error, % (None when a fold has fewer
        data than parameters).
    notes : list of Note
        Of the fit (values in SI units, :func:`in_si_units`) and the
        warnings it raised (``kind="warning"``).
    profile : list of (position m, χ²), optional
        The profile scan of an unmodeled attachment's position.
    failure : str or None
        Why the fit failed (it then ranks last: χ² and AICc infinite): an
        exception, or the final fit stopped at a bound of the search (the
        :mod:`stcs_ident.identify.bounds` rule, which names the parameter and
        the bound).
    penalty : float
        How implausible the departures are (:func:`prior_penalty`: −2 log of
        the priors that the tolerances of the nominal values give, and the
        Occam factor of an unmodeled attachment's position, at the
        estimate). The estimate is the data's alone (least squares);
        ``aicc`` counts the penalty beside ``chi2``, so that of hypotheses the
        frequencies cannot tell apart the more plausible one ranks first.
    epsilon : float
        The relative model error per frequency of :mod:`.model_error` (0
        when the data need none); ``aicc`` is then that of the likelihood
        with it.
    minima : list of dict
        The best distinct points of the profile scan (SI values by (kind,
        member)): the starts of pairs that contain this effect.
    terms : ndarray or None
        Each measured frequency's term of χ² (its squared normalised
        residual), tests in order; None when the fit failed.
    sigma : ndarray or None
        The measured frequencies' uncertainties the terms are normalised by.
    """

    hypothesis: Hypothesis
    result: IdentificationResult | None
    predicted: np.ndarray
    chi2: float
    aicc: float
    rms_error: float
    cv_rms_error: float | None = None
    notes: list[Note] = field(default_factory=list)
    profile: list[tuple[float, float]] = field(default_factory=list)
    minima: list[dict] = field(default_factory=list)
    failure: str | None = None
    penalty: float = 0.0
    epsilon: float = 0.0
    terms: np.ndarray | None = None
    sigma: np.ndarray | None = None

    def terms_with(self, epsilon: float) -> np.ndarray | None:
        """The terms with a relative model error ε per frequency: r² σ² / (σ² + (ε f)²)."""
        if self.terms is None or self.sigma is None or epsilon <= 0:
            return self.terms
        return self.terms * self.sigma**2 / (self.sigma**2 + (epsilon * self.predicted) ** 2)

    @property
    def effects(self) -> tuple[str, ...]:
        return self.hypothesis.effects

    @property
    def n_parameters(self) -> int:
        return len(self.hypothesis.parameters)

    def values(self) -> dict[tuple[str, str | None], float]:
        """SI value of every parameter, keyed by (kind, member)."""
        if self.result is None:
            return {}
        return {(p.kind, p.member): float(v) for p, v in zip(self.result.parameters, self.result.values)}


def prior_widths(campaign: Campaign, hypothesis: Hypothesis, parameters: Sequence | None = None) -> list:
    """Prior width (variable units, or None) of each parameter: the tolerance of the nominal value it
    changes, as its effect declares it and the campaign's ``[tolerance]`` overrides it."""
    owner = dict(zip((id(p) for p in hypothesis.parameters), hypothesis.owners))
    out = []
    for p in hypothesis.parameters if parameters is None else parameters:
        effect = owner[id(p)]
        out.append(registry.get(effect).prior_width(p, registry.tolerance(campaign, effect)))
    return out


def hypothesis_problem(hypothesis: Hypothesis, measurements: Sequence[Measurement], tension_model: str,
                       parameters: Sequence | None = None) -> Problem:
    """The identification problem of a hypothesis (or of some of its ``parameters``)."""
    chosen = hypothesis.parameters if parameters is None else tuple(parameters)
    return Problem(hypothesis.campaign, measurements, chosen, tension_model)


def search_cost(length: float, sigma_x: float) -> float:
    """The Occam factor of finding an attachment's position on a span of ``length`` to ``sigma_x`` (m):
    2 ln(l / (√(2π) σ_x)) − 2 (the 2 that AICc already charges for the parameter taken off), never below 0;
    inf when ``sigma_x`` is not a positive number."""
    if not (math.isfinite(sigma_x) and sigma_x > 0):
        return math.inf
    return max(0.0, 2.0 * math.log(length / (math.sqrt(2 * math.pi) * sigma_x)) - 2.0)


def prior_penalty(hypothesis: Hypothesis, estimate: np.ndarray, uncertainty: np.ndarray | None = None,
                  located: Mapping[str, float] | None = None) -> float:
    """How implausible the departures a hypothesis needs are, at ``estimate`` (−2 log of their prior).

    - A parameter whose nominal value has a tolerance t: 2 ln(1 + ((x − nominal)/t)²), a Cauchy prior of
      scale t. Within the tolerance a departure costs little (at most 2 ln 2); far beyond it the cost
      grows only logarithmically (a shift of 25 t costs 13, of 500 t 25), so that decisive frequencies
      still win over a recorded value, while of hypotheses they cannot separate the one with the smaller
      departures does.
    - The position of an unmodeled attachment, known only to lie on the span: the Occam factor of a
      search (:func:`search_cost`, σ_x its standard deviation). A position the data pin down to 1 cm on a
      120 m stay costs about 15: a point attachment found anywhere has to earn its place. Without a
      finite σ_x the search is not charged.
    - A recorded attachment's position or mass far off its record (a gross error: a position measured
      from the wrong end, a bracket left out of the mass) costs at most what an unrecorded attachment
      found at the same place would: the search cost of its position (``located``: the σ_x, m, that the
      data give the position of each recorded attachment whose mass is free). A recorded damper found
      9.6 m from its record is no less plausible than an unknown mass of the damper's size found there.
    """
    total = 0.0
    length = hypothesis.campaign.cable.length
    located = located or {}
    sigma = np.full(len(hypothesis.parameters), np.nan) if uncertainty is None else np.asarray(uncertainty, float)
    for p, x, s, width in zip(hypothesis.parameters, estimate, sigma,
                              prior_widths(hypothesis.campaign, hypothesis)):
        if width is not None:
            cost = 2.0 * math.log1p(((float(x) - p.start) / width) ** 2)
            if p.kind == "position" and not p.slots and math.isfinite(s) and s > 0:
                cost = min(cost, search_cost(length, float(p.value_uncertainty(x, s))))
            elif p.kind == "mass" and not p.slots and p.member in located:
                cost = min(cost, search_cost(length, located[p.member]))
            total += cost
        elif p.kind == "position" and p.slots and math.isfinite(s) and s > 0:
            total += search_cost(length, float(p.value_uncertainty(x, s)))
    return total


def position_uncertainty(campaign: Campaign, measurements: Sequence[Measurement], hypothesis: Hypothesis,
                         values: Mapping[tuple[str, str | None], float], tension_model: str) -> dict[str, float]:
    """σ (m) that the data give the position of each recorded attachment whose mass ``hypothesis`` frees,
    at the fitted ``values`` (SI, by (kind, member)) with that position freed as well: first order, from
    the Jacobian; inf where the data cannot place it. Empty when positions are exact (a tolerance of 0) or
    when the hypothesis frees them already."""
    members = {p.member for p in hypothesis.parameters if p.kind == "mass" and not p.slots}
    tests = [m.test for m in measurements]
    moving = next((e.name for e in registry.effects() if e.parameter_kind == "position" and not e.unmodeled), None)
    if not members or moving is None or moving in hypothesis.effects or applicable(campaign, tests, moving):
        return {}
    positions = {e: values[("position", unmodeled_name(e))] for e in hypothesis.effects
                 if unmodeled_name(e) and ("position", unmodeled_name(e)) in values}
    wider = build(campaign, tests, registry.in_order((*hypothesis.effects, moving)), positions)
    problem = hypothesis_problem(wider, measurements, tension_model)
    x = starts_from(problem, [values], nominal=False)[0]
    J = problem.jacobian(x)
    if not np.all(np.isfinite(J)):
        return {}
    normal = J.T @ J
    length = campaign.cable.length
    out = {}
    for j, q in enumerate(problem.parameters):
        if q.kind == "position" and not q.slots and q.member in members:
            # The conditional precision of the position, the others free (a Schur complement). A position the
            # frequencies do not feel (a mass at midspan: every mode's slope there is 0 or its shape's, and the
            # Jacobian's column is rounding noise) has none; pinv of the whole matrix gave such a column a
            # variance of 0 or of 1e4 m by the noise of the differences, and so a prior cost that moved
            # from one run of the same data to another.
            others = [i for i in range(J.shape[1]) if i != j]
            precision = normal[j, j] - (normal[j, others] @ np.linalg.pinv(normal[np.ix_(others, others)])
                                        @ normal[others, j] if others else 0.0)
            sigma = float(q.value_uncertainty(x[j], 1.0 / math.sqrt(precision))) if precision > 0 else math.inf
            out[q.member] = sigma if sigma < length else math.inf  # beyond the span: the data cannot place it
    return out


def failed_fit(campaign: Campaign, measurements: Sequence[Measurement], effects: Sequence[str], reason: str,
               tension_model: str) -> HypothesisFit:
    """A hypothesis whose fit failed: no estimate, infinite χ² and AICc, ``failure`` the reason."""
    tests = [m.test for m in measurements]
    hyp = build(campaign, tests, effects)
    n = sum(m.modes.size for m in measurements)
    return HypothesisFit(hyp, None, np.full(n, np.nan), math.inf, math.inf, math.nan, failure=reason)


def aicc(chi2: float, n: int, k: int) -> float:
    """Corrected Akaike criterion for least squares with known uncertainties (inf if n ≤ k + 1)."""
    if n - k - 1 <= 0:
        return math.inf
    return chi2 + 2 * k + 2 * k * (k + 1) / (n - k - 1)


def rms_percent(predicted: np.ndarray, measured: np.ndarray) -> float:
    """Root mean square of (predicted − measured) / measured, %."""
    return float(np.sqrt(np.mean(((predicted - measured) / measured * 100.0) ** 2)))


def nominal_prediction(campaign: Campaign, measurements: Sequence[Measurement], tension_model: str) -> np.ndarray:
    """Frequencies of the nominal model at every measured mode, each in its plane."""
    out = []
    for m in measurements:
        atts = campaign.setup(m.test.setup).attachments
        f = np.full(m.modes.size, np.nan)
        for plane in set(m.planes.tolist()):  # each plane's modes from its own model
            here = m.planes == plane
            f[here] = np.asarray(batch_frequencies(campaign.cable, atts, m.test.tension, int(m.modes[here].max()),
                                                   tension_model=tension_model, plane=plane))[m.modes[here] - 1]
        out.append(f)
    return np.concatenate(out)


def data(campaign: Campaign, measurements: Sequence[Measurement], tension_model: str) -> Problem:
    """The diagnosis's data as a problem of the nominal model (the stated tensions free, at their start):
    the frequencies and, with a damper in the model and measured damping ratios, those ratios (every
    hypothesis is judged on the same data, the nominal model included)."""
    tests = [m.test for m in measurements]
    return Problem(campaign, measurements, parse_parameters(campaign, tests, "tension"), tension_model)


def fit_nominal(campaign: Campaign, measurements: Sequence[Measurement], tension_model: str) -> HypothesisFit:
    problem = data(campaign, measurements, tension_model)
    if problem.use_damping:
        f = problem.predict(problem.start)
    else:
        f = nominal_prediction(campaign, measurements, tension_model)
    measured, sigma = problem.measured, problem.sigma
    terms = ((f - measured) / sigma) ** 2
    chi2 = float(np.sum(terms))
    nf = problem.n_frequencies
    rms = rms_percent(f[:nf], measured[:nf])
    hyp = Hypothesis((), campaign, (), ())
    return HypothesisFit(hyp, None, f, chi2, aicc(chi2, measured.size, 0), rms, cv_rms_error=rms, terms=terms,
                         sigma=sigma)


def quietly(fn, notes: list[Note]):
    """Run ``fn`` collecting warnings as notes (the diagnosis reports them, pytest must not fail on them)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn()
    for w in caught:
        note = Note.plain("warning", str(w.message).splitlines()[0])
        if note not in notes:
            notes.append(note)
    return out


def in_si_units(note: Note, parameters: Sequence) -> Note:
    """``note`` with every assignment of a variable of ``parameters`` in its points given in SI units
    (``position_ratio[W1] = 1.02`` → ``position[W1] = 10.05 m``); ratios of tension and the end
    fixity stay as they are."""
    by_name = {p.name: p for p in parameters if p.spec.noted_in_si}

    def convert(a: Assignment) -> Assignment:
        p = by_name.get(a.parameter)
        if p is None or a.unit:
            return a
        label = p.kind if p.member is None else f"{p.kind}[{p.member}]"
        return Assignment(label, float(p.to_value(a.value)), p.unit)

    if not note.points:
        return note
    return note.with_points([convert(a) for a in pt] for pt in note.points)
def starts_from(problem: Problem, seeds: Sequence[Mapping[tuple[str, str | None], float]],
                 nominal: bool = True) -> np.ndarray:
    """Variable vectors of ``problem`` from SI values by (kind, member); missing ones nominal.

    An unmodeled amplitude missing from a seed starts at 1 % of its upper bound rather than
    at zero (a trust-region fit creeps away from a bound slowly).
    """
    start = problem.start.copy()
    for j, p in enumerate(problem.parameters):
        if p.slots and p.spec.amplitude:
            start[j] = 0.01 * problem.upper[j]
    rows = [start] if nominal or not seeds else []
    for seed in seeds:
        x = start.copy()
        for j, p in enumerate(problem.parameters):
            v = seed.get((p.kind, p.member))
            if v is None:
                continue
            x[j] = p.to_variable(v)
        rows.append(np.clip(x, problem.lower, problem.upper))
    return np.unique(np.array(rows), axis=0)


def profile_points(measurements: Sequence[Measurement]) -> int:
    """Points of the profile scan: PROFILE_POINTS, or two per half-wave of the highest measured mode.

    An attachment's effect on mode k varies with its position as sin²(kπx/l),
    with minima l/k apart; a coarser grid can miss the basin of the right
    position (validate_diagnosis stay seed 5504, 15 modes on 120 m: a 288 kg
    mass at 78 m was found as 161 kg at 53 m with 17 points, the model error
    1.6 %, and end_restraint named instead).
    """
    highest = max((int(np.max(m.modes)) for m in measurements if len(m.modes)), default=0)
    return max(PROFILE_POINTS, 2 * highest + 1)


def fit_hypothesis(campaign: Campaign, measurements: Sequence[Measurement], effects: Sequence[str], *,
                   tension_model: str = "uniform", seeds: Sequence[Mapping] = (), symmetric: bool = False,
                   scan: bool = True, max_nfev: int = 200) -> HypothesisFit:
    """Fit the hypothesis ``effects`` (at least one effect) to the measurements.

    ``seeds`` are starts (SI values by (kind, member)); with ``scan`` an
    unmodeled attachment's position is scanned first (the single effects),
    without it its starts come from the seeds (the pairs, seeded with the
    single effects' profile minima).
    """
    tests = [m.test for m in measurements]
    notes: list[Note] = []
    extra = [e for e in effects if unmodeled_name(e)]
    profile: list[tuple[float, float]] = []
    seeds = list(seeds)
    positions: dict[str, float] = {}
    for e in extra:
        given = [s[("position", unmodeled_name(e))] for s in seeds if ("position", unmodeled_name(e)) in s]
        if given:
            positions[e] = given[0]
    minima: list[dict] = []
    if extra and scan:
        scanned = extra[0]
        grid = free_positions(campaign, tests, profile_points(measurements))
        if symmetric:
            grid = grid[grid <= campaign.cable.length / 2 + 1e-9]
        rows = []
        previous: dict = {}
        for x in grid:
            hyp = build(campaign, tests, effects, {**positions, scanned: float(x)}, fixed=(scanned,))
            problem = hypothesis_problem(hyp, measurements, tension_model)
            carried = [previous] if previous else list(seeds)
            amount = (registry.get(scanned).amount_kind, unmodeled_name(scanned))
            fresh = [{**(previous or {}), amount: a}
                     for a in registry.get(scanned).amount_starts(campaign, tests, float(x))]
            starts = starts_from(problem, carried + fresh, nominal=not previous)
            xb, c = quietly(lambda problem=problem, starts=starts: min(
                (local_fit(problem, x0, PROFILE_NFEV, TOL) for x0 in starts), key=lambda r: r[1]), [])
            values = {(p.kind, p.member): float(p.to_value(v)) for p, v in zip(problem.parameters, xb)}
            values[("position", unmodeled_name(scanned))] = float(x)
            previous = values
            rows.append((c, float(x), values))
            profile.append((float(x), c))
        rows.sort(key=lambda r: r[0])
        chosen: list[tuple] = []
        spacing = 1.5 * (grid[1] - grid[0]) if grid.size > 1 else 0.0
        for r in rows:
            if all(abs(r[1] - c[1]) > spacing for c in chosen):
                chosen.append(r)
            if len(chosen) == PROFILE_STARTS:
                break
        positions[scanned] = chosen[0][1]
        minima = [c[2] for c in chosen]
        seeds = minima + seeds
    hyp = build(campaign, tests, effects, positions)
    problem = hypothesis_problem(hyp, measurements, tension_model)
    starts = starts_from(problem, seeds)
    has_position = any(p.kind == "position" and not p.slots for p in problem.parameters)
    options = {} if has_position else {"n_starts": 0}
    result = quietly(lambda: fit_lsq(problem, starts=None if has_position and not seeds else starts,
                                    max_nfev=max_nfev, tol=TOL, **options), notes)
    if has_position and seeds and not extra:  # the scan of recorded attachments' positions, besides the seeds
        other = quietly(lambda: fit_lsq(problem, max_nfev=max_nfev, tol=TOL), [])
        if other.chi2 < result.chi2 * (1 - 1e-9):
            result = other
    notes += [n for n in result.notes if n not in notes]
    notes = [in_si_units(note, problem.parameters) for note in notes]
    if result.failure is not None:
        # The final fit stopped at a bound of the search: no estimate, so the hypothesis failed (ranked last,
        # never a cause). The profile scan's points may touch bounds; only this fit counts.
        failed = failed_fit(campaign, measurements, effects, str(in_si_units(result.failure, problem.parameters)),
                            tension_model)
        failed.notes, failed.profile, failed.minima = notes, sorted(profile), minima
        return failed
    n = problem.n_data
    predicted = problem.predict(result.estimate)
    terms = ((predicted - problem.measured) / problem.sigma) ** 2
    chi2 = float(np.sum(terms))
    located = position_uncertainty(campaign, measurements, hyp,
                                   {(p.kind, p.member): float(p.to_value(v))
                                    for p, v in zip(problem.parameters, result.estimate)}, tension_model)
    penalty = prior_penalty(hyp, result.estimate, result.uncertainty, located)
    fit = HypothesisFit(hyp, result, predicted, chi2, aicc(chi2 + penalty, n, len(hyp.parameters)),
                        rms_percent(predicted[:problem.n_frequencies], problem.measured[:problem.n_frequencies]),
                        notes=notes, profile=sorted(profile),
                        minima=minima, penalty=penalty, terms=terms, sigma=problem.sigma)
    return fit


def mirror_symmetric(campaign: Campaign, measurements: Sequence[Measurement], tension_model: str) -> bool:
    """Whether an extra mass at x and at l − x give the same frequencies (a configuration symmetric
    about midspan), checked numerically on the measured tests' setups."""
    tests: list[Test] = [m.test for m in measurements]
    length = campaign.cable.length
    used = {t.setup for t in tests}
    f = []
    for x in (0.31 * length, 0.69 * length):
        probe = Attachment("(probe mass)", clear_position(campaign, tests, x),
                           mass=0.05 * campaign.cable.mass_per_length * length)
        setups = tuple(replace(s, attachments=(*s.attachments, probe)) if s.name in used else s
                       for s in campaign.setups)
        f.append(nominal_prediction(replace(campaign, setups=setups), measurements, tension_model))
    return bool(np.allclose(f[0], f[1], rtol=1e-9, atol=0))
