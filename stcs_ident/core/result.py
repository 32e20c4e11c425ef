"""The one shape every result shares: settings, notes, ``summary()``, ``tables()`` and a short face.

A step returns one result object (lmfit's ``MinimizerResult``, SciPy's
``OptimizeResult``). Whatever the step, the result answers the same few
questions the same way:

- ``settings``: how it was made (a :class:`~stcs_ident.core.settings.Settings`
  or the step's own options; None where the step has none);
- ``notes``: what the computation has to say, as records
  (:class:`~stcs_ident.core.notes.Note`; ``()`` when it says nothing);
- ``summary()``: plain data that serialises to JSON (the command line's
  ``--json``);
- ``tables()``: the result's tables as named pandas DataFrames (the CSV
  files of a report), and ``to_dataframe()`` its main table;
- ``repr(result)``: what it is, how many, the headline numbers, in a few
  lines; ``_repr_html_()``: the main table as HTML under a title (a
  notebook shows it when the result is the cell's value).

:class:`Result` gives the last three from two hooks a result defines:
:meth:`Result.headline` (one line of words) and :attr:`Result.main_table`
(the name of the table ``to_dataframe()`` and the notebook show). A
dataclass using it is declared with ``repr=False`` so that the dataclass's
field dump does not replace the short ``__repr__``.
"""

from __future__ import annotations

import html
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pandas is the results' own dependency; this module imports nothing heavy
    import pandas as pd

__all__ = ["Result"]


class Result:
    """Mixin of the common face of results (see the module docstring).

    A subclass defines :meth:`summary`, :meth:`tables`, :meth:`headline`,
    :attr:`main_table`, and ``settings`` and ``notes`` (fields, or
    properties giving None and ``()`` for a step that has neither).
    """

    # Annotations only: a value here would become the default of the dataclass fields of that name.
    #: How the result was made (a field or property of every result).
    settings: Any
    #: Remarks as records (a field or property of every result).
    notes: tuple
    #: The key of :meth:`tables` that :meth:`to_dataframe` and :meth:`_repr_html_` show.
    main_table: str = ""

    def summary(self) -> dict:
        """Plain data for JSON."""
        raise NotImplementedError

    def tables(self) -> dict[str, pd.DataFrame]:
        """The result's tables by name (one DataFrame each)."""
        raise NotImplementedError

    def headline(self) -> str:
        """What the result is, in one line: how many, the headline numbers."""
        raise NotImplementedError

    def to_dataframe(self) -> pd.DataFrame:
        """The main table (``tables()[main_table]``)."""
        return self.tables()[self.main_table]

    def __repr__(self) -> str:
        lines = [f"<{type(self).__name__}: {self.headline()}>"]
        if self.notes:
            lines.append(f"  {len(self.notes)} note{'s' if len(self.notes) != 1 else ''} (.notes)")
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        """The main table as HTML under a title (what a notebook shows)."""
        title = f"<p><b>{html.escape(type(self).__name__)}</b>: {html.escape(self.headline())}</p>"
        table = self.tables()[self.main_table]
        return title + table.to_html(index=False, max_rows=30, float_format=lambda x: f"{x:.6g}", na_rep="")
