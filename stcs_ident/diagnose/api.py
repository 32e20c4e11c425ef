"""Diagnosis: does the nominal model explain the data, and if not, which effect is missing?

:func:`diagnose` fits the nominal model, every single effect of the
vocabulary, every pair and the baseline (tension + EI) plus each further
effect (:mod:`.hypotheses`, :mod:`.fitting`), ranks them by AICc (with the
plausibility of their departures from the nominal values and, when no
hypothesis reaches the measurement uncertainty, a model error),
cross-validates each by leaving one mode out, names the cause and the
corrections (:mod:`.selection`) and predicts each test from the others.
"""

from __future__ import annotations

import itertools
import os
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import numpy as np

from ..core import kinds
from ..core.errors import InputError
from ..core.model import Campaign, Test, has_dampers
from ..core.notes import Note
from ..core.settings import Settings
from ..effects import registry
from ..forward.compare import ForwardResult, compare_forward
from ..identify.measurement import with_record_spectra, without_doubtful
from ..identify.plausibility import check_plausibility as plausible
from ..identify.plausibility import check_records
from ..identify.problem import Measurement, gather_measurements, picked_planes, reset_warm_starts
from .cross_validation import cross_validate, cross_validate_tests
from .fitting import (
    HypothesisFit,
    aicc,
    data,
    failed_fit,
    fit_hypothesis,
    fit_nominal,
    mirror_symmetric,
)
from .hypotheses import applicable, build, hypothesis_sets, parse_effects, unmodeled_name
from .model_error import fit_epsilon
from .result import Diagnosis
from .selection import BASELINE, baseline_fit, explains, needs_model_error, select

Progress = Callable[[int, int, str], None]

#: Largest number of worker processes by default.
MAX_WORKERS = 8


