"""One entry point for both methods: :func:`identify`."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

# Imported for its registrations: the effects' names (bending_stiffness, ...) become aliases of their
# parameter kinds, which parse_parameters accepts.
from .. import effects  # noqa: F401
from ..core.errors import BoundError, InputError
from ..core.model import Campaign
from ..core.notes import Note
from ..core.parameters import parse_parameters
from ..core.settings import Settings
from .measurement import without_doubtful
from .nuisance import nuisance_parameters
from .problem import Problem, gather_measurements, reset_warm_starts
from .result import IdentificationResult

METHODS = ("lsq", "contour")


def identify(campaign: Campaign, tests: Sequence[str] | None = None, params: str | Iterable[str] | None = None, *,
             method: str = "lsq", picked: Mapping[str, object] | None = None,
             bounds: Mapping[str, tuple[float, float]] | None = None, tension_model: str = "uniform",
             scale_rule: str = "auto", tolerances: bool = True, check_plausibility: bool = True,
             **options) -> IdentificationResult:
    """Correct uncertain model parameters from measured natural frequencies.

    Parameters
    ----------
    campaign : Campaign
    tests : list of str, optional
        Tests fitted together (default: every test with measured
        frequencies or a record; the others are skipped and listed in
        ``result.skipped``). A tension is one parameter per test; EI,
        length, end stiffness and the attachments of a setup are shared.
    params : str or iterable of str, optional
        Free parameters, e.g. ``"tension,EI"``, ``"position[W1]"``,
        ``"tension,EI,position"`` (see
        :func:`~stcs_ident.core.parameters.parse_parameters`). Default
        (:func:`default_params`): ``"tension,EI"`` when the data carry EI (a
        test with two or more measured modes), else ``"tension"`` with a
        note that EI is held at its nominal value. On a bare cable (EI = 0)
        EI is freed as an absolute value in N m².
    method : {"lsq", "contour"}
        Weighted least squares (any number of parameters), or the source
        paper's contour intersection (exactly two parameters).
    picked : mapping, optional
        {test: spectra or :class:`~stcs_ident.identify.problem.Measurement`}
        replacing a test's table (its uncertainties become the weights).
        Modes of spectra (given or computed from a test's record) whose
        number is doubtful are left out, with a ``doubtful_modes`` note; a
        test with none sure is skipped, or refused when named in ``tests``.
    bounds : mapping, optional
        {parameter: (lower, upper)} in variable units; they win over the
        campaign's ``[bounds]``, which win over the kinds' defaults.
    tension_model : {"uniform", "per-segment", "none"}
    scale_rule : {"auto", "birge", "never"}
        When to scale the covariance by the reduced χ².
    tolerances : bool
        Carry the tolerances of the parameters held fixed (the campaign's ``[tolerance]``: EI, length,
        positions, masses, damper coefficients, the tensions not fitted) into the standard deviations of
        those fitted (:mod:`~stcs_ident.identify.nuisance`; a ``tolerances_propagated`` note lists them).
        Off: the standard deviations rest on the frequency uncertainties alone, as if every value held
        fixed were exact.
    check_plausibility : bool
        Refuse, before any fit, a campaign whose nominal model is
        implausibly far from the measured frequencies (a unit slip:
        :func:`~stcs_ident.identify.plausibility.check_plausibility`).
        False for a user who means it.
    **options :
        Passed to :func:`~stcs_ident.identify.lsq.fit_lsq` (``starts``,
        ``n_starts``, ``max_nfev``, ``seed``) or
        :func:`~stcs_ident.identify.contour.fit_contour` (``grid``,
        ``ranges``).

    Returns
    -------
    IdentificationResult

    Raises
    ------
    InputError
        Naming the field: ``method``, ``tension_model``, ``scale_rule``, ``test``,
        ``test[<name>].frequencies`` (a selected test with neither
        frequencies nor a record), ``params`` (unknown name, fewer measured
        frequencies than free parameters), ``bounds.<parameter>``; the
        implausible field (``test[<name>].tension``, ``cable.mass_per_length``)
        when the nominal model is far from the measurement.
    BoundError
        When the fit stopped at a bound of the search (a
        :class:`~stcs_ident.core.errors.ComputationError`): no result. Its
        ``result`` is the failed :class:`IdentificationResult` (``failure``
        names the parameter and the bound; before/after frequencies kept, no
        uncertainties).

    Warns
    -----
    IdentifiabilityWarning
        When parameters are not identifiable from the data.

    Each measured mode is predicted by the model of its plane (a test's ``planes``, or the picked spectra's
    ``mode_planes``; in-plane by default): out of plane without sag-extensibility, so a fit of out-of-plane
    modes alone does not depend on EA.
    """
    if method not in METHODS:
        raise InputError(f"must be one of {', '.join(METHODS)}, got {method!r}", field="method")
    if check_plausibility:  # the records' own scale first: a slip bends the numbering to the wrong nominal
        from .measurement import with_record_spectra
        from .plausibility import check_records

        picked = with_record_spectra(campaign, tests, picked)
        check_records(campaign, picked, tension_model)
    picked, doubt = without_doubtful(campaign, picked)
    measurements, skipped = gather_measurements(campaign, tests, picked, doubt)
    held = None
    if params is None:
        params, held = default_params(measurements)
    parameters = parse_parameters(campaign, [m.test for m in measurements], params, bounds)
    settings = Settings(tension_model=tension_model, scale_rule=scale_rule)
    if check_plausibility:  # after the options' checks: a bad --params is named before the data are judged
        from .plausibility import check_plausibility as check

        check(campaign, measurements, settings.tension_model)

    def run(chosen) -> IdentificationResult:
        free = parameters if chosen is measurements else parse_parameters(
            campaign, [m.test for m in chosen], params, bounds)
        nuisance = nuisance_parameters(campaign, [m.test for m in chosen], free) if tolerances else ()
        problem = Problem(campaign, chosen, free, settings.tension_model, nuisance=nuisance)
        reset_warm_starts()  # the result depends on these inputs alone, not on what this process solved before
        if method == "lsq":
            from .lsq import fit_lsq

            return fit_lsq(problem, settings=settings, **options)
        from .contour import fit_contour

        return fit_contour(problem, settings=settings, **options)

    result = run(measurements)
    if result.failure is not None:
        result = without_failed_tests(result, measurements, run)
    from dataclasses import replace

    if skipped:
        note = Note.make("skipped", "skipped (nothing to identify from): {tests}",
                         tests=", ".join(f"{n} ({r})" for n, r in skipped))
        result = replace(result, skipped=tuple(skipped), notes=result.notes + (note,))
    if held is not None:
        result = replace(result, notes=result.notes + (held,))
    if doubt:
        result = replace(result, notes=result.notes + tuple(doubt))
    if result.failure is not None:
        raise BoundError(str(result.failure), result)
    if campaign.published:  # the published results beside ours: part of the result, as the JSON has them
        from .published import published_comparison

        result = replace(result, published=tuple(published_comparison(campaign, result.summary())))
    return result


#: A joint fit over many tests leaves out at most this share of them (at least one, from three tests on) whose
#: data put it at a bound; more, and the campaign itself is wrong (every stated tension off): the fit fails.
MAX_FAILED_SHARE = 0.25


def without_failed_tests(result: IdentificationResult, measurements, run) -> IdentificationResult:
    """A joint fit stopped at a bound, refitted without the test(s) whose data put it there (issue 36: a joint
    fit over many tests does not fail as a whole because one test's evidence is weak or wrong).

    A bound reached by a test's own parameter (its tension) is that test's failure: it is left out and the rest
    refitted. A bound reached by a shared one (EI) is the failure of the test without which the rest fits (of
    those with two modes or more, which carry EI; the one leaving the smallest reduced χ²). At most
    :data:`MAX_FAILED_SHARE` of the tests (at least one, from three tests on) are left out so; where that does
    not make a fit, the first failure stands. The result lists them in ``failed_tests`` with the reason, and
    says so in a note.
    """
    from dataclasses import replace

    limit = int(MAX_FAILED_SHARE * len(measurements)) if len(measurements) >= 4 else (1 if len(measurements) == 3
                                                                                       else 0)
    current, failed, trial = list(measurements), [], result
    while trial.failure is not None and len(failed) < max(limit, 0):
        name = trial.failure.parameters[0]
        own = [m for m in current if name.endswith(f"[{m.test.name}]")]
        if own:
            choice = (own[0], run([m for m in current if m is not own[0]]))
        else:
            choice = None
            for m in (m for m in current if m.modes.size >= 2):
                attempt = run([k for k in current if k is not m])
                if attempt.failure is None and (choice is None or _reduced(attempt) < _reduced(choice[1])):
                    choice = (m, attempt)
            if choice is None:
                break
        failed.append((choice[0].test.name, str(trial.failure)))
        current, trial = [m for m in current if m is not choice[0]], choice[1]
    if trial.failure is not None or not failed:
        return result
    note = Note.make("tests_failed", "fitted without {tests}: their data put the joint fit at a bound (each "
                     "test's failure, listed in failed_tests; the rest fitted)",
                     tests=", ".join(f"{n} ({why})" for n, why in failed))
    return replace(trial, failed_tests=tuple(failed), notes=(note, *trial.notes))


def _reduced(result: IdentificationResult) -> float:
    return result.chi2 / max(result.dof, 1)


def default_params(measurements) -> tuple[str, Note | None]:
    """The default free parameters: ``"tension,EI"`` when the data carry EI, else ``"tension"`` and a note.

    A tension per test and one EI are one parameter more than the tests: the data carry EI only when some
    test has two or more measured modes (one mode per test gives as many frequencies as tensions, each
    matched exactly whatever EI is).
    """
    if any(m.modes.size >= 2 for m in measurements):
        return "tension,EI", None
    return "tension", Note.make("EI_held", "EI is held at its nominal value: every test has one measured mode, "
                                "as many frequencies as tensions, so the data cannot carry EI as well")
