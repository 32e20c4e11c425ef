"""Text and report of a diagnosis.

:func:`diagnosis_text` is the terminal summary. :func:`write_report` writes a
report directory: the tables first (:mod:`.tables`, pandas → CSV and
Markdown), the figures second (:mod:`.figures`), the prose last, every
number of it from the data.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import pandas as pd

from ..core.errors import InputError
from ..core.files import whole_directory, write_atomic, write_csv, write_figure
from ..core.formatting import counted, markdown_table, number, percent, rms
from ..diagnose.tables import (
    cause_table,
    damping_table,
    effects_label,
    frequency_table,
    gain_table,
    nominal_comparison,
    ranking_table,
)
from .diagnose_damping import DAMPING_CSV, DAMPING_PNG, damping_lines
from .plots import mode_axis

#: Files of the report, besides the figures.
CSV_FILES = ("ranking.csv", "frequencies.csv", "gain.csv", "nominal_comparison.csv", "cause.csv")


def diagnosis_text(diagnosis) -> str:
    """Ranking, cause and gain for the terminal."""
    d = diagnosis
    n = sum(m.modes.size for m in d.measurements)
    lines = [(f"Diagnosis of {d.campaign.name}: {counted(len(d.measurements), 'test')}, "
              f"{counted(n, 'measured frequency', 'measured frequencies')}"), ""]
    with_error = d.selection.model_error
    lines.append(f"{'hypothesis':<48} {'k':>3} {'chi2':>12} {'prior':>8}" + (f" {'eps':>9}" if with_error else "")
                 + f" {'dAICc':>10} {'rms %':>8} {'cv rms %':>9}")
    best = d.ranked[0].aicc
    for f in d.ranked:
        label = " + ".join(f.effects) if f.effects else "nominal"
        if f.failure:
            lines.append(f"{label:<48} {f.n_parameters:>3} failed: {f.failure}")
            continue
        delta = number(f.aicc - best, "{:.1f}", width=10, finite_only=True)
        eps = f" {f.epsilon:>9.2e}" if with_error else ""
        lines.append(f"{label:<48} {f.n_parameters:>3} {f.chi2:>12.4g} {f.penalty:>8.2f}{eps} {delta} "
                     f"{f.rms_error:>8.3f} {number(f.cv_rms_error, width=9, finite_only=True)}")
    lines += ["", "Cause: " + d.cause_text()]
    s = d.summary()["gain"]
    baseline, cv_baseline, cv_corrected = (number(s.get(k), finite_only=True) for k in (
        "rms_error_baseline", "cv_rms_error_baseline", "cv_rms_error_corrected"))
    lines.append(f"Gain: rms error nominal {s['rms_error_nominal']:.3f} %, baseline ({baseline_label(d)}) {baseline} %, "
                 f"corrected {s['rms_error_corrected']:.3f} %; cross-validated (leave one mode out) baseline "
                 f"{cv_baseline} %, corrected {cv_corrected} %.")
    if d.test_cv:
        shown = ", ".join(f"{label} {value:.3f} %" for label, value in d.test_cv.items())
        lines.append(f"Leave one test out (each test predicted from the others, its tension as stated): {shown}.")
    damping = damping_lines(damping_table(d), effects_label(d.corrected.effects))
    if damping:
        lines += ["", *damping[:-1]]
    for note in d.notes:
        lines.append(f"Note: {note}")
    lines += [f"Skipped {line}" for line in skipped_lines(d.skipped)]
    return "\n".join(lines) + "\n"


def skipped_lines(skipped) -> list[str]:
    """One line per reason: ``9 tests (no measured frequencies and no record): case1-L1, case1-L2, ...`` (a
    test alone: ``case1-L1: reason``), in the order the reasons first appear."""
    by_reason: dict[str, list[str]] = {}
    for name, reason in skipped:
        by_reason.setdefault(reason, []).append(name)
    return [f"{names[0]}: {reason}" if len(names) == 1 else f"{len(names)} tests ({reason}): {', '.join(names)}"
            for reason, names in by_reason.items()]


def removal_sentence(selection) -> str:
    """The removal costs behind the principal effect, one sentence: ``Removal cost (AICc rise when an effect is
    dropped): a 48.6; b not known (a alone failed (…)); principal: a, the largest known.``"""
    sel = selection
    costs = [f"{e} " + (f"not known: {sel.removal_unknown[e]}" if e in sel.removal_unknown
                        else number(v, "{:.1f}", finite_only=True)) for e, v in sel.removal_cost.items()]
    text = "Removal cost (AICc rise when an effect is dropped): " + "; ".join(costs) + "."
    if not sel.effects:
        return text + " No cause: corrections only."
    if len(sel.effects) == 1:
        return text
    known = [e for e in sel.effects if e not in sel.removal_unknown]
    why = "the largest known" if known else "no removal cost known: the first of the cause"
    return text + f" Principal effect: {sel.principal} ({why})."


def baseline_label(diagnosis) -> str:
    """What the baseline re-estimated: ``tension, EI`` (the source paper's correction), ``tension, EI absolute``
    on a bare cable, or the part of it that was fitted (``tension``); ``none`` when nothing was."""
    base = diagnosis.baseline
    if base is None:
        return "none"
    from ..effects import registry

    words = {"tension": "tension", "EI": "EI absolute" if diagnosis.campaign.cable.EI <= 0 else "EI"}
    return ", ".join(words.get(registry.get(e).parameter_kind, e) for e in base.effects)


def _file_stem(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]", "_", name).lstrip(".") or "test"


def _data_section(d, spectra) -> list[str]:
    cable = d.campaign.cable
    records = {ts.name: ts for ts in spectra}
    rows = []
    for m in d.measurements:
        where = f"record {os.path.basename(records[m.name].record)}" if m.name in records else "campaign table"
        rows.append({"test": m.name, "setup": m.test.setup, "tension_kN": m.test.tension / 1e3,
                     "modes": " ".join(mode_axis(m.modes, getattr(m, "planes", None))[1]), "frequencies": where,
                     "uncertainty_Hz": f"{m.uncertainty.min():.2g} – {m.uncertainty.max():.2g}"
                     if m.uncertainty.min() != m.uncertainty.max() else f"{m.uncertainty[0]:.2g}",
                     "uncertainty from": m.source})
    n = d.measured.size
    out = ["## Data", "",
           (f"Cable: length {cable.length:g} m, mass {cable.mass_per_length:g} kg/m, nominal EI "
           f"{cable.EI / 1e3:.4g} kN m². {counted(len(d.measurements), 'test')}, "
           f"{counted(n, 'measured frequency', 'measured frequencies')}"
           f"{' (setups symmetric about midspan: a position x and l − x are not told apart)' if d.symmetric else ''}."),
           "", markdown_table(pd.DataFrame(rows), {"tension_kN": "{:.1f}"},
                              {"test": "test", "setup": "setup", "tension_kN": "tension (kN)", "modes": "modes",
                               "frequencies": "frequencies from", "uncertainty_Hz": "uncertainty (Hz)",
                               "uncertainty from": "uncertainty from"})]
    if d.skipped:
        out.append("Skipped " + "; ".join(skipped_lines(d.skipped)) + ".\n")
    out.append(f"Effects considered: {', '.join(d.considered) or 'none'}.\n")
    return out


def _forward_section(forward, table: pd.DataFrame) -> list[str]:
    out = ["## Nominal model against the measurements", "",
           ("Taut string, pinned beam and the exact dynamic-stiffness model (DSM) with the nominal cable and "
           "tensions; errors are (model − measured) / measured in %."), ""]
    columns = {"test": "test", "mode": "mode", "measured_Hz": "measured (Hz)", "taut_string_Hz": "string (Hz)",
               "taut_string_error_percent": "err %", "beam_pinned_Hz": "beam (Hz)",
               "beam_pinned_error_percent": "err %", "dsm_Hz": "DSM (Hz)", "dsm_error_percent": "err %"}
    columns = {c: h for c, h in columns.items() if c in table.columns}
    fmt = {c: ("{:.2f}" if c.endswith("_percent") else "{:.3f}") for c in columns if c not in ("test", "mode")}
    out.append(markdown_table(table, fmt, columns))
    errors = []
    for t in forward.tests:
        if t.measured is None:
            continue
        errs = {c: rms(t.error(c)) for c in ("taut_string", "beam_pinned", "dsm")}
        errors.append(f"{t.name}: string {errs['taut_string']:.2f} %, beam {errs['beam_pinned']:.2f} %, "
                      f"DSM {errs['dsm']:.2f} %")
    if errors:
        out.append("rms errors — " + "; ".join(errors) + ".\n")
    for check in forward.reference_checks:
        out.append(f"- {check.sentence()}")
    if forward.reference_checks:
        out.append("")
    return out


def _ranking_section(d, ranking: pd.DataFrame) -> list[str]:
    from scipy.stats import chi2 as chi2_distribution

    from ..diagnose.selection import ALPHA, AMBIGUITY

    n = d.measured.size
    gate = float(chi2_distribution.isf(ALPHA, n))
    columns = {"rank": "#", "effects": "hypothesis", "n_parameters": "k", "chi2": "χ²", "reduced_chi2": "χ²/(n−k)",
               "prior_penalty": "prior", "relative_model_error": "ε", "delta_aicc": "ΔAICc",
               "rms_error_percent": "rms %", "cv_rms_error_percent": "CV rms %", "cause": "chosen",
               "parameters": "key parameter values"}
    if not d.selection.model_error:
        del columns["relative_model_error"]
    fmt = {"chi2": "{:.4g}", "reduced_chi2": "{:.3g}", "prior_penalty": "{:.2f}", "relative_model_error": "{:.2e}",
           "delta_aicc": "{:.1f}", "rms_error_percent": "{:.3f}", "cv_rms_error_percent": "{:.3f}"}
    failed = ranking["failure"] != ""
    listed = ["Failed fits (no estimate, not ranked):", ""] if failed.any() else []
    listed += [f"- {row.effects}: {row.failure}" for row in ranking[failed].itertuples()]
    return ["## Hypotheses ranked by AICc", "", markdown_table(ranking[~failed], fmt, columns), *listed,
            *([""] if listed else []), "How to read this:", "",
            (f"- χ² sums the squared misfits in units of the frequency uncertainties; k is the number of fitted "
            f"parameters, n = {n} the number of measured frequencies."),
            ("- AICc = χ² + prior + 2k + 2k(k + 1)/(n − k − 1) trades misfit against parameters; lower is better "
            "and ΔAICc is measured from the best hypothesis."),
            ("- prior = Σ 2 ln(1 + ((x − nominal)/tolerance)²) over the parameters whose nominal value has a "
            "tolerance (stated tension, nominal EI, recorded positions and masses, length; the campaign's "
            "[tolerance] or the defaults), plus 2 ln(l/(√(2π) σ_x)) − 2 for the position of an unmodeled "
            "attachment found on the span: of hypotheses the frequencies cannot tell apart, the one needing the "
            "more plausible departures ranks first. A departure within its tolerance is a correction, never a "
            "cause."),
            ("- ε (shown when no hypothesis reaches the measurement uncertainty): the relative model error per "
            "frequency each hypothesis needs; χ² in AICc is then replaced by the likelihood with variances "
            "σ² + (ε f)², ε one more parameter, so that ΔAICc keeps its meaning."),
            (f"- Hypotheses within ΔAICc < {AMBIGUITY:g} of the chosen one are not told apart (ambiguous); of "
            "nested ones the simpler is preferred."),
            (f"- The χ² gate: the nominal model is accepted (no cause named) when its χ² is below the "
            f"{100 * (1 - ALPHA):g} % quantile of the χ² distribution with n degrees of freedom ({gate:.1f} here). "
            f"The nominal χ² is {d.nominal.chi2:.4g}: {'accepted' if d.selection.explained else 'rejected'}."),
            ("- rms % is the root mean square relative error in-sample; CV rms % predicts each mode number left "
            "out of the fit (leave-one-mode-out cross-validation). The gain also predicts each test from the "
            "others (leave-one-test-out, its tension as stated): the honest measure on real data."), ""]


def _cause_section(d, cause: pd.DataFrame, figures: dict) -> list[str]:
    from scipy.stats import chi2 as chi2_distribution

    from ..diagnose.selection import ALPHA, BASELINE, allowed

    sel = d.selection
    n = d.measured.size
    # The cause's sentence (with its alternatives) heads the report: here only what it does not say.
    out = ["## Named cause", ""]
    if not sel.fitted:
        out += [sel.statement, ""]
    else:
        out += [removal_sentence(sel), "", markdown_table(cause, {"value": "{:.5g}", "uncertainty": "{:.2g}"})]
    best = d.ranked[0]
    if best is not d.corrected and best.effects == BASELINE and not allowed(BASELINE, d.settings.max_effects):
        out += [(f"The first-ranked {effects_label(best.effects)} is the baseline (the source paper's correction), fitted "
                f"as a reference with more effects than the hypotheses searched (at most {d.settings.max_effects} "
                "here), so it is not chosen."), ""]
    dof = n - best.n_parameters
    if dof > 0 and best.chi2 > chi2_distribution.isf(ALPHA, dof):
        red = best.chi2 / dof
        out.append(f"**Model error dominates the measurement uncertainty.** Even the best hypothesis "
                   f"({effects_label(best.effects)}) leaves χ² = {best.chi2:.4g} for {dof} degrees of freedom (reduced "
                   f"χ² {red:.3g}): its misfit is {math.sqrt(red):.3g} times the stated frequency uncertainties "
                   f"({', '.join(sorted({m.source for m in d.measurements}))}). No hypothesis of the vocabulary "
                   f"explains the data within their uncertainty; the ranking shows which explains them least badly, "
                   f"and parameter uncertainties are scaled by the reduced χ².")
        out.append("")
    if "profile" in figures:
        out += ["![Profile of the position](profile.png)", "",
                (f"χ² of the named cause with each unmodeled attachment held at {figures['profile_points']} or more "
                 "positions along the span (every other parameter of the cause refitted); the red star is the "
                 "named cause's estimate, a point of the curve."
                 + (" The setup is symmetric about midspan: the curve is too, and the estimate's mirror image is "
                    "starred as well." if d.symmetric else "")
                 + (f" {figures['unscanned']}" if figures.get("unscanned") else "")), ""]
    return out


def _before_after_section(d, freq: pd.DataFrame, figures: dict) -> list[str]:
    out = ["## Residual pattern", "", f"![Residuals per mode]({figures['residuals']})", "",
           "Error in % per mode for each test; the grey band is ± one measurement uncertainty.", "",
           "## Before and after, per test", ""]
    have_baseline = d.baseline is not None
    columns = {"mode": "mode", "measured_Hz": "measured", "uncertainty_Hz": "σ", "nominal_Hz": "nominal",
               "nominal_error_percent": "err %"}
    if have_baseline:
        columns |= {"baseline_Hz": "baseline", "baseline_error_percent": "err %"}
    columns |= {"corrected_Hz": "corrected", "corrected_error_percent": "err %"}
    fmt = {c: ("{:.3f}" if c.endswith("_percent") else "{:.2g}" if c == "uncertainty_Hz" else "{:.4f}") for c in columns}
    fmt["mode"] = "{}"
    for m in d.measurements:
        out += [f"### {m.name}", "", markdown_table(freq[freq["test"] == m.name], fmt, columns)]
    return out


def _damping_section(d, table: pd.DataFrame, figures: dict) -> list[str]:
    """Measured against modelled damping ratios (nothing when the damping ratios are not data)."""
    if table.empty:
        return []
    out = ["## Damping ratios, measured and modelled", ""]
    if "damping" in figures:
        out += [f"![Damping ratios per mode]({figures['damping']})", "",
                ("Damping ratio in % per mode for each test: measured with ±1σ error bars, the nominal and the "
                 "corrected model's."), ""]
    return out + damping_lines(table, effects_label(d.corrected.effects), "markdown")


def _gain_section(d, gain: pd.DataFrame) -> list[str]:
    g = d.summary()["gain"]
    sentence = (f"The rms error against the measured frequencies is {percent(g['rms_error_nominal'])} with the nominal "
                f"model")
    if "rms_error_baseline" in g:
        sentence += f", {percent(g['rms_error_baseline'])} with {baseline_label(d).replace(', ', ' and ')} re-estimated (baseline)"
    sentence += (f" and {percent(g['rms_error_corrected'])} with the corrected model ({effects_label(d.corrected.effects)}); "
                 f"cross-validated, nominal {percent(g['cv_rms_error_nominal'])}")
    if "rms_error_baseline" in g:
        sentence += f", baseline {percent(g.get('cv_rms_error_baseline'))}"
    sentence += f", corrected {percent(g['cv_rms_error_corrected'])}."
    if d.test_cv:
        sentence += (" Predicting each test from the others (leave one test out, its tension as stated): "
                     + ", ".join(f"{label} {percent(value)}" for label, value in d.test_cv.items()) + ".")
    out = ["## Gain", "", sentence, ""]
    if d.selection.effects and d.corrected.rms_error > d.nominal.rms_error:
        out += [(f"The corrected model lowers χ² (errors in Hz weighted by the uncertainties) but its relative "
                f"rms error ({percent(d.corrected.rms_error)}) is larger than the nominal model's "
                f"({percent(d.nominal.rms_error)})."), ""]
    columns = {"model": "model", "effects": "effects", "n_parameters": "k", "chi2": "χ²", "reduced_chi2": "χ²/(n−k)",
               "rms_error_percent": "rms %", "cv_rms_error_percent": "CV rms %",
               "test_cv_rms_error_percent": "test CV rms %"}
    fmt = {"chi2": "{:.4g}", "reduced_chi2": "{:.3g}", "rms_error_percent": "{:.3f}", "cv_rms_error_percent": "{:.3f}",
           "test_cv_rms_error_percent": "{:.3f}"}
    return out + [markdown_table(gain, fmt, columns)]


def _notes_section(d) -> list[str]:
    notes = list(d.notes) + [f"{effects_label(d.corrected.effects)}: {note}" for note in d.corrected.notes]
    if d.baseline is not None and d.baseline is not d.corrected:
        notes += [f"baseline ({effects_label(d.baseline.effects)}): {note}" for note in d.baseline.notes]
    out = ["## Notes", ""] + [f"- {note}" for note in notes] if notes else []
    return out + ([""] if notes else [])


def report_markdown(diagnosis, tables: dict, figures: dict, spectra=None) -> str:
    """``report.md`` from the tables (``report_tables``) and the figure file names (``spectra``: default
    the spectra the diagnosis carries)."""
    d = diagnosis
    spectra = d.spectra if spectra is None else spectra
    lines = [f"# Diagnosis of {d.campaign.name}", "",
             (f"{counted(len(d.measurements), 'test')}, "
              f"{counted(d.measured.size, 'measured frequency', 'measured frequencies')}, "
              f"{counted(len(d.fits), 'hypothesis', 'hypotheses')} "
             f"fitted in {d.elapsed:.1f} s."), "", "**Cause:** " + d.cause_text(), "",
             "**Gain:** rms error nominal " + percent(d.nominal.rms_error) + ", corrected "
             + percent(d.corrected.rms_error) + " (cross-validated " + percent(d.corrected.cv_rms_error) + ").", ""]
    lines += _data_section(d, spectra)
    if figures.get("spectra"):
        lines += ["## Spectra", ""]
        for name, file in figures["spectra"]:
            lines += [f"### {name}", "", f"![Spectra of {name}]({file})", ""]
    lines += _forward_section(d.comparison, tables["nominal_comparison"])
    lines += _ranking_section(d, tables["ranking"])
    lines += _cause_section(d, tables["cause"], figures)
    lines += _before_after_section(d, tables["frequencies"], figures)
    damping = tables.get("damping")
    if damping is not None:
        lines += _damping_section(d, damping, figures)
    lines += _gain_section(d, tables["gain"])
    lines += _notes_section(d)
    csv = CSV_FILES + ((DAMPING_CSV,) if damping is not None and not damping.empty else ())
    lines += ["## Files", "", "Tables as CSV: " + ", ".join(f"[{f}]({f})" for f in csv) + ".", ""]
    return "\n".join(lines)


def check_report_directory(out_dir, field: str = "out_dir") -> Path:
    """``out_dir`` as a Path if a report may be written there: absent, empty, or an earlier report (it is
    replaced as a whole, so anything else it holds would be lost). Called before any work by the command
    line (``field="--out"``) and again by :func:`write_report`.

    Raises
    ------
    InputError
        Naming ``field``, if ``out_dir`` exists and is not a directory, or is a non-empty directory
        without ``report.md``.
    """
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError("exists and is not a directory", field=field, file=str(out))
    if out.is_dir() and any(out.iterdir()) and not (out / "report.md").is_file():
        # replacing a directory as a whole deletes what it holds: only ever an earlier report
        raise InputError("is a non-empty directory without report.md: not a report, not replaced", field=field,
                         file=str(out))
    return out


def write_report(diagnosis, out_dir, spectra=None) -> Path:
    """Write the diagnosis report into ``out_dir``, whole or not at all.

    ``out_dir`` gets ``report.md`` (tables, figures and the named cause in
    plain words), the tables as CSV (:data:`CSV_FILES`) and the figures as
    PNG: ``residuals.png``, ``profile.png`` when the cause is an unmodeled
    mass or support, and ``spectra_<test>.png`` for each test with a record;
    where the damping ratios are data (a damper in question), also
    ``damping.csv`` and ``damping.png``, measured against modelled.
    The report is built in a temporary directory beside ``out_dir`` and
    renamed; an existing ``out_dir`` is replaced as a whole only once the
    new report is complete, and left untouched if anything fails.

    Parameters
    ----------
    diagnosis : Diagnosis
    out_dir : path-like
    spectra : sequence of TestSpectra, optional
        The spectra the frequencies were picked from (one figure each);
        default those the diagnosis carries (``diagnosis.spectra``).

    Returns
    -------
    Path
        ``out_dir``.

    Raises
    ------
    InputError
        If ``out_dir`` exists and is not a directory, or is a non-empty
        directory that is not a report (holds no ``report.md``).
    """
    from . import diagnose_figures as diagnosis_figures

    out = check_report_directory(out_dir)
    d = diagnosis
    spectra = d.spectra if spectra is None else spectra
    tables = {"ranking": ranking_table(d), "frequencies": frequency_table(d), "gain": gain_table(d),
              "nominal_comparison": nominal_comparison(d), "cause": cause_table(d)}
    damping = damping_table(d)
    if not damping.empty:  # a damper in question: its table and figure
        tables["damping"] = damping
    with whole_directory(out) as tmp:
        for name, frame in tables.items():
            write_csv(frame, tmp / f"{name}.csv", index=False)
        figures: dict = {"spectra": []}
        if spectra:
            from .plots import plot_test_spectra

            used = {m.name for m in d.measurements}
            for ts in spectra:
                if ts.name in used:
                    file = f"spectra_{_file_stem(ts.name)}.png"
                    write_figure(plot_test_spectra(ts)["figure"], tmp / file)
                    figures["spectra"].append((ts.name, file))
        write_figure(diagnosis_figures.plot_residuals(d)["figure"], tmp / "residuals.png")
        figures["residuals"] = "residuals.png"
        if "damping" in tables:
            write_figure(diagnosis_figures.plot_damping(damping)["figure"], tmp / DAMPING_PNG)
            figures["damping"] = DAMPING_PNG
        profiles = diagnosis_figures.cause_profiles(d)
        if profiles:
            drawn = diagnosis_figures.plot_profiles(d, profiles=profiles)
            write_figure(drawn["figure"], tmp / "profile.png")
            figures["profile"] = "profile.png"
            figures["profile_points"] = min(p.positions.size for p in profiles.values())
            if drawn["unscanned"]:
                figures["unscanned"] = diagnosis_figures.flat_sentence(drawn["unscanned"])
        text = report_markdown(d, tables, figures, spectra)
        write_atomic(tmp / "report.md", text)
    return out
