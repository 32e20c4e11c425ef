"""How numbers, tables and notes are written, in one place.

Every text output of the toolkit (terminal tables, Markdown reports, the
JSON's note sentences) formats through these helpers, so that a missing
value, a value with its uncertainty or a note reads the same everywhere.
Nothing here computes a result; nothing parses text back.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

#: What a table shows for a missing value (None, NaN).
MISSING = "-"
#: Table styles of :func:`table_lines`.
STYLES = ("text", "markdown")


def percent_error(computed, measured):
    """(computed − measured) / measured × 100, elementwise."""
    measured = np.asarray(measured, float)
    return (np.asarray(computed, float) - measured) / measured * 100.0


def rms(values) -> float:
    """Root mean square of ``values``, NaN left out (NaN when none is left)."""
    a = np.asarray(values, float)
    a = a[~np.isnan(a)]
    return float(np.sqrt(np.mean(a**2))) if a.size else math.nan


def is_missing(value, finite_only: bool = False) -> bool:
    """None or NaN (or ±inf with ``finite_only``); strings and booleans are never missing."""
    if value is None:
        return True
    if isinstance(value, (str, bool, np.bool_)):
        return False
    try:
        x = float(value)
    except (TypeError, ValueError):
        return False
    return not math.isfinite(x) if finite_only else math.isnan(x)


def number(value, fmt: str = "{:.3f}", *, width: int = 0, finite_only: bool = False) -> str:
    """``fmt.format(value)``, or :data:`MISSING` for a missing value; right-aligned in ``width``."""
    text = MISSING if is_missing(value, finite_only) else fmt.format(value)
    return text.rjust(width)


def percent(value, digits: int = 3) -> str:
    """``1.234 %``, or :data:`MISSING` when the value is missing or not finite."""
    return number(value, f"{{:.{digits}f}} %", finite_only=True)


def plus_minus(value: float, sigma: float | None, digits: int = 3, sigma_digits: int = 2) -> str:
    """``1.02 ± 0.0031`` (``digits`` and ``sigma_digits`` significant); the value alone when the
    uncertainty is unknown or not finite."""
    if sigma is None or not math.isfinite(sigma):
        return f"{value:.{digits}g}"
    return f"{value:.{digits}g} ± {sigma:.{sigma_digits}g}"


def cell(value, fmt: str = "{}") -> str:
    """One table cell: strings as they are, booleans ``yes`` or empty, missing values :data:`MISSING`."""
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else ""
    return number(value, fmt)


def table_lines(head: Sequence, rows: Sequence[Sequence], style: str = "text",
                align: Sequence[str] | None = None) -> list[str]:
    """A table as lines: ``style="markdown"`` a pipe table (``|`` in cells escaped), ``"text"`` columns
    padded to their width and separated by two spaces.

    ``align`` gives ``"left"`` or ``"right"`` per column (default: the first
    column left, the others right).
    """
    if style not in STYLES:
        raise ValueError(f"style must be one of {STYLES}, got {style!r}")
    head = [str(c) for c in head]
    rows = [[str(c) for c in r] for r in rows]
    align = list(align) if align is not None else ["left"] + ["right"] * (len(head) - 1)
    if style == "markdown":
        def escape(row):
            return [c.replace("|", "\\|") for c in row]

        out = ["| " + " | ".join(escape(head)) + " |",
               "|" + "|".join(":---" if a == "left" else "---:" for a in align) + "|"]
        return out + ["| " + " | ".join(escape(r)) + " |" for r in rows]
    widths = [max(len(c) for c in col) for col in zip(head, *rows)]
    return ["  ".join(c.ljust(w) if a == "left" else c.rjust(w) for c, w, a in zip(r, widths, align))
            for r in [head, *rows]]


def markdown_table(frame, formats: Mapping[str, str] | None = None, columns: Mapping[str, str] | None = None) -> str:
    """A pipe table of a DataFrame: ``formats`` {column: "{:.3f}"}, ``columns`` {column: header} (and
    order); numeric columns right-aligned, the others left."""
    import pandas as pd

    formats = formats or {}
    columns = columns or {c: c for c in frame.columns}
    align = ["right" if pd.api.types.is_numeric_dtype(frame[c]) and not pd.api.types.is_bool_dtype(frame[c])
             else "left" for c in columns]
    rows = []
    for row in frame.itertuples(index=False):
        record = dict(zip(frame.columns, row))
        rows.append([cell(record[c], formats.get(c, "{}")) for c in columns])
    return "\n".join(table_lines(list(columns.values()), rows, "markdown", align)) + "\n"


def render_assignment(a) -> str:
    """``name = value`` (six significant digits), with the unit when there is one (``a``: a
    :class:`~stcs_ident.core.notes.Assignment`)."""
    return f"{a.parameter} = {a.value:.6g}" + (f" {a.unit}" if a.unit else "")


def render_points(points) -> str:
    """Assignments of one point joined by commas, points by semicolons."""
    return "; ".join(", ".join(render_assignment(a) for a in p) for p in points)


def render_note(note) -> str:
    """The sentence of ``note``: its template filled with its fields (see :class:`~stcs_ident.core.notes.Note`)."""
    names = tuple(note.parameters)
    fields = {"value": note.value, "unit": note.unit, "parameters": ", ".join(names),
              "parameter": names[0] if names else "", "names": names, "points": render_points(note.points)}
    fields.update(dict(note.data))
    return note.template.format(**fields)


def counted(n: int, noun: str, plural: str | None = None) -> str:
    """A count with its noun in the right number: ``1 test``, ``0 tests``, ``2 hypotheses``.

    Parameters
    ----------
    n : int
    noun : str
        The singular.
    plural : str, optional
        The plural when it is not ``noun + "s"``.
    """
    return f"{n} {noun if n == 1 else plural or noun + 's'}"
