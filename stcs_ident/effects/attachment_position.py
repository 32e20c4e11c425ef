"""``attachment_position``: a recorded attachment is elsewhere than recorded.

A clamp or weight placed by hand on a long cable, or a position measured
along the sagged cable rather than the chord, can be off by centimetres to
decimetres. One position per recorded attachment, shared by the tests of
its setup.
"""

from __future__ import annotations

from .base import Option, Quantity, RecordedAttachment, pm


class AttachmentPosition(RecordedAttachment):
    name = "attachment_position"
    meaning = "an attachment is elsewhere than recorded"
    quantities = (Quantity("position", per="attachment"),)
    parameter_kind = "position"
    attribute = "position"
    positive = True
    truth_key = "attachment_positions"
    option = Option("--move", "NAME@X", "an attachment truly at X m (repeatable)", repeatable=True)

    def describe(self, values, sigmas, cable):
        where = ", ".join(f"{a} at {pm(v, sigmas['position'].get(a))} m" for a, v in values["position"].items())
        return f"attachments elsewhere than recorded ({where})"


EFFECT = AttachmentPosition()
