"""Bounds of a fit: where an estimate stopped at one, and whether that is a failure.

A least-squares fit bounded to, say, 0.5–2 × the nominal tension that ends
at 2 × has not found a minimum: the data want a value the bounds exclude,
and the standard deviation computed there is meaningless. Such a fit is
reported as failed, naming the parameter and the bound (:func:`bound_failure`).

Two kinds of bound are physical limits rather than search limits, and an
estimate there is a result (with a note): a lower bound of 0 for a
quantity that cannot be negative (a mass, a spring, a dashpot, the EI of a
bare cable: "the data show none"), and the ends 0 and 1 of an end's
fixity (pinned, clamped). Every other bound (a tension ratio's 0.5 and 2,
an EI ratio's 0.01 and 100, a position's margin from the anchorages, the
largest mass worth a search, a campaign's ``[bounds]``) is a limit of the
search, and an estimate there is a failure.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..core.notes import Note
from ..core.parameters import Parameter

#: An estimate within this fraction of the bounds' span from a bound is at it.
AT_BOUND = 1e-9
#: How a failed fit's reason starts (the diagnosis tells bound failures from errors by it).
FAILURE_HEAD = "the fit stopped at a bound, so it is no result"


def hits(parameters: Sequence[Parameter], x, lower, upper) -> list[tuple[Parameter, str, float, float]]:
    """Parameters at a bound: (parameter, "lower" or "upper", the bound, the estimate)."""
    out = []
    for p, v, lo, hi in zip(parameters, np.asarray(x, float), lower, upper):
        width = hi - lo
        if v - lo <= AT_BOUND * width:
            out.append((p, "lower", float(lo), float(v)))
        elif hi - v <= AT_BOUND * width:
            out.append((p, "upper", float(hi), float(v)))
    return out


def physical_limit(p: Parameter, side: str, bound: float) -> bool:
    """Whether ``bound`` is a physical limit of ``p`` rather than a limit of the search (module docstring)."""
    if p.is_fixity:
        return bound in (0.0, 1.0)
    return side == "lower" and bound == 0.0


def bound_failure(parameters: Sequence[Parameter], x, lower, upper) -> tuple[Note | None, list[str]]:
    """(failure, limits) of an estimate ``x``: a ``fit_at_bound`` note naming the first parameter that
    stopped at a bound of the search (None when none did), and the names of those at a physical limit."""
    failure, limits = None, []
    for p, side, bound, value in hits(parameters, x, lower, upper):
        if physical_limit(p, side, bound):
            limits.append(p.name)
        elif failure is None:
            if p.is_ratio:
                what = f"ratio to nominal, {float(p.to_value(bound)):.4g} {p.unit}"
            else:
                what = "fixity" if p.is_fixity else p.unit
            failure = Note.make(
                "fit_at_bound", FAILURE_HEAD + ": {parameter} = {bound:.6g} is its "
                "{side} bound ({what}); widen the bounds (a [bounds] table in the campaign) if the value "
                "is plausible, or check the nominal values", parameters=[p.name], value=bound, side=side,
                bound=bound, what=what)
    return failure, limits
