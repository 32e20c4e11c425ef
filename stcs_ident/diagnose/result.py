"""The diagnosis result: the data of the ``diagnose`` step, its JSON (``.summary()``) and tables (``.tables()``).

The terminal summary and the report are made from it by
:mod:`stcs_ident.report.diagnose`, which this module does not import.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import effects as registry
from ..core.formatting import percent_error
from ..core.model import Cable, Campaign
from ..core.result import Result
from ..core.settings import Settings
from ..effects.base import Context
from ..forward.compare import ForwardResult
from ..identify.problem import Measurement
from .fitting import HypothesisFit
from .selection import Selection, baseline_fit, ranking
from .tables import damping_columns, diagnosis_tables


def _finite_or_none(v: float | None) -> float | None:
    return None if v is None or not math.isfinite(v) else float(v)


def effect_parameters(fit: HypothesisFit, cable: Cable, symmetric: bool) -> tuple[dict, dict]:
    """Values and standard uncertainties by effect, in the units of the diagnosis JSON.

    Each effect of the registry puts its own parameters in (:meth:`~stcs_ident.effects.base.Effect.record`);
    a position on a configuration symmetric about midspan is given in [0, l/2] (x and l − x cannot be told
    apart).
    """
    values: dict = {}
    sigmas: dict = {}
    if fit.result is None:
        return values, sigmas
    res = fit.result
    context = Context(cable, symmetric)
    for p, owner, x, s, v in zip(res.parameters, fit.hypothesis.owners, res.estimate, res.uncertainty, res.values):
        val, sig = values.setdefault(owner, {}), sigmas.setdefault(owner, {})
        registry.get(owner).record(p, float(x), _finite_or_none(float(s)), float(v),
                                   _finite_or_none(float(p.value_uncertainty(x, s))), val, sig, context)
    return values, sigmas


@dataclass(frozen=True, repr=False)
class Diagnosis(Result):
    """What :func:`~stcs_ident.diagnose.diagnose` found.

    ``tables()`` holds ``ranking`` (every hypothesis, best first: the main
    table), ``frequencies``, ``gain``, ``nominal_comparison`` and ``cause``
    (:mod:`stcs_ident.diagnose.tables`).

    Attributes
    ----------
    campaign : Campaign
    measurements : tuple of Measurement
    fits : dict
        {effects: HypothesisFit}; ``()`` is the nominal model.
    selection : Selection
    symmetric : bool
        Whether the measured setups are symmetric about midspan.
    skipped : tuple of (test, reason)
    notes : tuple of Note
    timings : dict
        Seconds per hypothesis (fit and cross-validation).
    elapsed : float
        Seconds in all.
    considered : tuple of str
        The effects that made hypotheses.
    settings : Settings
        How the diagnosis was run (tension model, largest number of effects
        per hypothesis, whether every pair was fitted).
    comparison : ForwardResult or None
        The nominal model against the measured frequencies (taut string,
        pinned beam, DSM), computed by :func:`~stcs_ident.diagnose.diagnose`
        with the same settings.
    test_cv : dict
        Leave-one-test-out prediction error (%) of ``nominal``, ``baseline``
        and ``corrected`` (each test predicted by the model fitted to the
        others; empty with one test).
    spectra : tuple of TestSpectra
        The spectra the frequencies were picked from (the inputs given as
        ``picked``; empty when every test's frequencies came from a table),
        for the report's figures.
    """

    campaign: Campaign
    measurements: tuple[Measurement, ...]
    fits: dict
    selection: Selection
    symmetric: bool
    skipped: tuple = ()
    notes: tuple = ()
    timings: dict = field(default_factory=dict)
    elapsed: float = 0.0
    considered: tuple = ()
    settings: Settings = field(default_factory=Settings)
    comparison: ForwardResult | None = None
    test_cv: dict = field(default_factory=dict)
    spectra: tuple = ()

    main_table = "ranking"

    def tables(self) -> dict[str, pd.DataFrame]:
        """The diagnosis's tables by name (:func:`~stcs_ident.diagnose.tables.diagnosis_tables`)."""
        return diagnosis_tables(self)

    def headline(self) -> str:
        """Campaign, data, the named cause and the rms error of the nominal and the corrected model."""
        sel = self.selection
        if sel.effects:
            cause = f"cause {' + '.join(sel.effects)} (principal {sel.principal})"
        else:
            cause = "no cause: the nominal model stands" if sel.explained else "no cause named"
        n = len(self.measurements)
        return (f"{self.campaign.name}, {n} test{'s' if n != 1 else ''}, {self.measured.size} frequencies, "
                f"{len(self.fits)} hypotheses; {cause}; rms error {self.nominal.rms_error:.3g} % nominal, "
                f"{self.corrected.rms_error:.3g} % corrected")

    @property
    def measured(self) -> np.ndarray:
        return np.concatenate([m.frequencies for m in self.measurements])

    @property
    def nominal(self) -> HypothesisFit:
        return self.fits[()]

    @property
    def corrected(self) -> HypothesisFit:
        """The chosen hypothesis: the named cause and the corrections within tolerance (the nominal model
        when the data need neither)."""
        return self.fits[self.selection.fitted]

    @property
    def baseline(self) -> HypothesisFit | None:
        """Tension and EI re-estimated (the paper's correction), or what of it applies."""
        return baseline_fit(self.fits)

    @property
    def ranked(self) -> list[HypothesisFit]:
        return ranking(self.fits)

    def parameters(self, fit: HypothesisFit) -> tuple[dict, dict]:
        return effect_parameters(fit, self.campaign.cable, self.symmetric)

    def per_test(self, fit: HypothesisFit) -> list[np.ndarray]:
        """``fit.predicted`` split by test."""
        out, k = [], 0
        for m in self.measurements:
            out.append(fit.predicted[k:k + m.modes.size])
            k += m.modes.size
        return out

    def summary(self) -> dict:
        """The ``diagnose`` JSON (plain data, notes as sentences)."""
        nominal, corrected, baseline = self.nominal, self.corrected, self.baseline
        tests = []
        parts = {"nominal": self.per_test(nominal), "corrected": self.per_test(corrected)}
        if baseline is not None:
            parts["baseline"] = self.per_test(baseline)
        damping = damping_columns(self)
        for i, m in enumerate(self.measurements):
            entry = {"name": m.name, "setup": m.test.setup, "modes": [int(k) for k in m.modes],
                     "planes": [str(p) for p in m.planes],
                     "measured": m.frequencies.tolist(), "uncertainty": m.uncertainty.tolist(), "source": m.source}
            for label, values in parts.items():
                entry[label] = values[i].tolist()
            for label, values in parts.items():
                entry[f"{label}_error"] = percent_error(values[i], m.frequencies).tolist()
            if damping is not None and np.isfinite(damping[i]["measured"]).any():
                entry["damping"] = {key: [_finite_or_none(v) for v in values] for key, values in damping[i].items()}
            tests.append(entry)
        ranked = self.ranked
        best = ranked[0].aicc
        cv_rank = self.cv_ranks()
        hypotheses = []
        for f in ranked:
            values, sigmas = self.parameters(f)
            hypotheses.append({"effects": list(f.effects), "parameters": values, "uncertainty": sigmas,
                               "n_parameters": f.n_parameters, "chi2": _finite_or_none(f.chi2),
                               "rms_error": _finite_or_none(f.rms_error), "failed": f.failure,
                               "aicc": _finite_or_none(f.aicc), "delta_aicc": _finite_or_none(f.aicc - best),
                               "cv_rms_error": _finite_or_none(f.cv_rms_error), "cv_rank": cv_rank.get(f.effects),
                               "epsilon": f.epsilon, "prior_penalty": f.penalty,
                               "notes": [str(n) for n in f.notes]})
        sel = self.selection
        values, sigmas = self.parameters(corrected)
        gain = {"rms_error_nominal": nominal.rms_error, "rms_error_corrected": corrected.rms_error,
                "cv_rms_error_nominal": nominal.cv_rms_error,
                "cv_rms_error_corrected": _finite_or_none(corrected.cv_rms_error)}
        if baseline is not None:
            gain["baseline_effects"] = list(baseline.effects)
            gain["rms_error_baseline"] = baseline.rms_error
            gain["cv_rms_error_baseline"] = _finite_or_none(baseline.cv_rms_error)
        for label, value in self.test_cv.items():
            gain[f"test_cv_rms_error_{label}"] = value
        cause_values = {e: v for e, v in values.items() if e in sel.effects}
        cause_sigmas = {e: v for e, v in sigmas.items() if e in sel.effects}
        return {
            "campaign": self.campaign.name,
            "tests": tests,
            "hypotheses": hypotheses,
            "cause": {"effects": list(sel.effects), "principal": sel.principal, "parameters": cause_values,
                      "uncertainty": cause_sigmas, "ambiguous_with": [list(a) for a in sel.ambiguous_with],
                      "fitted": list(sel.fitted),
                      "corrections": {e: values.get(e, {}) for e in sel.corrections},
                      "corrections_uncertainty": {e: sigmas.get(e, {}) for e in sel.corrections},
                      "implausible": [list(a) for a in sel.implausible], "model_error": sel.model_error,
                      "epsilon": corrected.epsilon,
                      "explained_by_nominal": sel.explained, "p_value_nominal": sel.p_value,
                      "removal_cost": {k: _finite_or_none(v) for k, v in sel.removal_cost.items()},
                      "removal_unknown": dict(sel.removal_unknown),
                      "statement": sel.statement, "description": self.cause_text()},
            "gain": gain,
            "symmetric": self.symmetric,
            "skipped": [{"test": n, "reason": r} for n, r in self.skipped],
            "notes": [str(n) for n in self.notes],
            "seconds": self.elapsed,
            "settings": self.settings.summary(),
        }

    def cv_ranks(self) -> dict[tuple[str, ...], int]:
        """Rank (1 = best) of each hypothesis by its leave-one-mode-out prediction error."""
        scored = sorted((f for f in self.fits.values() if f.cv_rms_error is not None),
                        key=lambda f: (f.cv_rms_error, f.n_parameters))
        return {f.effects: i for i, f in enumerate(scored, start=1)}

    def cause_text(self) -> str:
        """The named cause in plain words, with values and uncertainties."""
        sel = self.selection
        values, sigmas = self.parameters(self.corrected)
        corrections = ""
        if sel.corrections:
            said = [registry.get(e).describe(values.get(e, {}), sigmas.get(e, {}), self.campaign.cable)
                    for e in sel.corrections]
            corrections = (f" Corrections within the tolerance of the nominal values (not causes): "
                           f"{'; '.join(said)}.")
        if not sel.effects:
            return sel.statement + corrections
        # The principal effect first: the sentence leads with what the removal costs say matters most.
        ordered = sorted(sel.effects, key=lambda e: e != sel.principal)
        parts = [registry.get(e).describe(values.get(e, {}), sigmas.get(e, {}), self.campaign.cable)
                 for e in ordered]
        delta = self.nominal.aicc - self.corrected.aicc
        text = f"{'; '.join(parts)} explain{'s' if len(parts) == 1 else ''} the residual pattern"
        text = text[0].upper() + text[1:]
        text += f" (ΔAICc = {delta:.1f} against the nominal model"
        if len(sel.effects) > 1:
            text += f"; principal effect: {sel.principal}"
        text += ")."
        ranks = self.cv_ranks()
        chosen = self.corrected
        said: tuple = ()
        if ranks.get(chosen.effects, 1) > 1:
            top = next(f for f in self.fits.values() if ranks.get(f.effects) == 1)
            name = " + ".join(top.effects) or "the nominal model"
            text += (f" Leave-one-mode-out prediction prefers {name} ({top.cv_rms_error:.3g} % against "
                     f"{chosen.cv_rms_error:.3g} %); the diagnosis follows AICc (each frequency weighed by its "
                     f"uncertainty, parameters and implausible departures charged), which ")
            if top.effects in sel.ambiguous_with:
                text += "does not tell the two apart (ΔAICc < 2): the simpler is named."
            else:
                more = (f" and {top.n_parameters} parameters against {chosen.n_parameters}"
                        if top.n_parameters > chosen.n_parameters else "")
                text += f"ranks {name} {top.aicc - chosen.aicc:.1f} higher"
                if top.effects in sel.implausible:
                    text += (f": it needs less plausible departures from the nominal values (prior cost "
                             f"{top.penalty:.1f} against {chosen.penalty:.1f}){more}.")
                else:
                    text += f" (χ² {top.chi2:.4g} against {chosen.chi2:.4g}{more})."
            said = (top.effects,)
        ambiguous = [a for a in sel.ambiguous_with if a not in said]
        implausible = [a for a in sel.implausible if a not in said]
        if ambiguous:
            text += " Not told apart from: " + "; ".join(" + ".join(a) for a in ambiguous) + " (ΔAICc < 2)."
        if implausible:
            text += (" The frequencies alone do not separate it from "
                     + "; ".join(" + ".join(a) for a in implausible)
                     + ", which need less plausible departures from the nominal values.")
        if chosen.epsilon > 0:
            text += (f" No hypothesis reaches the measurement uncertainty: the ranking includes a model error of "
                     f"{chosen.epsilon:.2g} (relative, per frequency) for this one.")
        return text + corrections
