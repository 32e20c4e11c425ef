"""One entry point for both methods: :func:`identify`."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

# Imported for its registrations: the effects' names (bending_stiffness, ...) become aliases of their
# parameter kinds, which parse_parameters accepts.
from .. import effects  # noqa: F401
from ..core.errors import InputError
from ..core.model import Campaign
from ..core.notes import Note
from ..core.parameters import parse_parameters
from ..core.settings import Settings
from .nuisance import nuisance_parameters
from .problem import Problem, gather_measurements
from .result import IdentificationResult

METHODS = ("lsq", "contour")


def identify(campaign: Campaign, tests: Sequence[str] | None = None, params: str | Iterable[str] = "tension,EI", *,
             method: str = "lsq", picked: Mapping[str, object] | None = None,
             bounds: Mapping[str, tuple[float, float]] | None = None, tension_model: str = "uniform",
             scale_rule: str = "auto", tolerances: bool = True, **options) -> IdentificationResult:
    """Correct uncertain model parameters from measured natural frequencies.

    Parameters
    ----------
    campaign : Campaign
    tests : list of str, optional
        Tests fitted together (default: every test with measured
        frequencies or a record; the others are skipped and listed in
        ``result.skipped``). A tension is one parameter per test; EI,
        length, end stiffness and the attachments of a setup are shared.
    params : str or iterable of str
        Free parameters, e.g. ``"tension,EI"``, ``"position[W1]"``,
        ``"tension,EI,position"`` (see
        :func:`~stcs_ident.core.parameters.parse_parameters`).
    method : {"lsq", "contour"}
        Weighted least squares (any number of parameters), or the source
        paper's contour intersection (exactly two parameters).
    picked : mapping, optional
        {test: spectra or :class:`~stcs_ident.identify.problem.Measurement`}
        replacing a test's table (its uncertainties become the weights).
    bounds : mapping, optional
        {parameter: (lower, upper)} in variable units.
    tension_model : {"uniform", "per-segment", "none"}
    scale_rule : {"auto", "birge", "never"}
        When to scale the covariance by the reduced χ².
    tolerances : bool
        Carry the tolerances of the parameters held fixed (the campaign's ``[tolerance]``: EI, length,
        positions, masses, damper coefficients, the tensions not fitted) into the standard deviations of
        those fitted (:mod:`~stcs_ident.identify.nuisance`; a ``tolerances_propagated`` note lists them).
        Off: the standard deviations rest on the frequency uncertainties alone, as if every value held
        fixed were exact.
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
        frequencies than free parameters), ``bounds.<parameter>``.

    Warns
    -----
    IdentifiabilityWarning
        When parameters are not identifiable from the data.
    """
    if method not in METHODS:
        raise InputError(f"must be one of {', '.join(METHODS)}, got {method!r}", field="method")
    measurements, skipped = gather_measurements(campaign, tests, picked)
    parameters = parse_parameters(campaign, [m.test for m in measurements], params, bounds)
    settings = Settings(tension_model=tension_model, scale_rule=scale_rule)
    nuisance = nuisance_parameters(campaign, [m.test for m in measurements], parameters) if tolerances else ()
    problem = Problem(campaign, measurements, parameters, settings.tension_model, nuisance=nuisance)
    if method == "lsq":
        from .lsq import fit_lsq

        result = fit_lsq(problem, settings=settings, **options)
    else:
        from .contour import fit_contour

        result = fit_contour(problem, settings=settings, **options)
    if skipped:
        from dataclasses import replace

        note = Note.make("skipped", "skipped (nothing to identify from): {tests}",
                         tests=", ".join(f"{n} ({r})" for n, r in skipped))
        result = replace(result, skipped=tuple(skipped), notes=result.notes + (note,))
    return result
