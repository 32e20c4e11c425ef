"""The header line of a text record written after a preamble (HBM catman, Dewesoft and many DAQ exports).

Such a file opens with metadata lines (``File: run3.bin``, ``Sample rate: 200 Hz``) before the line that names
the columns. The reader option ``header_row`` gives that line's number (0-based); without it
:func:`find_header` looks for it: the data block is the run of numeric rows, all of one field count, that the
file's beginning ends with; the header is the last line before it with as many fields, passing over a units
row (``s;g;g``) just above the data. Where every line before the data block has the data's field count (no
preamble) the header is line 0, as for any CSV, and a units row under it is left to the CSV reader's own
refusal (``skip_rows = [1]``). Where no data block is found the header is line 0 too, and the CSV reader's
checks say what is wrong.
"""

from __future__ import annotations

import csv
import re

__all__ = ["HEAD_LINES", "find_header", "looks_like_units"]

#: Lines of a file's beginning looked at for its header (a preamble longer than this needs ``header_row``).
HEAD_LINES = 2000
#: Characters of a file's beginning looked at (a long line counts as many).
HEAD_CHARS = 1 << 20

_DATE_TIME = re.compile(r"\d[\d\-/. :T]*\d(Z|[+-]\d\d:?\d\d)?")
#: Unit spellings a units row under a header holds (lower case, without brackets), beside those of acceleration.
_UNIT_WORDS = {
    "s", "sec", "ms", "us", "µs", "min", "h", "hz", "v", "mv", "µv", "uv", "a", "ma", "°c", "degc", "c", "k", "%",
    "-", "ts", "rn", "n", "kn", "mn", "m", "mm", "µm", "um", "m/s", "mm/s", "µm/m", "um/m", "ustrain", "µstrain",
    "m/s^2", "m/s²", "m/s2", "mm/s^2", "mm/s²", "mm/s2", "m s^-2", "m s-2", "g", "mg", "volts", "deg", "°", "rad",
}


def _fields(line: str, separator: str) -> list[str]:
    try:
        return [field.strip() for field in next(csv.reader([line], delimiter=separator), [])]
    except csv.Error:
        return [line]


def _is_number(text: str, decimal: str) -> bool:
    if decimal != "." and "." in text:
        return False
    try:
        float(text.replace(decimal, "."))
    except ValueError:
        return False
    return True


def _is_data(fields: list[str], decimal: str) -> bool:
    """A row of numbers (date-times and empty cells allowed among them), at least one a number."""
    numbers = 0
    for text in fields:
        if not text:
            continue
        if _is_number(text, decimal):
            numbers += 1
        elif not (":" in text and _DATE_TIME.fullmatch(text)):
            return False
    return numbers > 0


def looks_like_units(fields: list[str]) -> bool:
    """Whether every non-empty field is a unit (``s``, ``[g]``, ``(m/s²)``), and at least one is."""
    units = [text.strip("[]() ").lower() for text in fields if text.strip("[]() ")]
    return bool(units) and all(unit in _UNIT_WORDS for unit in units)


def find_header(file: str, separator: str, decimal: str) -> tuple[int, tuple[str, ...]]:
    """The header line of ``file`` (0-based) and the note saying it was found, if it is not line 0.

    Reads at most :data:`HEAD_LINES` lines (:data:`HEAD_CHARS` characters); an unreadable file gives line 0
    (the reader then says what is wrong).
    """
    lines: list[str] = []
    cut = False
    try:
        with open(file, encoding="utf-8-sig", errors="replace", newline="") as stream:
            size = 0
            for line in stream:
                if len(lines) >= HEAD_LINES or size > HEAD_CHARS:
                    cut = True
                    break
                lines.append(line.rstrip("\r\n"))
                size += len(line)
    except OSError:
        return 0, ()
    if cut and lines:
        lines.pop()  # the last line read may be a data row cut short: not looked at
    rows = [_fields(line, separator) if line.strip() else [] for line in lines]
    end = len(rows) - 1
    while end >= 0 and not rows[end]:
        end -= 1
    if end < 0 or not _is_data(rows[end], decimal):
        return 0, ()
    width = len(rows[end])
    start = end
    while start > 0 and len(rows[start - 1]) == width and _is_data(rows[start - 1], decimal):
        start -= 1
    run = start
    while run > 0 and len(rows[run - 1]) == width:
        run -= 1
    if run == start:  # no line of the data's width before the data: no header
        return 0, ()
    if run == 0:  # every line above the data is as wide: no preamble
        return 0, ()
    header = next((i for i in range(start - 1, run - 1, -1) if not looks_like_units(rows[i])), run)
    return header, ((f"header line found at line {header} (0-based) after a preamble of {header} line(s), "
                     f"{width} columns: give header_row = {header} in record_format to set it"),)
