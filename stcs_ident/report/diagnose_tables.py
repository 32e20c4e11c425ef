"""The tables of a diagnosis report: made by :mod:`stcs_ident.diagnose.tables` (data), named here as files."""

from __future__ import annotations

from ..diagnose.tables import (
    cause_table,
    damping_table,
    effects_label,
    frequency_table,
    gain_table,
    nominal_comparison,
    parameter_rows,
    ranking_table,
)

__all__ = ["CSV_FILES", "cause_table", "damping_table", "effects_label", "frequency_table", "gain_table",
           "nominal_comparison", "parameter_rows", "ranking_table"]

#: Files of the report, besides the figures.
CSV_FILES = ("ranking.csv", "frequencies.csv", "gain.csv", "nominal_comparison.csv", "cause.csv")
