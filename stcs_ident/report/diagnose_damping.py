"""The damping ratios of a diagnosis with a damper in question, measured against the nominal and the chosen
model: the terminal's and the report's tables and their reading.

The numbers come from :func:`~stcs_ident.diagnose.tables.damping_table` (ratios; shown here in %); the
figure is :func:`~stcs_ident.report.diagnose_figures.plot_damping`. A diagnosis whose damping ratios are
not data (a cable without a damper) has no such table, and nothing here is shown.
"""

from __future__ import annotations

import math

import pandas as pd

from ..core.formatting import number, table_lines
from ..identify.problem import DAMPING_SPREAD

__all__ = ["DAMPING_CSV", "DAMPING_PNG", "damping_lines", "damping_reading"]

#: The report's damping table and figure (written only when the damping ratios are data).
DAMPING_CSV = "damping.csv"
DAMPING_PNG = "damping.png"

_HEAD = ["mode", "plane", "measured % ± 1σ", "nominal %", "z", "corrected %", "z"]


def _measured(zeta: float, sigma: float) -> str:
    """``ζ ± σ`` in %, three decimals each (the spectra table's)."""
    if math.isnan(sigma):
        return number(100 * zeta, "{:.3f}")
    return f"{100 * zeta:.3f} ± {100 * sigma:.3f}"


def _rows(frame: pd.DataFrame) -> list[list[str]]:
    return [[str(int(r.mode)), r.plane, _measured(r.measured_damping_ratio, r.damping_ratio_uncertainty),
             number(100 * r.nominal_damping_ratio, "{:.3f}"), number(r.nominal_z, "{:+.2f}"),
             number(100 * r.corrected_damping_ratio, "{:.3f}"), number(r.corrected_z, "{:+.2f}")]
            for r in frame.itertuples(index=False)]


def damping_reading(table: pd.DataFrame, corrected_label: str) -> str:
    """What the damping table shows and how its z is made, with the χ² share of each model (from the table)."""
    n = len(table)
    nominal, corrected = (float((table[f"{k}_z"] ** 2).sum()) for k in ("nominal", "corrected"))
    return (f"Damping ratios (%): measured ± 1σ (spectra), the nominal model's and the corrected model's "
            f"({corrected_label}); a model's ratio is its dampers' (−Re(s)/|s| of the complex modes) plus the "
            f"cable's own ratio, one for all modes, fitted to the data. z = (measured − model)/σ, σ the 1σ with "
            f"{100 * DAMPING_SPREAD:g} % (the mode-to-mode spread of a cable's own damping) added in quadrature, "
            f"as the diagnosis weighs the ratios; Σz² over the {n} ratios: nominal {nominal:.3g}, corrected "
            f"{corrected:.3g}.")


def damping_lines(table: pd.DataFrame, corrected_label: str, style: str = "text") -> list[str]:
    """The damping ratios per test as lines (``style`` ``text`` for the terminal, ``markdown`` for the report);
    no lines for an empty table (no damper in question)."""
    if table.empty:
        return []
    md = style == "markdown"
    lines = [damping_reading(table, corrected_label), ""]
    for test, frame in table.groupby("test", sort=False):
        lines += [f"### {test}: damping ratios", ""] if md else [f"Test {test}"]
        lines += table_lines(_HEAD, _rows(frame), style, align=["right", "left"] + ["right"] * 5)
        lines.append("")
    return lines
