"""How numbers, tables and notes are written, in one place.

Every text output of the toolkit (terminal tables, Markdown reports, the
JSON's note sentences) formats through these helpers, so that a missing
value, a value with its uncertainty or a note reads the same everywhere.
Nothing here computes a result; nothing parses text back.
"""

from __future__ import annotations

from .notes import Assignment, Note


def render_assignment(a: Assignment) -> str:
    """``name = value`` (six significant digits), with the unit when there is one."""
    return f"{a.parameter} = {a.value:.6g}" + (f" {a.unit}" if a.unit else "")


def render_points(points) -> str:
    """Assignments of one point joined by commas, points by semicolons."""
    return "; ".join(", ".join(render_assignment(a) for a in p) for p in points)


def render_note(note: Note) -> str:
    """The sentence of ``note``: its template filled with its fields (see :class:`~stcs_ident.notes.Note`)."""
    names = tuple(note.parameters)
    fields = {"value": note.value, "unit": note.unit, "parameters": ", ".join(names),
              "parameter": names[0] if names else "", "names": names, "points": render_points(note.points)}
    fields.update(dict(note.data))
    return note.template.format(**fields)