def diagnose(campaign: Campaign, tests: Sequence[str] | None = None, *, effects: str | Sequence[str] | None = None,
             picked: Mapping[str, object] | None = None, max_effects: int = 2, tension_model: str = "uniform",
             progress: Progress | None = None, workers: int | None = None,
             all_hypotheses: bool = False, check_plausibility: bool = True) -> Diagnosis:
    """Diagnose the nominal model of ``campaign`` against its measured frequencies.

    Parameters
    ----------
    campaign : Campaign
    tests : list of str, optional
        Tests to use (default every test with frequencies or a record; the
        others are skipped and listed).
    effects : str or list of str, optional
        Effects of the vocabulary to consider (default all of
        :func:`stcs_ident.effects.names`).
    picked : mapping, optional
        {test: spectra or Measurement} replacing a test's table. Modes of
        spectra whose number is flagged doubtful are left out (and said so
        in the notes): a wrong number would pass for a model error.
    max_effects : int
        Largest number of effects combined in one hypothesis (1 or 2).
    tension_model : {"uniform", "per-segment", "none"}
    progress : callable(k, n, label), optional
        Called as each hypothesis fit is done (k of n).
    workers : int, optional
        Processes fitting hypotheses in parallel (default: the CPUs this
        process may use, at most :data:`MAX_WORKERS`; 1 fits in this process).
    all_hypotheses : bool
        Fit every pair even when the nominal model explains the data (by
        default only the single effects and the baseline are then fitted:
        no pair can change an empty cause).
    check_plausibility : bool
        Refuse, before any fit, a campaign whose nominal model is
        implausibly far from the measured frequencies (a unit slip:
        :func:`~stcs_ident.identify.plausibility.check_plausibility`).

    Returns
    -------
    Diagnosis
        With the nominal comparison (taut string, pinned beam, DSM against
        the measured frequencies) computed once here, for the report.

    Raises
    ------
    InputError
        ``field="max_effects"`` or ``"tension_model"`` for a setting out of
        its range; ``field="effects"`` for an unknown effect or one that has nothing
        to act on in the measured tests (an attachment effect when no
        measured test's setup has an attachment); ``field="frequencies"``
        when there are fewer measured frequencies than the smallest
        hypothesis needs; ``field="test"`` for unknown tests or no data;
        the implausible field (``test[<name>].tension``,
        ``cable.mass_per_length``) when the nominal model is far from the
        measurement.

    A hypothesis whose final fit stops at a bound of the search is a failed
    hypothesis (``failure`` names the parameter and the bound), ranked last
    and never the cause. On a bare cable (nominal EI = 0) ``bending_stiffness``
    fits EI as an absolute value in N m² (a note says so).
    """
    started = time.perf_counter()
    requested = effects is not None
    names = parse_effects(effects)
    settings = Settings(tension_model=tension_model, max_effects=max_effects, all_hypotheses=all_hypotheses)
    given = dict(picked or {})
    if check_plausibility:  # the records' own scale first: a slip bends the numbering to the wrong nominal
        given = with_record_spectra(campaign, tests, given)
        check_records(campaign, given, settings.tension_model)
    picked, excluded = without_doubtful(campaign, given)
    measurements, skipped = gather_measurements(campaign, tests, picked, excluded)
    measured_tests = [m.test for m in measurements]
    seen = [as_measured(m) for m in measurements]  # the tests with the modes (and planes) measured
    notes: list[Note] = list(excluded)
    usable = []
    for e in names:
        why = applicable(campaign, seen, e)
        if why is None or (requested and registry.get(e).opt_in and registry.tolerance(campaign, e) != 0):
            usable.append(e)
        elif requested:
            raise InputError(why, field="effects")
        elif not registry.get(e).quiet:
            notes.append(Note.make("not_considered", "not considered: {reason}", reason=why))
    if check_plausibility:  # after the options' checks (an unknown or inapplicable effect is named first)
        plausible(campaign, measurements, settings.tension_model)
    # The damping ratios are data, for the nominal model and every hypothesis alike, where a damper is in
    # question: a recorded damper, or a missing one asked for.
    with_damping = (any(has_dampers(campaign.setup(m.test.setup).attachments) for m in measurements)
                    or any("coefficient" in (registry.get(e).parameter_kind, getattr(registry.get(e), "amount_kind", None))
                           for e in usable))
    measurements = [replace(m, damping_is_data=with_damping) for m in measurements]
    n = data(campaign, measurements, settings.tension_model).n_data  # the frequencies (and damping ratios)
    sizes = {e: len(build(campaign, measured_tests, (e,)).parameters) for e in usable}
    baseline = tuple(e for e in BASELINE if applicable(campaign, seen, e) is None)
    for e in baseline:  # fitted as the reference of the gain even when not among the effects considered
        sizes.setdefault(e, len(build(campaign, measured_tests, (e,)).parameters))
    smallest = min(sizes[e] for e in usable) if usable else 0
    if not usable or n < smallest + 2:
        raise InputError(f"{n} measured frequencies, but the smallest hypothesis ({smallest} parameter(s)) needs "
                         f"at least {smallest + 2} (AICc needs n > k + 1)", field="frequencies")
    sets = [s for s in hypothesis_sets(usable, settings.max_effects) if sum(sizes[e] for e in s) + 2 <= n]
    dropped = len(hypothesis_sets(usable, settings.max_effects)) - len(sets)
    if dropped:
        notes.append(Note.make("too_many_parameters", "{value} hypotheses not fitted: more parameters than the "
                               "{n} frequencies allow", value=dropped, n=n))
    if baseline and baseline not in sets and sum(sizes[e] for e in baseline) + 2 <= n:
        sets.append(baseline)
    if campaign.cable.EI <= 0 and any(registry.get(e).parameter_kind == "EI" for s in sets for e in s):
        notes.append(Note.make("EI_absolute", "the nominal EI is 0 (a bare cable): bending_stiffness fits EI as "
                               "an absolute value, from 0 to {value:.4g} {unit} (where xi = l sqrt(T/EI) falls to 2 "
                               "at the largest tension)", value=kinds.get("EI").zero_upper(campaign), unit="N m^2"))
    symmetric = mirror_symmetric(campaign, measurements, settings.tension_model)
    fits: dict[tuple[str, ...], HypothesisFit] = {}
    timings: dict[tuple[str, ...], float] = {}
    done = 0
    # Single effects first (their estimates and profile minima seed the pairs, the pairs the baseline plus
    # one), each stage in parallel.
    stages = [[s for s in sets if len(s) <= 1], [s for s in sets if len(s) == 2], [s for s in sets if len(s) > 2]]
    total = len(sets)
    for i, stage in enumerate(stages):
        if i >= 1 and not settings.all_hypotheses and explains(fits[()], n):
            # No pair can change an empty cause: fit only the baseline, which the gain needs.
            kept = [s for s in stage if s == baseline]
            if len(stage) > len(kept):
                notes.append(Note.make("pairs_not_fitted", "the nominal model explains the data: {value} "
                                       "{what} of effects not fitted (they cannot change an empty cause; "
                                       "all_hypotheses fits them)", value=len(stage) - len(kept),
                                       what="pairs" if i == 1 else "combinations"))
            total -= len(stage) - len(kept)
            stage = kept
        if _workers(workers) > 1:  # the longest fits first, so that no worker is left with one at the end
            stage = sorted(stage, key=lambda s: -_expected_seconds(s, timings))
        jobs = [(campaign, measurements, s, settings.tension_model, symmetric,
                 _seeds(fits, s, campaign.cable.length if symmetric else None) if len(s) > 1 else [])
                for s in stage]
        for s, fit, seconds in _map(_fit_job, jobs, workers):
            fits[s], timings[s] = fit, seconds
            done += 1
            if progress is not None:
                progress(done, total, " + ".join(s) if s else "nominal")
    # In the order of a serial run, whatever order the workers finished in: whatever reads the fits in
    # turn (the ranking's ties, the report's tables) must not depend on the number of CPUs or the load.
    order = {s: (len(s), i) for i, s in enumerate(sets)}
    fits = {s: fits[s] for s in sorted(fits, key=lambda s: order.get(s, (len(s), len(sets))))}
    timings = {s: timings[s] for s in fits}
    reset_warm_starts()  # what follows in this process must not depend on which jobs ran here
    if needs_model_error(fits, n):
        reference = data(campaign, measurements, settings.tension_model)  # the frequencies (and damping ratios)
        for fit in fits.values():
            with_model_error(fit, reference.measured, reference.sigma)
    selection = select(fits, n, settings.max_effects)
    test_cv = _test_cv(fits, selection, measurements, settings.tension_model)
    comparison = nominal_comparison(campaign, measurements, given, settings)
    return Diagnosis(campaign=campaign, measurements=tuple(measurements), fits=fits, selection=selection,
                     symmetric=symmetric, skipped=tuple(skipped), notes=tuple(notes), timings=timings,
                     elapsed=time.perf_counter() - started, considered=tuple(usable), settings=settings,
                     comparison=comparison, test_cv=test_cv,
                     spectra=_record_spectra(given))


