"""``bending_stiffness``: the effective EI differs from the nominal one.

A strand's or a bundle's bending stiffness lies between that of its wires
bending alone and that of a solid section, depending on interwire friction
and hence on tension; the nominal value is often a guess within tens of per
cent. One value for all tests. Part of the source paper's correction. On a
bare cable (nominal EI = 0) the parameter is EI itself, in N m², from 0 to
the EI at which ξ = l √(T/EI) falls to 2 (:func:`stcs_ident.core.kinds.bare_EI_upper`).
"""

from __future__ import annotations

from dataclasses import replace

from .base import Effect, Option, Quantity, pm, positive_ratio, scaled


class BendingStiffness(Effect):
    name = "bending_stiffness"
    meaning = "the effective bending stiffness EI differs from nominal"
    quantities = (Quantity("EI"),)
    baseline = True
    parameter_kind = "EI"
    truth_key = "EI_ratio"
    option = Option("--EI-ratio", "R", "true / nominal bending stiffness")

    def applicable(self, campaign, tests):
        return None  # on a bare cable (EI = 0) EI is an absolute value in N m² (core.kinds.bare_EI_upper)

    def describe(self, values, sigmas, cable):
        shown = f"EI = {pm(values['EI'] / 1e3, scaled(sigmas.get('EI'), 1e3))} kN m²"
        if cable.EI <= 0:
            return f"a bending stiffness {shown} (an absolute value: the nominal EI is 0, a bare cable)"
        return f"an effective bending stiffness {shown} ({values['EI'] / cable.EI:.3g} × nominal)"

    def check_truth(self, value, field):
        return positive_ratio(value, field)

    def apply_truth(self, truth, value):
        truth.cable = replace(truth.cable, EI=truth.cable.EI * value)


EFFECT = BendingStiffness()
