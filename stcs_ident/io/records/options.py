"""Reader options: what a campaign's ``record_format`` may tell the record readers.

One table, :data:`OPTIONS`, names every option and the kind of its value;
:func:`option_problem` says what is wrong with a value (the campaign parser
turns it into an error naming the key, :func:`check_options` into one naming
the record file), :func:`option_value` gives the value as the readers take
it. Each reader uses the options that apply to its format and ignores the
others: one campaign may give options for several formats. ``channels``,
``header_row`` and ``skip_rows`` apply to text files (CSV, TOA5 and LVM as
their readers say); ``override_sampling_rate`` to every format whose file has
a rate of its own (:mod:`~stcs_ident.io.records.rates`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from datetime import datetime
from typing import Any

from ...core.errors import InputError
from ...core.times import instant_problem
from .directions import axes_problem, axes_value
from .validation import UNITS

__all__ = ["OPTIONS", "check_options", "option_problem", "option_value"]

#: Every reader option, with what its value must be.
OPTIONS = {
    "unit": "a unit of acceleration (" + ", ".join(UNITS) + ")",
    "sampling_rate": "a number of Hz > 0",
    "time_column": "a non-empty string (the time column's name)",
    "separator": "one character (the column separator)",
    "decimal": "one character (the decimal mark)",
    "skip_rows": "a list of line numbers >= 1 (0-based, the header is line 0)",
    "header_row": "a line number >= 0 (0-based: the file's line that names the columns, after a preamble)",
    "channels": "a list of column names, at least one, each once (the acceleration channels of a text file)",
    "override_sampling_rate": "true or false (whether sampling_rate replaces a rate of the file's that differs)",
    "start_time": "an ISO 8601 date-time, YYYY-MM-DD[Thh:mm[:ss[.f]]][Z|±hh:mm], from 1677-09-22 to 2262-04-10",
    "temperature": "a number of degC",
    "variable": "a non-empty string (the MATLAB variable)",
    "group": "a non-empty string (the TDMS group)",
    "axes": 'a table placing the file\'s axes on the cable, { X = "axial", Y = "in", Z = "out" } say '
            '(UFF, TDMS, SEP005 and HDF5 channels whose direction is an axis X, Y or Z)',
}


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def option_problem(key: str, value: Any) -> str | None:
    """What is wrong with ``value`` for option ``key`` (None: nothing); an unknown key is a problem too."""
    if key not in OPTIONS:
        return f"unknown key {key!r}; expected one of: {', '.join(OPTIONS)}"
    if key == "axes":
        return axes_problem(value)
    must = f"must be {OPTIONS[key]}, got {value!r}"
    if key in ("sampling_rate", "temperature"):
        ok = _is_number(value) and math.isfinite(value) and (key != "sampling_rate" or value > 0)
    elif key in ("separator", "decimal"):
        ok = isinstance(value, str) and len(value) == 1 and value not in "\r\n\"" and (key != "decimal" or value != " ")
    elif key == "skip_rows":
        ok = isinstance(value, list | tuple) and all(isinstance(v, int) and not isinstance(v, bool) and v >= 1
                                                     for v in value)
    elif key == "start_time":
        ok = instant_problem(value.isoformat() if isinstance(value, datetime) else value) is None
    elif key == "header_row":
        ok = isinstance(value, int) and not isinstance(value, bool) and value >= 0
    elif key == "channels":
        ok = (isinstance(value, list | tuple) and len(value) > 0
              and all(isinstance(v, str) and v.strip() == v and bool(v) for v in value)
              and len(set(value)) == len(value))
    elif key == "override_sampling_rate":
        ok = isinstance(value, bool)
    elif key == "unit":
        ok = isinstance(value, str) and value.strip() in UNITS
    else:
        ok = isinstance(value, str) and bool(value)
    return None if ok else must


def option_value(key: str, value: Any) -> Any:
    """``value`` (checked) as the readers take it: rows as a tuple, a TOML date-time as ISO 8601 text, axes as
    (axis, direction) pairs in the order X, Y, Z."""
    if key == "skip_rows":
        return tuple(int(v) for v in value)
    if key == "channels":
        return tuple(value)
    if key == "axes":
        return axes_value(value)
    if key == "start_time" and isinstance(value, datetime):
        return value.isoformat()
    if key in ("sampling_rate", "temperature"):
        return float(value)
    return value


def check_options(options: Mapping[str, Any], file: str | None = None) -> dict[str, Any]:
    """The options as the readers take them; a wrong key or value is an InputError naming ``file`` and the key."""
    out = {}
    for key, value in options.items():
        if value is None:
            continue
        problem = option_problem(key, value)
        if problem is not None:
            raise InputError(f"record_format: {problem}", field=key, file=file)
        out[key] = option_value(key, value)
    return out


