"""The tables of a diagnosis, as pandas DataFrames (``Diagnosis.tables()``; the report's CSV and Markdown).

Every number of the report comes from these tables: the ranking of the
hypotheses, the frequencies per test and mode, the gain, the named cause's
parameters, the nominal comparison (taut string, pinned beam, DSM) and, where
the damping ratios are data (a damper in question), the damping ratios
measured and modelled.
They are data, laid out by :mod:`stcs_ident.report.diagnose`.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .. import effects as registry
from ..core import kinds
from ..core.formatting import percent_error
from ..identify.problem import DAMPING_SPREAD
from .fitting import data

#: The tables of :func:`diagnosis_tables`, in order (each a CSV file of the report).
TABLES = ("ranking", "frequencies", "gain", "nominal_comparison", "cause")
#: Columns of :func:`damping_table`.
#: The damping ratios are ratios (not percent): ``measured_damping_ratio`` with its 1σ, the σ the diagnosis weighs it
#: by, the nominal and the chosen model's ratios, and each one's z, (measured − model) / σ.
DAMPING_COLUMNS = ("test", "setup", "mode", "plane", "measured_damping_ratio", "damping_ratio_uncertainty",
                   "damping_ratio_sigma", "nominal_damping_ratio", "corrected_damping_ratio", "nominal_z",
                   "corrected_z")
#: The keys of :func:`damping_columns` for the columns of :data:`DAMPING_COLUMNS` after the first four.
_DAMPING_KEYS = ("measured", "uncertainty", "sigma", "nominal", "corrected", "nominal_z", "corrected_z")


def effects_label(effects) -> str:
    """``a + b`` for a hypothesis's effects, ``nominal`` for none."""
    return " + ".join(effects) if effects else "nominal"


def parameter_rows(values: dict, sigmas: dict) -> list[dict]:
    """One row per parameter of ``Diagnosis.parameters(fit)``: effect, parameter, value, uncertainty, unit.

    A parameter with one value per member (a test's tension ratio, an
    attachment's position) is named ``kind[member]``; a clamped end's
    rotational stiffness is ``inf``.
    """
    rows = []
    for effect, entries in values.items():
        for key, value in entries.items():
            unit = _unit(effect, key.split("_A")[0].split("_B")[0])
            sig = sigmas.get(effect, {}).get(key)
            if isinstance(value, dict):
                for member, v in value.items():
                    s = (sig or {}).get(member)
                    rows.append({"effect": effect, "parameter": f"{key}[{member}]", "value": float(v),
                                 "uncertainty": math.nan if s is None else float(s), "unit": unit})
            else:
                v = math.inf if value == "inf" else (math.nan if value is None else float(value))
                rows.append({"effect": effect, "parameter": key, "value": v,
                             "uncertainty": math.nan if sig is None else float(sig), "unit": unit})
    return rows


def _unit(effect: str, key: str) -> str:
    """Unit of the quantity ``key`` of ``effect`` as the effect declares it (else that of the parameter kind
    ``key`` names); ``-`` for a ratio or a key of no known unit."""
    declared = {q.key: q.unit for q in registry.get(effect).quantities} if effect in registry.names() else {}
    unit = declared.get(key, kinds.unit(key))
    return unit or "-"


def _short(rows: list[dict]) -> str:
    """Key parameter values in one cell: ``EI = 1.05e+05 N m^2; ratio[T1] = 0.981``."""
    parts = []
    for r in rows:
        unit = "" if r["unit"] == "-" else f" {r['unit']}"
        parts.append(f"{r['parameter']} = {r['value']:.4g}{unit}")
    return "; ".join(parts)


def _reduced_chi2(fit, n: int) -> float:
    dof = n - fit.n_parameters
    return fit.chi2 / dof if dof > 0 else math.nan