def _record_spectra(given: Mapping) -> tuple:
    """The picked spectra of records among ``given`` (the report draws them). A TestSpectra exists only once its
    module is loaded: a table-only diagnosis does not load the peak picking (0.4 s of SciPy) to find none."""
    pipeline = sys.modules.get("stcs_ident.spectra.pipeline")
    return () if pipeline is None else tuple(p for p in given.values() if isinstance(p, pipeline.TestSpectra))


def with_model_error(fit: HypothesisFit, measured: np.ndarray, sigma: np.ndarray) -> None:
    """Give a fitted hypothesis its model error ε (:mod:`.model_error`) and the AICc of the likelihood with
    it (ε one more parameter); ``measured`` and ``sigma`` are the measured frequencies and their
    uncertainties, tests in order."""
    if fit.failure is not None or not np.all(np.isfinite(fit.predicted)):
        return
    fit.epsilon, dev = fit_epsilon(fit.predicted - measured, sigma, measured)
    fit.aicc = aicc(dev + fit.penalty, measured.size, fit.n_parameters + 1)


def _test_cv(fits: dict, selection, measurements: Sequence[Measurement], tension_model: str) -> dict[str, float]:
    """Leave-one-test-out prediction error (%) of the nominal model, the baseline and the corrected model."""
    if len(measurements) < 2:
        return {}
    chosen = {"nominal": (), "corrected": selection.fitted}
    base = baseline_fit(fits)
    if base is not None:
        chosen["baseline"] = base.effects
    out = {}
    for label, key in chosen.items():
        try:
            value = cross_validate_tests(fits[key], measurements, tension_model)
        except Exception:  # noqa: BLE001 (a failed fold leaves this figure out; the diagnosis stands)
            value = None
        if value is not None:
            out[label] = value
    return out


def nominal_comparison(campaign: Campaign, measurements: Sequence[Measurement], picked: Mapping[str, object],
                       settings: Settings) -> ForwardResult:
    """The ``forward`` comparison (taut string, pinned beam, DSM) of the measured tests with the nominal model.

    The measured frequencies are the picked ones where a test has them
    (doubtful modes included: the comparison shows what was picked), else
    those the diagnosis used when they are not the campaign's table, else
    the table (its reference columns then checked as well).
    """
    names = [m.name for m in measurements]
    given = {name: (p.modes, p.frequencies, picked_planes(p)) for name, p in picked.items() if name in names}
    for m in measurements:
        test = campaign.test(m.name)
        table = dict(zip(zip(test.planes or ("in",) * len(test.modes or ()), test.modes or ()), test.frequencies or ()))
        if m.name not in given and any(table.get((str(p), int(k))) != float(f)
                                       for p, k, f in zip(m.planes, m.modes, m.frequencies)):
            given[m.name] = (m.modes, m.frequencies, tuple(map(str, m.planes)))
    return compare_forward(campaign, names, None, settings.tension_model, picked=given)


