"""Result objects of the identification step.

:class:`IdentificationResult` is what :func:`~stcs_ident.identify.identify`
returns for either method: the estimates in the dimensionless variables of
the parameters (ratios to nominal, mostly) and in SI units, their
uncertainties, and per test the measured frequencies before and after the
correction (:class:`TestFit`). ``.summary()`` is the ``identify`` JSON
plus optional keys; ``.to_dataframe()`` is the paper's Table 9/10 form.
The tables in words (text and Markdown) and the CSV file are made by
:mod:`stcs_ident.report.identify_tables`, which reads these objects; nothing here
imports it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..core.formatting import percent_error
from ..core.notes import Note
from ..core.parameters import Parameter
from ..core.result import Result
from ..core.settings import Settings

#: Reference columns shown beside the correction: labels containing this word.
SHOWN_REFERENCE = "corrected"


@dataclass(frozen=True)
class TestFit:
    """One test's measured frequencies against the model before and after correction.

    Attributes
    ----------
    name, setup : str
    modes : tuple of int
    measured, uncertainty : ndarray
        Hz; the standard uncertainty used as weight.
    source : str
        Where ``uncertainty`` comes from.
    before, after : ndarray
        Model frequencies (Hz) with the nominal and with the identified
        parameters.
    reference : dict of str to ndarray
        Frequencies computed by others for the same modes (the test's
        ``reference`` columns, e.g. the paper's own corrected values), NaN
        where missing.
    damping : dict of str to ndarray
        With a damper and measured damping ratios: ``measured``,
        ``uncertainty``, ``before`` and ``after`` ratios per mode (NaN where
        not measured; the model's include the fitted own damping of the
        cable). Empty otherwise.
    planes : tuple of str
        The plane of each mode, ``"in"`` or ``"out"`` (empty: all in-plane).
    """

    __test__ = False

    name: str
    setup: str
    modes: tuple[int, ...]
    measured: np.ndarray
    uncertainty: np.ndarray
    source: str
    before: np.ndarray
    after: np.ndarray
    reference: dict[str, np.ndarray] = field(default_factory=dict)
    damping: dict[str, np.ndarray] = field(default_factory=dict)
    planes: tuple[str, ...] = ()

    @property
    def mode_planes(self) -> tuple[str, ...]:
        """The plane of each mode (all ``"in"`` when none was given)."""
        return tuple(self.planes) if self.planes else ("in",) * len(self.modes)

    def reference_error(self, label: str) -> np.ndarray:
        """(reference − measured) / measured × 100 for one reference column."""
        return percent_error(self.reference[label], self.measured)

    @property
    def before_error(self) -> np.ndarray:
        """(before − measured) / measured × 100."""
        return percent_error(self.before, self.measured)

    @property
    def after_error(self) -> np.ndarray:
        """(after − measured) / measured × 100."""
        return percent_error(self.after, self.measured)

    @property
    def rms_before(self) -> float:
        """Root mean square of ``before_error``, %."""
        return float(np.sqrt(np.mean(self.before_error**2)))

    @property
    def rms_after(self) -> float:
        """Root mean square of ``after_error``, %."""
        return float(np.sqrt(np.mean(self.after_error**2)))


@dataclass(frozen=True, repr=False)
class IdentificationResult(Result):
    """Identified parameters with uncertainties, and the fit to every test.

    Parameters are looked up by name (:meth:`value`, :meth:`get`), never by
    position. ``tables()`` holds ``parameters`` (:meth:`parameter_table`,
    the main table a notebook shows) and ``frequencies`` (the paper's Table
    9/10 form, :meth:`to_dataframe`).

    Attributes
    ----------
    method : {"lsq", "contour"}
    parameters : tuple of Parameter
    estimate : ndarray
        The identified variables (ratio to nominal for most kinds; see
        :mod:`stcs_ident.core.parameters`).
    uncertainty : ndarray
        lsq: one standard deviation from the covariance. contour: half the
        extent of the intersection region along each axis.
    covariance, correlation : ndarray or None
        Of the variables (lsq only).
    tests : tuple of TestFit
    chi2 : float
        Σ ((f_model − f_measured)/σ)² at the estimate.
    dof : int
        Measured frequencies minus free parameters.
    covariance_scale : float
        Factor applied to the covariance: the reduced χ² when the misfit is
        larger than the stated uncertainties explain, else 1.
    notes : tuple of Note
        Remarks as records (scaling, parameters at a bound, ambiguity, not
        identifiable, ...); ``str(note)`` says one in words.
    skipped : tuple of (test, reason)
    alternatives : tuple of ndarray
        Other estimates that explain the data equally well (mirror images,
        interchangeable attachments).
    sweep : ContourSweep or None
        The contour method's grids, surfaces and region (for figures).
    settings : Settings
        How the identification was run (tension model, scale rule).
    uncertainty_sources : dict
        With tolerances propagated (:mod:`~stcs_ident.identify.nuisance`): ``frequencies`` and
        ``tolerances``, the two shares of each standard deviation (variable units; their squares add up to
        the variance), and ``held`` ({parameter held fixed: its tolerance as stated}); else empty.
    failure : Note or None
        Why the fit is no result (``kind="fit_at_bound"``: it stopped at a
        bound of the search, naming the parameter and the bound), or None.
        A failed result keeps ``estimate`` (where the fit stopped) and the
        before/after frequencies, but its ``uncertainty`` is NaN: no value
        with a standard deviation is reported. :func:`~stcs_ident.identify.identify`
        raises :class:`~stcs_ident.core.errors.BoundError` carrying it.
    failed_tests : tuple of (test, reason)
        Tests left out of a joint fit because their data put it at a bound
        (:func:`~stcs_ident.identify.api.without_failed_tests`): each one's failure, the rest fitted.
    """

    method: str
    parameters: tuple[Parameter, ...]
    estimate: np.ndarray
    uncertainty: np.ndarray
    covariance: np.ndarray | None
    correlation: np.ndarray | None
    tests: tuple[TestFit, ...]
    chi2: float
    dof: int
    covariance_scale: float = 1.0
    notes: tuple[Note, ...] = ()
    skipped: tuple[tuple[str, str], ...] = ()
    alternatives: tuple[np.ndarray, ...] = ()
    sweep: object | None = field(default=None, repr=False)
    settings: Settings = field(default_factory=Settings)
    uncertainty_sources: dict = field(default_factory=dict)
    failure: Note | None = None
    failed_tests: tuple[tuple[str, str], ...] = ()
    published: tuple[dict, ...] = ()

    main_table = "parameters"

    @property
    def ok(self) -> bool:
        """True unless the fit failed (:attr:`failure`)."""
        return self.failure is None

    @property
    def status(self) -> str:
        """``"ok"`` or ``"failed"``."""
        return "ok" if self.failure is None else "failed"

    def failed(self, failure: Note) -> IdentificationResult:
        """This result marked as failed for ``failure``: the uncertainties become NaN (a fit stopped at a
        bound has no standard deviation worth reporting), the rest stays for the before/after tables."""
        from dataclasses import replace

        return replace(self, failure=failure, uncertainty=np.full(len(self.parameters), np.nan),
                       notes=(failure, *self.notes))

    @property
    def names(self) -> list[str]:
        return [p.name for p in self.parameters]

    def _index(self, name: str) -> int:
        """Place of the parameter called ``name``: its display name (``tension_ratio[T1]``), its kind and
        member (``tension[T1]``), or its kind alone when one parameter has it (``EI``, ``tension``)."""
        for i, p in enumerate(self.parameters):
            if name in (p.name, p.kind if p.member is None else f"{p.kind}[{p.member}]"):
                return i
        same = [i for i, p in enumerate(self.parameters) if p.kind == name]
        if len(same) == 1:
            return same[0]
        known = ", ".join(self.names)
        if same:
            raise KeyError(f"{name!r} names {len(same)} parameters; give the member: {known}")
        raise KeyError(f"no parameter {name!r} (identified: {known})")

    def value(self, name: str) -> tuple[float, float]:
        """(value, uncertainty) in SI units of the parameter called ``name`` (display name such as
        ``tension_ratio[T1]``, ``tension[T1]``, or a kind that one parameter has: ``EI``, ``tension``).

        Raises
        ------
        KeyError
            When no parameter, or more than one, answers to ``name`` (the message lists the names).
        """
        i = self._index(name)
        return float(self.values[i]), float(self.value_uncertainty[i])

    def parameter_table(self) -> pd.DataFrame:
        """One row per parameter: ``parameter`` (display name), ``kind``, ``member``, ``value`` and
        ``uncertainty`` in SI units, ``unit``, ``nominal`` (SI), and the dimensionless ``variable`` the fit
        works in (a ratio to nominal, mostly) with its ``variable_uncertainty``."""
        rows = [{"parameter": p.name, "kind": p.kind, "member": p.member, "value": float(v),
                 "uncertainty": float(vs), "unit": p.unit, "nominal": float(p.nominal),
                 "variable": float(x), "variable_uncertainty": float(s)}
                for p, x, s, v, vs in zip(self.parameters, self.estimate, self.uncertainty, self.values,
                                          self.value_uncertainty)]
        return pd.DataFrame(rows, columns=["parameter", "kind", "member", "value", "uncertainty", "unit", "nominal",
                                           "variable", "variable_uncertainty"])

    def tables(self) -> dict[str, pd.DataFrame]:
        """``parameters`` (:meth:`parameter_table`) and ``frequencies`` (:meth:`to_dataframe`)."""
        return {"parameters": self.parameter_table(), "frequencies": self.to_dataframe()}

    def headline(self) -> str:
        """Method, the first parameters in SI units with their 1σ, and the rms error before and after."""
        shown = [f"{p.kind if p.member is None else f'{p.kind}[{p.member}]'} = {v:.4g} ± {vs:.2g} "
                 f"{p.unit}"
                 for p, v, vs in zip(self.parameters, self.values, self.value_uncertainty)]
        more = f", … ({len(shown)} parameters)" if len(shown) > 3 else ""
        n = sum(len(t.modes) for t in self.tests)
        if self.failure is not None:
            return f"{self.method} failed: {self.failure}"
        return (f"{self.method}, {', '.join(shown[:3])}{more}; rms error {self.rms_before:.3g} % → "
                f"{self.rms_after:.3g} % over {n} frequencies of {len(self.tests)} "
                f"test{'s' if len(self.tests) != 1 else ''}")

    @property
    def reduced_chi2(self) -> float:
        """χ² / dof (NaN when dof is 0)."""
        return self.chi2 / self.dof if self.dof > 0 else math.nan

    @property
    def values(self) -> np.ndarray:
        """The estimates in SI units."""
        return np.array([float(p.to_value(x)) for p, x in zip(self.parameters, self.estimate)])

    @property
    def value_uncertainty(self) -> np.ndarray:
        """The uncertainties in SI units (first order)."""
        return np.array([p.value_uncertainty(float(x), float(s))
                         for p, x, s in zip(self.parameters, self.estimate, self.uncertainty)])

    def get(self, name: str) -> tuple[float, float]:
        """(estimate, uncertainty) of the parameter with this display name."""
        i = self.names.index(name)
        return float(self.estimate[i]), float(self.uncertainty[i])

    def test(self, name: str) -> TestFit:
        return next(t for t in self.tests if t.name == name)

    @property
    def rms_before(self) -> float:
        """rms error (%) over every measured frequency, nominal model."""
        return float(np.sqrt(np.mean(np.concatenate([t.before_error for t in self.tests]) ** 2)))

    @property
    def rms_after(self) -> float:
        """rms error (%) over every measured frequency, corrected model."""
        return float(np.sqrt(np.mean(np.concatenate([t.after_error for t in self.tests]) ** 2)))

    def summary(self) -> dict:
        """Plain data for JSON: the ``identify`` object, with extra keys.

        Extra keys: ``status`` (``"ok"`` or ``"failed"``), ``failure`` (null, or ``reason``,
        ``parameter``, ``side`` and ``bound`` of a fit stopped at a bound; the uncertainties are then
        null), ``values`` and ``value_uncertainty`` (SI units),
        ``uncertainty_kind``, ``correlation``, ``chi2``, ``dof``,
        ``reduced_chi2``, ``covariance_scale``, ``rms_error_before``,
        ``rms_error_after`` (%), ``notes`` (as sentences), ``skipped``, ``alternatives``, ``settings``,
        ``uncertainty_sources`` (with tolerances propagated: each σ's share from the frequencies and from the
        tolerances of the values held fixed, in variable units, and those tolerances),
        and per test ``uncertainty``, ``uncertainty_source`` and ``reference``
        (frequencies computed by others, e.g. the paper's corrected values); ``published``: the campaign's
        published results beside ours (:func:`~stcs_ident.identify.published.published_comparison`, attached by
        :func:`~stcs_ident.identify.identify`; empty when the campaign has none).
        """
        out = {
            "method": self.method,
            "status": self.status,
            "failure": None if self.failure is None else {
                "reason": str(self.failure), "parameter": self.failure.parameters[0],
                **{k: v for k, v in self.failure.data if k in ("side", "bound")}},
            "parameters": _nest(self.parameters, self.estimate, by="key"),
            "uncertainty": _nest(self.parameters, self.uncertainty, by="key"),
            "uncertainty_kind": "one standard deviation" if self.method == "lsq"
            else "half extent of the contours' intersection region",
            "values": _nest(self.parameters, self.values, by="kind"),
            "value_uncertainty": _nest(self.parameters, self.value_uncertainty, by="kind"),
            "tests": [
                {"name": t.name, "setup": t.setup, "modes": list(t.modes), "planes": list(t.mode_planes),
                 "measured": _floats(t.measured),
                 "before": _floats(t.before), "after": _floats(t.after),
                 "before_error": _floats(t.before_error), "after_error": _floats(t.after_error),
                 "uncertainty": _floats(t.uncertainty), "uncertainty_source": t.source,
                 "reference": {k: _floats(v) for k, v in t.reference.items()},
                 **({"damping": {k: _floats(v) for k, v in t.damping.items()}} if t.damping else {})}
                for t in self.tests
            ],
            "correlation": None if self.correlation is None else
            {"parameters": self.names, "matrix": [_floats(row) for row in self.correlation]},
            "chi2": _float(self.chi2),
            "dof": self.dof,
            "reduced_chi2": _float(self.reduced_chi2),
            "covariance_scale": _float(self.covariance_scale),
            "rms_error_before": _float(self.rms_before),
            "rms_error_after": _float(self.rms_after),
            "notes": [str(n) for n in self.notes],
            "skipped": [{"test": n, "reason": r} for n, r in self.skipped],
            "failed_tests": [{"test": n, "reason": r} for n, r in self.failed_tests],
            "alternatives": [_nest(self.parameters, a, by="key") for a in self.alternatives],
            "settings": self.settings.summary(),
            "published": [dict(item) for item in self.published],
        }
        if self.uncertainty_sources:
            out["uncertainty_sources"] = {
                "frequencies": _nest(self.parameters, self.uncertainty_sources["frequencies"], by="key"),
                "tolerances": _nest(self.parameters, self.uncertainty_sources["tolerances"], by="key"),
                "held": dict(self.uncertainty_sources["held"]),
            }
        return out

    @property
    def shown_references(self) -> list[str]:
        """Labels of the tests' reference columns shown beside the correction (those containing
        :data:`SHOWN_REFERENCE`, e.g. the paper's own corrected frequencies)."""
        return list(dict.fromkeys(label for t in self.tests for label in t.reference if SHOWN_REFERENCE in label))

    def to_dataframe(self) -> pd.DataFrame:
        """Before/after table in the paper's Table 9/10 form: one row per test and mode.

        Columns ``test``, ``mode``, ``measured_Hz``, ``before_Hz``,
        ``before_error_abs_percent``, ``corrected_Hz``, ``corrected_error_abs_percent``
        (errors |computed − measured| / measured × 100), and for each of
        :attr:`shown_references` ``<label>_Hz`` and ``<label>_error_abs_percent``; last, ``plane`` (``in`` or
        ``out``, the plane of the mode).
        """
        frames = []
        labels = self.shown_references
        for t in self.tests:
            data = {
                "test": t.name, "mode": list(t.modes), "measured_Hz": t.measured,
                "before_Hz": t.before, "before_error_abs_percent": np.abs(t.before_error),
                "corrected_Hz": t.after, "corrected_error_abs_percent": np.abs(t.after_error),
            }
            for label in labels:
                values = t.reference.get(label, np.full(len(t.modes), np.nan))
                data[f"{label}_Hz"] = values
                data[f"{label}_error_abs_percent"] = np.abs(percent_error(values, t.measured))
            data["plane"] = list(t.mode_planes)
            frames.append(pd.DataFrame(data))
        return pd.concat(frames, ignore_index=True)


def _float(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def _floats(a) -> list:
    return [_float(x) for x in np.asarray(a, float)]


def _nest(parameters, values, by: str) -> dict:
    """{key: value} for cable properties, {key: {member: value}} for per-member ones."""
    out: dict = {}
    for p, v in zip(parameters, values):
        key = p.key if by == "key" else p.kind
        if p.member is None:
            out[key] = _float(v)
        else:
            out.setdefault(key, {})[p.member] = _float(v)
    return out
