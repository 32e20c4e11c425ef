"""Checks of option values, and the frozen group of options they validate (:mod:`.options`).

Each check returns what is wrong with a value, or None; an :class:`OptionGroup` runs its fields' checks
when built and raises :class:`~stcs_ident.core.errors.InputError` naming ``"<group>.<option>"``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import fields
from typing import ClassVar

import numpy as np

from ..core.errors import InputError

# ----------------------------------------------------------------------------------------------------------------
# Checks: each returns what is wrong with a value, or None.


def is_real(value) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) and math.isfinite(
        value)


def positive(value) -> str | None:
    return None if is_real(value) and value > 0 else f"must be a finite number > 0, got {value!r}"


def non_negative(value) -> str | None:
    return None if is_real(value) and value >= 0 else f"must be a finite number >= 0, got {value!r}"


def probability(value) -> str | None:
    return None if is_real(value) and 0 < value < 1 else f"must be a probability in (0, 1), got {value!r}"


def fraction(value) -> str | None:
    return None if is_real(value) and 0 < value <= 1 else f"must be in (0, 1], got {value!r}"


def count(value) -> str | None:
    ok = isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= 1
    return None if ok else f"must be an integer >= 1, got {value!r}"


def at_least(lowest: float) -> Callable:
    def check(value) -> str | None:
        return None if is_real(value) and value >= lowest else f"must be a finite number >= {lowest:g}, got {value!r}"

    return check


def integer_at_least(lowest: int) -> Callable:
    def check(value) -> str | None:
        ok = isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= lowest
        return None if ok else f"must be an integer >= {lowest}, got {value!r}"

    return check


def tuple_of(check: Callable, length: int | None = None) -> Callable:
    def check_tuple(value) -> str | None:
        if not isinstance(value, tuple) or not value or (length is not None and len(value) != length):
            size = "a non-empty tuple" if length is None else f"a tuple of {length}"
            return f"must be {size}, got {value!r}"
        for item in value:
            if check(item) is not None:
                return f"has a bad entry: {check(item)}"
        return None

    return check_tuple


def ratio_range(value) -> str | None:
    problem = tuple_of(positive, 2)(value)
    if problem is None and not value[0] < value[1]:
        problem = f"must be (low, high) with low < high, got {value!r}"
    return problem


class OptionGroup:
    """A frozen group of options, checked when built: ``_checks`` maps each field to its check."""

    _name: ClassVar[str] = ""
    _checks: ClassVar[dict[str, Callable]] = {}

    def __post_init__(self):
        for f in fields(self):
            problem = self._checks[f.name](getattr(self, f.name))
            if problem is not None:
                raise InputError(problem, field=f"{self._name}.{f.name}")