def as_measured(m: Measurement) -> Test:
    """``m``'s test holding the modes, frequencies and planes measured (picked from a record, or the table), for
    what an effect asks of the tests (an effect of one plane needs modes of both)."""
    return replace(m.test, frequencies=tuple(map(float, m.frequencies)), modes=tuple(map(int, m.modes)),
                   planes=tuple(map(str, m.planes)), uncertainty=None, reference=())


def _seeds(fits: dict, effects: tuple[str, ...], mirror: float | None = None) -> list[dict]:
    """Starts of a combination: each sub-combination's estimate (one effect fewer) and profile minima,
    completed by the other sub-combinations' estimates.

    ``mirror``: the span on a configuration symmetric about midspan, where the single effects' positions are
    found in [0, l/2] only; each start is then also tried with one unmodeled attachment mirrored (x → l − x),
    so that a pair with its attachments on opposite halves is reached (han2020: a mass at 14.5 m with a
    support at 3.2 m fits χ² 12 978, the pair of both in the first half 13 228).
    """
    subs = [fits[s] for s in itertools.combinations(effects, len(effects) - 1)
            if s in fits and fits[s].failure is None]
    seeds = []
    for i, fit in enumerate(subs):
        others: dict = {}
        for j, other in enumerate(subs):
            if j != i:
                others.update(other.values())
        for point in [fit.values(), *fit.minima]:
            seeds.append({**others, **point})
    members = [("position", unmodeled_name(e)) for e in effects if unmodeled_name(e)]
    if mirror is not None and len(members) > 1:
        seeds += [{**seed, key: mirror - seed[key]} for seed in list(seeds) for key in members[1:] if key in seed]
    return seeds

def _fit_job(job) -> tuple[tuple[str, ...], HypothesisFit, float]:
    """Fit and cross-validate one hypothesis (runs in a worker process)."""
    campaign, measurements, effects, tension_model, symmetric, seeds = job
    t0 = time.perf_counter()
    reset_warm_starts()  # the hypothesis's result depends on it alone, in whichever worker it runs
    if not effects:
        fit = fit_nominal(campaign, measurements, tension_model)
        return effects, fit, time.perf_counter() - t0
    try:
        fit = fit_hypothesis(campaign, measurements, effects, tension_model=tension_model, seeds=seeds,
                             symmetric=symmetric, scan=len(effects) == 1)
    except Exception as err:  # noqa: BLE001 (one hypothesis failing must not abort the diagnosis: it is reported)
        reason = " ".join(str(err).split()) or type(err).__name__
        fit = failed_fit(campaign, measurements, effects, f"{type(err).__name__}: {reason}", tension_model)
        return effects, fit, time.perf_counter() - t0
    try:
        fit.cv_rms_error = cross_validate(fit, measurements, tension_model)
    except Exception as err:  # noqa: BLE001 (as above: reported, the diagnosis goes on)
        fit.notes.append(Note.plain("cv_failed", f"cross-validation failed ({type(err).__name__}: "
                                                 f"{' '.join(str(err).split())})"))
        fit.cv_rms_error = None
    return effects, fit, time.perf_counter() - t0


def _expected_seconds(effects: tuple[str, ...], timings: Mapping[tuple[str, ...], float]) -> float:
    """What a hypothesis's fit is expected to take, for the order of a parallel stage: the sum of its
    sub-combinations' times (one effect fewer), fitted in the stage before; for a single effect 2 with an
    unmodeled attachment (its position scanned first), else 1. The order does not change the fits."""
    if len(effects) <= 1:
        return 2.0 if effects and unmodeled_name(effects[0]) else float(len(effects))
    return sum(timings.get(s, 0.0) for s in itertools.combinations(effects, len(effects) - 1))


def _workers(workers: int | None) -> int:
    """The number of worker processes ``workers`` asks for (None: :func:`default_workers`)."""
    return default_workers() if workers is None else max(1, int(workers))


def default_workers() -> int:
    """Worker processes used by default: the CPUs this process may use, at most :data:`MAX_WORKERS`."""
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        n = os.cpu_count() or 1
    return max(1, min(n, MAX_WORKERS))


def _map(fn, jobs: list, workers: int | None):
    """``fn`` over ``jobs``, results as they finish; in worker processes when more than one is useful."""
    workers = _workers(workers)
    if workers == 1 or len(jobs) < 2:
        yield from map(fn, jobs)
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    context = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)
    with ProcessPoolExecutor(min(workers, len(jobs)), mp_context=context) as pool:
        futures = [pool.submit(fn, job) for job in jobs]
        for future in as_completed(futures):
            yield future.result()
