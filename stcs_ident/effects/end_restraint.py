"""``end_restraint``: the anchorages are not fully clamped (or not free to rotate).

A socket in a guide pipe, a pin, or a clamp that lets the cable rotate a
little: a rotational stiffness (N m/rad) at the ends, one value for both
when they are alike. The fit works in the fixity φ = k / (k + √(EI H)),
0 pinned and 1 clamped.
"""

from __future__ import annotations

import math
from dataclasses import replace

from ..core.errors import InputError, ModelError
from ..core.model import Boundary
from .base import Effect, Option, Quantity, number, pm


class EndRestraint(Effect):
    name = "end_restraint"
    meaning = "anchorages are not fully clamped (or not free to rotate)"
    quantities = (Quantity("rotational_stiffness"), Quantity("fixity", ""))
    parameter_kind = "end_stiffness"
    truth_key = "end_stiffness"
    option = Option("--end-stiffness", "KA,KB", "rotational end stiffness, N m/rad ('inf' clamped)")

    def record(self, p, variable, sigma, value, value_sigma, values, sigmas, context):
        suffix = "" if p.member == "AB" else f"_{p.member}"
        values[f"rotational_stiffness{suffix}"] = value if math.isfinite(value) else "inf"
        sigmas[f"rotational_stiffness{suffix}"] = value_sigma
        values[f"fixity{suffix}"] = float(variable)

    def describe(self, values, sigmas, cable):
        k = values.get("rotational_stiffness")
        shown = "clamped" if k == "inf" else pm(k, sigmas.get('rotational_stiffness'), "N m/rad")
        return f"anchorages restrained by a rotational stiffness {shown} (fixity {values.get('fixity', math.nan):.3f})"

    def check_truth(self, value, field):
        try:
            ka, kb = value
        except (TypeError, ValueError):
            raise ModelError("must be a pair (k_A, k_B)", field=field) from None
        ends = (number(ka, field), number(kb, field))
        if min(ends) < 0:
            raise ModelError(f"must be >= 0, got {value!r}", field=field)
        return ends

    def apply_truth(self, truth, value):
        truth.cable = replace(truth.cable, boundary_a=Boundary(value[0]), boundary_b=Boundary(value[1]))

    def truth_json(self, value):
        return [k if math.isfinite(k) else "inf" for k in value]

    def parse_option(self, given):
        parts = str(given).split(",")
        if len(parts) != 2:
            raise InputError(f"expected KA,KB, got {given!r}", field=self.option.flag)
        return tuple(number(v, self.option.flag, error=InputError) for v in parts)


EFFECT = EndRestraint()
