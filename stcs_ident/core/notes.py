"""Notes: what a computation has to say about its result, kept as records.

A :class:`Note` holds the numbers and names of a remark (a scaled
covariance, a parameter at a bound, other minima that fit as well) beside a
template that says it in words. Results carry notes; only the formatting
module (:func:`stcs_ident.core.formatting.render_note`, which ``str(note)``
calls) turns them into sentences, and a step that needs a note's values in
other units works on its data (:meth:`Note.with_points`), never on its text.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, replace

from .formatting import render_note


@dataclass(frozen=True)
class Assignment:
    """One parameter's value in a note: ``parameter = value unit``.

    Attributes
    ----------
    parameter : str
        Display name (``EI_ratio``, ``position[W1]``).
    value : float
    unit : str
        Empty for a dimensionless variable (a ratio to nominal).
    """

    parameter: str
    value: float
    unit: str = ""


@dataclass(frozen=True)
class Note:
    """A remark about a result, as data.

    Attributes
    ----------
    kind : str
        What the note is about, for programs (``"covariance_scaled"``,
        ``"at_bound"``, ``"equally_well"``, ``"warning"``, ...).
    template : str
        The sentence, as a :meth:`str.format` template over the fields
        below: ``{value}``, ``{unit}``, ``{parameters}`` (the names joined
        by commas), ``{parameter}`` (the first name), ``{names}`` (the
        tuple, for ``{names[1]}``), ``{points}`` (the assignments, points
        separated by semicolons) and every key of ``data``.
    parameters : tuple of str
        The parameters the note names.
    value : float or None
        The note's main number (a reduced χ², a correlation, a count).
    unit : str
        Unit of ``value`` (empty when it has none).
    points : tuple of tuple of Assignment
        Parameter vectors the note quotes (other minima, mirror images),
        each a tuple of assignments.
    data : tuple of (str, object)
        Other named values the template uses.
    """

    kind: str
    template: str
    parameters: tuple[str, ...] = ()
    value: float | None = None
    unit: str = ""
    points: tuple[tuple[Assignment, ...], ...] = ()
    data: tuple[tuple[str, object], ...] = ()

    def __post_init__(self):
        if not self.kind:
            raise ValueError("a note needs a kind")

    @classmethod
    def make(cls, kind: str, template: str, *, parameters: Iterable[str] = (), value: float | None = None,
             unit: str = "", points: Iterable[Iterable[Assignment]] = (), **data) -> Note:
        """A note from keyword data (``Note.make("k", "{count} left", count=3)``)."""
        return cls(kind, template, tuple(parameters), value, unit, tuple(tuple(p) for p in points),
                   tuple(sorted(data.items())))

    @classmethod
    def plain(cls, kind: str, text: str) -> Note:
        """A note that is a finished sentence (a warning's message, say): its braces are kept as text."""
        return cls(kind, text.replace("{", "{{").replace("}", "}}"))

    def field(self, name: str, default=None):
        """The ``data`` value ``name``."""
        return dict(self.data).get(name, default)

    def with_points(self, points: Iterable[Iterable[Assignment]]) -> Note:
        """The same note quoting other assignments (the same point in other units, say)."""
        return replace(self, points=tuple(tuple(p) for p in points))

    def __str__(self) -> str:
        return render_note(self)


def point(names: Iterable[str], values: Iterable[float], units: Iterable[str] | None = None) -> tuple[Assignment, ...]:
    """One parameter vector as assignments (``units`` default: none)."""
    names, values = list(names), [float(v) for v in values]
    units = [""] * len(names) if units is None else list(units)
    return tuple(Assignment(n, v, u) for n, v, u in zip(names, values, units))
