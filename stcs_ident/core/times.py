"""The one rule for a record's start time: an ISO 8601 instant the table of ``track`` can hold.

Every reader checks a record's ``start_time`` with :func:`check_instant`,
the campaign's ``record_format.start_time`` option with
:func:`instant_problem`, and ``track`` converts its table's column with the
same rule (:func:`stcs_ident.io.tables.instant_column`), so a time the
reader accepts is a time the table holds: never a time read as "not a
time" (``NaT``) beside the status ``ok``.

The rule, strict:

- the ISO 8601 calendar form, extended: ``YYYY-MM-DD``, optionally
  followed by ``T`` (or a space) and ``hh:mm``, ``hh:mm:ss`` or
  ``hh:mm:ss.f`` (1 to 9 digits: nanoseconds are kept), optionally
  followed by ``Z`` or an offset ``±hh:mm``. A date alone is its midnight;
  a time without offset is UTC. Week dates (``2026-W10-2``), ordinal dates
  (``2026-063``) and the basic form (``20260303T100000``) are refused:
  Python reads some of them and pandas none, and a time that two readers
  read differently is not a time;
- a real date and time of day (no 30 February, no 24:00);
- within the range of a nanosecond time stamp (the table's type), taken
  inward to whole days: from 1677-09-22 to 2262-04-10 included (UTC).
"""

from __future__ import annotations

import re
from datetime import UTC, datetime
from typing import Any

from .errors import InputError

__all__ = ["EARLIEST", "LATEST", "check_instant", "instant_problem"]

#: The first and last instants a start time may be (UTC; the range of a nanosecond time stamp, inward to whole
#: days).
EARLIEST = datetime(1677, 9, 22, tzinfo=UTC)
LATEST = datetime(2262, 4, 11, tzinfo=UTC)

_FORM = re.compile(r"\d{4}-\d{2}-\d{2}(?:[T ]\d{2}:\d{2}(?::\d{2}(?:\.\d{1,9})?)?)?(?:Z|[+-]\d{2}:\d{2})?")


def instant_problem(value: Any) -> str | None:
    """What keeps ``value`` from being a start time under the rule of this module (None: nothing)."""
    if not isinstance(value, str):
        return f"is not an ISO 8601 time: {value!r} (a text is needed)"
    if _FORM.fullmatch(value) is None:
        return (f"is not an ISO 8601 time: {value!r} (expected YYYY-MM-DD[Thh:mm[:ss[.f]]][Z|±hh:mm]; week and "
                "ordinal dates and the basic form are not read)")
    try:
        parsed = datetime.fromisoformat(value)  # nanoseconds read to the microsecond: enough for the range
    except ValueError as err:
        return f"is not an ISO 8601 time: {value!r} ({err})"
    instant = parsed.replace(tzinfo=UTC) if parsed.tzinfo is None else parsed
    try:
        inside = EARLIEST <= instant < LATEST
    except OverflowError:  # an offset that pushes year 1 or 9999 beyond what datetime holds
        inside = False
    if not inside:
        return (f"is out of range: {value!r} (a start time must lie from {EARLIEST:%Y-%m-%d} (included) to "
                f"{LATEST:%Y-%m-%d} (excluded) UTC, the range of a nanosecond time stamp)")
    return None


def check_instant(value: Any, *, field: str = "start_time", file: str | None = None) -> str:
    """``value`` if it is a start time under the rule of this module, else an
    :class:`~stcs_ident.core.errors.InputError` naming ``field`` and ``file``."""
    problem = instant_problem(value)
    if problem is not None:
        raise InputError(problem, field=field, file=file)
    return value
