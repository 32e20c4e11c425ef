"""``attachment_mass``: a recorded attachment's mass differs from the recorded one.

Clamps, sensors' brackets and bolts add to a weight's nominal mass; a
damper's moving mass is seldom known well. One mass per recorded
attachment, shared by the tests of its setup.
"""

from __future__ import annotations

from .base import Option, Quantity, RecordedAttachment, pm


class AttachmentMass(RecordedAttachment):
    name = "attachment_mass"
    meaning = "an attachment's mass differs from recorded"
    quantities = (Quantity("mass", per="attachment"),)
    parameter_kind = "mass"
    attribute = "mass"
    truth_key = "attachment_masses"
    option = Option("--attachment-mass", "NAME@KG", "an attachment's true mass, kg (repeatable)", repeatable=True)

    def describe(self, values, sigmas, cable):
        masses = ", ".join(f"{a}: {pm(v, sigmas['mass'].get(a))} kg" for a, v in values["mass"].items())
        return f"attachment masses differ from the recorded ones ({masses})"


EFFECT = AttachmentMass()
