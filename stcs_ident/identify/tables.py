"""Before/after tables in the source paper's Table 9/10 form, as Markdown, text and CSV.

Per test and mode: the measured frequency, the nominal model's ("before")
and its error |δ|, the corrected model's and its error |δ*| (errors in %,
|computed − measured| / measured × 100). Reference columns whose label
says ``corrected`` (the paper's own corrected frequencies) are shown beside
ours with their errors, so the two corrections can be compared. The
numbers come from the result (``IdentificationResult.to_dataframe()`` and
its fields); this module only lays them out.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pandas as pd

from .problem import printed_step


def parameters_table(result) -> pd.DataFrame:
    """One row per parameter: nominal (SI), estimate and uncertainty (variable and SI)."""
    rows = []
    for p, x, s, v, vs in zip(result.parameters, result.estimate, result.uncertainty, result.values,
                              result.value_uncertainty):
        rows.append({"parameter": p.name, "estimate": float(x), "uncertainty": float(s), "nominal_SI": p.nominal,
                     "value_SI": float(v), "uncertainty_SI": float(vs), "unit": _UNITS[p.kind]})
    return pd.DataFrame(rows)


_UNITS = {"tension": "N", "EI": "N m^2", "length": "m", "mass_per_length": "kg/m", "position": "m", "mass": "kg",
          "stiffness": "N/m", "end_stiffness": "N m/rad"}

_HEAD = ("mode", "measured (Hz)", "before (Hz)", "|δ| (%)", "corrected (Hz)", "|δ*| (%)")


def _fmt(x, digits: int) -> str:
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}f}"


def _rows(result, t) -> tuple[list[str], list[list[str]], list[str]]:
    labels = [k for k in result.shown_references if k in t.reference]
    head = list(_HEAD) + [h for k in labels for h in (f"{k} (Hz)", f"|δ| {k} (%)")]
    rows = []
    digits = min(4, max(2, round(-math.log10(printed_step(t.measured)))))
    for i, k in enumerate(t.modes):
        row = [str(k), _fmt(float(t.measured[i]), digits),
               _fmt(float(t.before[i]), 3), _fmt(abs(float(t.before_error[i])), 2),
               _fmt(float(t.after[i]), 3), _fmt(abs(float(t.after_error[i])), 2)]
        for label in labels:
            row += [_fmt(float(t.reference[label][i]), 2), _fmt(abs(float(t.reference_error(label)[i])), 2)]
        rows.append(row)
    rms = ["rms", "", "", _fmt(t.rms_before, 2), "", _fmt(t.rms_after, 2)]
    for label in labels:
        e = t.reference_error(label)
        rms += ["", _fmt(float(np.sqrt(np.nanmean(e**2))), 2)]
    rows.append(rms)
    return head, rows, labels


def _parameter_lines(result) -> list[list[str]]:
    out = []
    for p, x, s, v, vs in zip(result.parameters, result.estimate, result.uncertainty, result.values,
                              result.value_uncertainty):
        unit = _UNITS[p.kind]
        out.append([p.name, f"{x:.5g}", f"{s:.2g}", f"{_si(p.nominal)} {unit}", f"{_si(v)} ± {_si(vs)} {unit}"])
    return out


def _si(x: float) -> str:
    return "inf" if math.isinf(x) else f"{x:.5g}"


def _uncertainty_word(result) -> str:
    return "± 1 sd" if result.method == "lsq" else "± half region"


def result_markdown(result) -> str:
    """Parameters, then one before/after table per test, then the notes, as Markdown."""
    lines = [f"### Identified parameters ({result.method})", ""]
    head = ["parameter", "estimate", _uncertainty_word(result), "nominal", "value"]
    lines += _md_table(head, _parameter_lines(result))
    lines += ["", (f"chi2 = {result.chi2:.4g}, {result.dof} degrees of freedom; rms error "
                  f"{result.rms_before:.2f} % before, {result.rms_after:.2f} % after."), ""]
    for t in result.tests:
        head, rows, _ = _rows(result, t)
        lines += [f"#### {t.name} (setup {t.setup}; frequency uncertainty: {t.source})", ""]
        lines += _md_table(head, rows)
        lines.append("")
    if result.notes:
        lines += ["Notes:", ""] + [f"- {n}" for n in result.notes] + [""]
    return "\n".join(lines)


def result_text(result) -> str:
    """Parameters, before/after tables and notes as aligned plain text."""
    lines = [f"Identification ({result.method}): {', '.join(result.names)}", ""]
    head = ["parameter", "estimate", _uncertainty_word(result), "nominal", "value"]
    lines += _text_table(head, _parameter_lines(result))
    lines += ["", (f"chi2 {result.chi2:.4g}, {result.dof} degrees of freedom; rms error "
                  f"{result.rms_before:.2f} % before, {result.rms_after:.2f} % after"), ""]
    for t in result.tests:
        head, rows, _ = _rows(result, t)
        lines.append(f"Test {t.name} (setup {t.setup}; frequency uncertainty: {t.source})")
        lines += _text_table(head, rows)
        lines.append("")
    for n in result.notes:
        lines.append(f"note: {n}")
    return "\n".join(lines) + "\n"


def write_csv(result, path: str | os.PathLike) -> None:
    """The before/after table (``result.to_dataframe()``) as CSV."""
    result.to_dataframe().to_csv(path, index=False, float_format="%.6g")


def _md_table(head, rows) -> list[str]:
    head = [_md_cell(c) for c in head]
    rows = [[_md_cell(c) for c in r] for r in rows]
    out = ["| " + " | ".join(head) + " |", "|" + "|".join("---" if i == 0 else "--:" for i in range(len(head))) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return out


def _md_cell(text) -> str:
    return str(text).replace("|", "\\|")


def _text_table(head, rows) -> list[str]:
    widths = [max(len(str(c)) for c in col) for col in zip(head, *rows)]
    return ["  ".join(str(c).ljust(w) if i == 0 else str(c).rjust(w) for i, (c, w) in enumerate(zip(r, widths)))
            for r in [head, *rows]]
