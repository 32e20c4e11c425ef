"""``attachment_mass``: a recorded attachment's mass differs from the recorded one.

Clamps, sensors' brackets and bolts add to a weight's nominal mass; a
damper's moving mass is seldom known well. One mass per recorded
attachment, shared by the tests of its setup.
"""

from __future__ import annotations

from .attachment_position import needs_attachment
from .base import Effect, Option, Quantity, Tolerance, at_pair, named_values, pm, set_attachments


class AttachmentMass(Effect):
    name = "attachment_mass"
    meaning = "an attachment's mass differs from recorded"
    quantities = (Quantity("mass", "kg", per="attachment"),)
    shared_by = "the tests of its setup"
    tolerance = Tolerance("mass", 0.02)
    parameter_kind = "mass"
    truth_key = "attachment_masses"
    option = Option("--attachment-mass", "NAME@KG", "an attachment's true mass, kg (repeatable)", repeatable=True)

    def applicable(self, campaign, tests):
        return needs_attachment(self.name, campaign, tests)

    def describe(self, values, sigmas, cable):
        masses = ", ".join(f"{a}: {pm(v, sigmas['mass'].get(a))} kg" for a, v in values["mass"].items())
        return f"attachment masses differ from the recorded ones ({masses})"

    def check_truth(self, value, field):
        return named_values(value, field, positive=False)

    def apply_truth(self, truth, value):
        set_attachments(truth, value, "mass", self.truth_key)

    def truth_json(self, value):
        return dict(value)

    def parse_option(self, given):
        return dict(at_pair(item, self.option.flag) for item in given)

EFFECT = AttachmentMass()
