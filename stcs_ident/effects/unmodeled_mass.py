"""``unmodeled_mass``: a point mass the model lacks.

Accelerometers and their clamps, a forgotten weight, ice or a bird's nest
on a hanger: one mass (kg) at one position (m), the same in every test.
"""

from __future__ import annotations

from .base import Option, Quantity, UnmodeledAttachment


class UnmodeledMass(UnmodeledAttachment):
    name = "unmodeled_mass"
    meaning = "a point mass the model lacks"
    quantities = (Quantity("mass"), Quantity("position"))
    attachment_name = "(unmodeled mass)"
    amount_kind = "mass"
    noun = "mass"
    truth_key = "extra_mass"
    option = Option("--extra-mass", "KG@X", "an unmodelled point mass at X m")

    def amount_upper(self, campaign, tests):
        return campaign.cable.mass_per_length * campaign.cable.length


EFFECT = UnmodeledMass()
