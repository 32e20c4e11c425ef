"""``length``: the effective vibrating length differs from the chord length.

Anchor sockets, guide pipes and saddles move the points where the cable
starts to vibrate freely by centimetres. One value for all tests; positions
stay measured from end A, so the change is at end B.
"""

from __future__ import annotations

from dataclasses import replace

from .base import Effect, Option, Quantity, pm, positive_ratio


class Length(Effect):
    name = "length"
    meaning = "the effective vibrating length differs"
    quantities = (Quantity("length"),)
    parameter_kind = "length"
    truth_key = "length_ratio"
    option = Option("--length-ratio", "R", "true vibrating length / chord length")

    def describe(self, values, sigmas, cable):
        return f"a vibrating length of {pm(values['length'], sigmas.get('length'), digits=5)} m (nominal {cable.length:g} m)"

    def check_truth(self, value, field):
        return positive_ratio(value, field)

    def apply_truth(self, truth, value):
        truth.cable = replace(truth.cable, length=truth.cable.length * value)
        truth.span_field = f"effects.{self.truth_key}"


EFFECT = Length()