def ranking_table(diagnosis) -> pd.DataFrame:
    """Every hypothesis, best AICc first: effects, k, χ², reduced χ², AICc, ΔAICc, rms and CV rms (%); a failed
    fit last, its figures empty and its reason in ``failure``."""
    d = diagnosis
    n = d.measured.size
    ranked = d.ranked
    best = ranked[0].aicc
    rows = []
    for rank, f in enumerate(ranked, start=1):
        # A failed fit has no estimate: its figures are empty (not χ² inf, ε 0), its reason in ``failure``.
        failed = f.failure is not None
        rows.append({"rank": rank, "effects": effects_label(f.effects), "n_parameters": f.n_parameters,
                     "chi2": math.nan if failed else f.chi2,
                     "reduced_chi2": math.nan if failed else _reduced_chi2(f, n),
                     "prior_penalty": math.nan if failed else f.penalty,
                     "relative_model_error": math.nan if failed else f.epsilon,
                     "aicc": math.nan if failed else f.aicc, "delta_aicc": math.nan if failed else f.aicc - best,
                     "rms_error_percent": f.rms_error,
                     "cv_rms_error_percent": math.nan if f.cv_rms_error is None else f.cv_rms_error,
                     "cause": f.effects == d.selection.fitted,
                     "parameters": "" if failed else _short(parameter_rows(*d.parameters(f))),
                     "failure": f.failure or "",
                     "elapsed_s": d.timings.get(f.effects, math.nan)})
    return pd.DataFrame(rows)


def frequency_table(diagnosis) -> pd.DataFrame:
    """Per test and mode: measured (with uncertainty), nominal, baseline, corrected (Hz) and errors (%), the source
    and the mode's plane."""
    d = diagnosis
    models = {"nominal": d.nominal, "baseline": d.baseline, "corrected": d.corrected}
    split = {key: (d.per_test(fit) if fit is not None else None) for key, fit in models.items()}
    frames = []
    for i, m in enumerate(d.measurements):
        data = {"test": m.name, "setup": m.test.setup, "mode": m.modes, "measured_Hz": m.frequencies,
                "uncertainty_Hz": m.uncertainty}
        for key, values in split.items():
            data[f"{key}_Hz"] = values[i] if values is not None else np.full(m.modes.size, np.nan)
        for key in models:
            data[f"{key}_error_percent"] = percent_error(data[f"{key}_Hz"], m.frequencies)
        data["source"] = m.source
        data["plane"] = [str(p) for p in m.planes]
        frames.append(pd.DataFrame(data))
    return pd.concat(frames, ignore_index=True)


def gain_table(diagnosis) -> pd.DataFrame:
    """rms error (%) in-sample and cross-validated of the nominal, baseline and corrected models."""
    d = diagnosis
    n = d.measured.size
    rows = []
    for key, fit in (("nominal", d.nominal), ("baseline", d.baseline), ("corrected", d.corrected)):
        if fit is None:
            continue
        rows.append({"model": key, "effects": effects_label(fit.effects), "n_parameters": fit.n_parameters,
                     "chi2": fit.chi2, "reduced_chi2": _reduced_chi2(fit, n), "aicc": fit.aicc,
                     "rms_error_percent": fit.rms_error,
                     "cv_rms_error_percent": math.nan if fit.cv_rms_error is None else fit.cv_rms_error,
                     "test_cv_rms_error_percent": d.test_cv.get(key, math.nan)})
    return pd.DataFrame(rows)


def cause_table(diagnosis) -> pd.DataFrame:
    """The parameters of the chosen hypothesis, each marked ``cause`` or ``correction`` (within the tolerance
    of its nominal value); no rows when the nominal model stands."""
    d = diagnosis
    rows = parameter_rows(*d.parameters(d.corrected)) if d.selection.fitted else []
    for row in rows:
        row["role"] = "correction" if row["effect"] in d.selection.corrections else "cause"
    return pd.DataFrame(rows, columns=["effect", "role", "parameter", "value", "uncertainty", "unit"])


