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


#: Units shown with an engineering prefix (kN, MN) by :func:`plus_minus`: forces and the quantities built on them.
PREFIXED_UNITS = ("N", "N/m", "N s/m", "N m/rad", "N m^2", "N m²")
#: Magnitudes outside [SCIENTIFIC_BELOW, SCIENTIFIC_FROM) are written as ``(m ± s)e+XX`` by :func:`plus_minus`.
SCIENTIFIC_BELOW = 1e-3
SCIENTIFIC_FROM = 1e6


def _prefixed(value: float, sigma: float | None, unit: str) -> tuple[float, float | None, str]:
    """``value`` and ``sigma`` in kN or MN (MN from 10⁶) when ``unit`` is force-based; as they are otherwise
    (also from 10⁹, where the shared exponent of :func:`plus_minus` reads better than a prefix)."""
    size = max(abs(value), sigma or 0.0)
    if unit not in PREFIXED_UNITS or size >= 1e9:
        return value, sigma, unit
    for factor, prefix in ((1e6, "M"), (1e3, "k")):
        if size >= factor:
            return value / factor, None if sigma is None else sigma / factor, prefix + unit
    return value, sigma, unit


def _decimal_place(sigma: float, sigma_digits: int) -> int:
    """Decimals that keep ``sigma_digits`` significant digits of ``sigma`` > 0, once rounded there
    (0.0996 → 0.10: 2 decimals, not 3)."""
    decimals = sigma_digits - 1 - math.floor(math.log10(sigma))
    rounded = round(sigma, decimals)
    return sigma_digits - 1 - math.floor(math.log10(rounded))


def _fixed(value: float, decimals: int) -> str:
    """``value`` rounded to ``decimals`` (negative: to tens, hundreds, ...), without a sign on zero."""
    x = round(value, decimals) + 0.0  # + 0.0 turns -0.0 into 0.0
    return f"{x:.{max(decimals, 0)}f}"


def plus_minus(value: float | None, sigma: float | None, unit: str = "", *, digits: int = 3,
               sigma_digits: int = 2) -> str:
    """A value with its standard uncertainty as a reader expects it: ``9.5984 ± 0.0015 kg``.

    The uncertainty keeps ``sigma_digits`` significant digits and the value is
    rounded to the same decimal place, so it carries the digits the
    uncertainty supports and no more. Force-based units (:data:`PREFIXED_UNITS`)
    take an engineering prefix: ``1248.7 ± 4.2 kN``, ``5.0012 ± 0.0042 MN``.
    Magnitudes far from 1 are written with a shared exponent,
    ``(3.553 ± 0.010)e+21``.

    Parameters
    ----------
    value : float or None
        The value; missing (None, NaN) gives :data:`MISSING`.
    sigma : float or None
        Its standard uncertainty. Unknown (None, NaN, ±inf) gives the value
        alone with ``digits`` significant digits; 0 gives the value with
        ``digits`` significant digits and ``± 0``. A negative σ is read as its
        magnitude.
    unit : str, optional
        Appended after a space; force-based units are prefixed.
    digits : int, optional
        Significant digits of a value shown without a usable uncertainty.
    sigma_digits : int, optional
        Significant digits of the uncertainty.

    Returns
    -------
    str
    """
    if is_missing(value):
        return MISSING
    value = float(value)
    known = sigma is not None and math.isfinite(sigma)
    sigma = abs(float(sigma)) if known else None
    if not math.isfinite(value):
        return f"{value}" + (f" {unit}" if unit else "")
    value, sigma, unit = _prefixed(value, sigma, unit)
    tail = f" {unit}" if unit else ""
    if sigma is None:
        return f"{value:.{digits}g}{tail}"
    if sigma == 0.0:
        return f"{value:.{digits}g} ± 0{tail}"
    decimals = _decimal_place(sigma, sigma_digits)
    size = max(abs(value), sigma)
    if SCIENTIFIC_BELOW <= size < SCIENTIFIC_FROM:
        return f"{_fixed(value, decimals)} ± {_fixed(sigma, decimals)}{tail}"
    exponent = math.floor(math.log10(size))
    scale = 10.0**exponent
    decimals += exponent
    return f"({_fixed(value / scale, decimals)} ± {_fixed(sigma / scale, decimals)})e{exponent:+03d}{tail}"


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
