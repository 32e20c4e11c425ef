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

import pandas as pd

from ..core import files
from ..core.formatting import STYLES, number, plus_minus, rms, table_lines
from ..identify.problem import printed_step


def parameters_table(result) -> pd.DataFrame:
    """One row per parameter (``result.parameter_table()``): ``value``, ``uncertainty`` and ``nominal`` in the
    row's ``unit``, and the fit's dimensionless ``variable`` with its ``variable_uncertainty``."""
    return result.parameter_table()


_HEAD = ("mode", "measured (Hz)", "before (Hz)", "|δ| (%)", "corrected (Hz)", "|δ*| (%)")


def _rows(result, t) -> tuple[list[str], list[list[str]], list[str]]:
    labels = [k for k in result.shown_references if k in t.reference]
    head = list(_HEAD) + [h for k in labels for h in (f"{k} (Hz)", f"|δ| {k} (%)")]
    rows = []
    digits = min(4, max(2, round(-math.log10(printed_step(t.measured)))))
    measured = f"{{:.{digits}f}}"
    for i, k in enumerate(t.modes):
        row = [_mode(k, t.mode_planes[i]), number(t.measured[i], measured), number(t.before[i]), number(abs(t.before_error[i]), "{:.2f}"),
               number(t.after[i]), number(abs(t.after_error[i]), "{:.2f}")]
        for label in labels:
            row += [number(t.reference[label][i], "{:.2f}"), number(abs(t.reference_error(label)[i]), "{:.2f}")]
        rows.append(row)
    last = ["rms", "", "", number(t.rms_before, "{:.2f}"), "", number(t.rms_after, "{:.2f}")]
    for label in labels:
        last += ["", number(rms(t.reference_error(label)), "{:.2f}")]
    rows.append(last)
    return head, rows, labels


def _mode(k: int, plane: str) -> str:
    """A mode's name in a table: ``3`` in-plane, ``3 out`` out-of-plane."""
    return str(k) if plane == "in" else f"{k} out"


def _damping_rows(t) -> list[list[str]]:
    z = t.damping
    return [[_mode(k, t.mode_planes[i])] + [number(100 * z[key][i], "{:.3f}") for key in ("measured", "uncertainty", "before", "after")]
            for i, k in enumerate(t.modes) if math.isfinite(z["measured"][i])]


def _parameter_lines(result) -> list[list[str]]:
    out = []
    for p, x, s, v, vs in zip(result.parameters, result.estimate, result.uncertainty, result.values,
                              result.value_uncertainty):
        unit = p.unit
        out.append([p.name, f"{x:.5g}", f"{s:.2g}", plus_minus(p.nominal, None, unit, digits=5),
                    plus_minus(v, vs, unit, digits=5)])
    return out


def _uncertainty_word(result) -> str:
    return "± 1 sd" if result.method == "lsq" else "± half region"


def format_result(result, style: str = "text") -> str:
    """Parameters, one before/after table per test and the notes, as aligned text or Markdown.

    Parameters
    ----------
    result : IdentificationResult
    style : {"text", "markdown"}
        ``text``: the CLI's standard output; ``markdown``: headings and pipe
        tables for a report.
    """
    if style not in STYLES:
        raise ValueError(f"style must be one of {STYLES}, got {style!r}")
    md = style == "markdown"
    lines = [f"### Identified parameters ({result.method})" if md
             else f"Identification ({result.method}): {', '.join(result.names)}", ""]
    head = ["parameter", "estimate", _uncertainty_word(result), "nominal", "value"]
    lines += table_lines(head, _parameter_lines(result), style)
    chi2 = f"chi2 = {result.chi2:.4g}" if md else f"chi2 {result.chi2:.4g}"
    lines += ["", (f"{chi2}, {result.dof} degrees of freedom; rms error {result.rms_before:.2f} % before, "
                   f"{result.rms_after:.2f} % after{'.' if md else ''}"), ""]
    for t in result.tests:
        head, rows, _ = _rows(result, t)
        title = f"{t.name} (setup {t.setup}; frequency uncertainty: {t.source})"
        lines += [f"#### {title}", ""] if md else [f"Test {title}"]
        lines += table_lines(head, rows, style)
        lines.append("")
        if t.damping:
            lines += [f"Damping ratios of {t.name} (%; the model's include the cable's own, fitted)", ""]
            lines += table_lines(["mode", "measured", "± 1 sd", "before", "corrected"], _damping_rows(t), style)
            lines.append("")
    if md and result.notes:
        lines += ["Notes:", ""] + [f"- {n}" for n in result.notes] + [""]
    elif not md:
        lines += [f"note: {n}" for n in result.notes]
    return "\n".join(lines) + ("" if md else "\n")


def write_csv(result, path: str | os.PathLike) -> None:
    """The before/after table (``result.to_dataframe()``) as CSV, whole or not at all."""
    files.write_csv(result.to_dataframe(), path, index=False, float_format="%.6g")


#: File names of :func:`write_tables`, in the ``--plot`` directory.
PARAMETERS_CSV, FREQUENCIES_CSV = "parameters.csv", "frequencies.csv"


def write_tables(result, directory: str | os.PathLike) -> list[str]:
    """The identification's tables as CSV in ``directory`` (created), each whole or not at all.

    ``parameters.csv`` (:func:`parameters_table`: one row per parameter) and ``frequencies.csv``
    (:func:`write_csv`: the before/after table, one row per test and mode). Returns the paths.
    """
    os.makedirs(directory, exist_ok=True)
    parameters, frequencies = os.path.join(directory, PARAMETERS_CSV), os.path.join(directory, FREQUENCIES_CSV)
    files.write_csv(parameters_table(result), parameters, index=False, float_format="%.6g")
    write_csv(result, frequencies)
    return [parameters, frequencies]