def nominal_comparison(diagnosis) -> pd.DataFrame:
    """The diagnosis's nominal comparison (``diagnosis.comparison``: taut string, pinned beam, DSM against
    measured), one row per test and mode.

    Raises
    ------
    ValueError
        When the diagnosis carries no comparison (one not made by
        :func:`~stcs_ident.diagnose.diagnose`).
    """
    if diagnosis.comparison is None:
        raise ValueError("the diagnosis carries no nominal comparison (made by diagnose())")
    frames = []
    for t in diagnosis.comparison.tests:
        frame = t.to_dataframe()
        frame.insert(0, "test", t.name)
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def damping_columns(diagnosis) -> list[dict[str, np.ndarray]] | None:
    """Per measurement, its damping ratios measured and modelled, by mode (NaN where a mode's ratio is not data);
    None when the damping ratios are not data of the diagnosis (no damper in question, or none measured).

    Keys: ``measured`` and ``uncertainty`` (its 1σ from the spectra); ``sigma``, the σ the diagnosis weighs it
    by (the 1σ with :data:`~stcs_ident.identify.problem.DAMPING_SPREAD`, the mode-to-mode spread of a cable's
    own damping, added in quadrature); ``nominal`` and ``corrected``, the ratios of the nominal model and of
    the chosen hypothesis (the dampers' −Re(s)/|s| of the complex modes plus the cable's own ratio profiled
    out of the data, as each fit weighed them); ``nominal_z`` and ``corrected_z``, (measured − model) / sigma,
    whose squares are the damping ratios' terms of each model's χ².
    """
    d = diagnosis
    if not any(m.damping_is_data for m in d.measurements):
        return None
    problem = data(d.campaign, d.measurements, d.settings.tension_model)
    if not problem.use_damping:
        return None
    rows = {}
    for key, fit in (("nominal", d.nominal), ("corrected", d.corrected)):
        predicted = np.asarray(fit.predicted, float)
        rows[key] = predicted if predicted.size == problem.n_data else np.full(problem.n_data, np.nan)
    out = []
    for columns in problem.damping_columns(rows["nominal"], rows["corrected"]):
        sigma = np.hypot(columns["uncertainty"], DAMPING_SPREAD)
        entry = {"measured": columns["measured"], "uncertainty": columns["uncertainty"], "sigma": sigma,
                 "nominal": columns["before"], "corrected": columns["after"]}
        for key in ("nominal", "corrected"):
            entry[f"{key}_z"] = (entry["measured"] - entry[key]) / sigma
        out.append(entry)
    return out


def damping_table(diagnosis) -> pd.DataFrame:
    """Per test and mode whose damping ratio is data of the diagnosis: measured (with its 1σ), the σ it is
    weighed by, the nominal and the chosen (corrected) model's ratios and each one's z (:func:`damping_columns`;
    ratios, not percent). No rows when the damping ratios are not data."""
    d = diagnosis
    columns = damping_columns(d)
    if columns is None:
        return pd.DataFrame(columns=list(DAMPING_COLUMNS))
    frames = []
    for m, entry in zip(d.measurements, columns):
        used = np.isfinite(entry["measured"])
        frame = {"test": m.name, "setup": m.test.setup, "mode": m.modes[used], "plane": [str(p) for p in m.planes[used]]}
        frame |= {column: entry[key][used] for column, key in zip(DAMPING_COLUMNS[4:], _DAMPING_KEYS)}
        frames.append(pd.DataFrame(frame, columns=list(DAMPING_COLUMNS)))
    return pd.concat(frames, ignore_index=True)


def diagnosis_tables(diagnosis) -> dict[str, pd.DataFrame]:
    """Every table of :data:`TABLES` by name; ``nominal_comparison`` only when the diagnosis carries one;
    ``damping`` (:func:`damping_table`) added when the damping ratios are data."""
    makers = {"ranking": ranking_table, "frequencies": frequency_table, "gain": gain_table,
              "nominal_comparison": nominal_comparison, "cause": cause_table}
    out = {name: makers[name](diagnosis) for name in TABLES
           if name != "nominal_comparison" or diagnosis.comparison is not None}
    if damping_columns(diagnosis) is not None:
        out["damping"] = damping_table(diagnosis)
    return out
