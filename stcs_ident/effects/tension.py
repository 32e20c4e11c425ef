"""``tension``: the true tension of a test differs from the stated one.

The stated tension comes from a ring gauge, a jack's pressure or a previous
frequency measurement, each good to a few per cent; it is one ratio
(true / stated) per test. Part of the source paper's correction.
"""

from __future__ import annotations

from .base import Effect, Option, Quantity, pm, positive_ratio


class Tension(Effect):
    name = "tension"
    meaning = "the true tension differs from the measured value"
    quantities = (Quantity("ratio", "", per="test"),)
    shared_by = "one per test"
    baseline = True
    parameter_kind = "tension"
    truth_key = "tension_ratio"
    option = Option("--tension-ratio", "R", "true / stated tension of every test")

    def record(self, p, variable, sigma, value, value_sigma, values, sigmas, context):
        values.setdefault("ratio", {})[p.member] = float(variable)
        sigmas.setdefault("ratio", {})[p.member] = sigma

    def describe(self, values, sigmas, cable):
        ratios = ", ".join(f"{t}: {pm(v, sigmas['ratio'].get(t), digits=4)}" for t, v in values["ratio"].items())
        return f"tensions differ from the measured ones (true/measured {ratios})"

    def check_truth(self, value, field):
        return positive_ratio(value, field)

    def apply_truth(self, truth, value):
        truth.tension = truth.tension * value


EFFECT = Tension()
