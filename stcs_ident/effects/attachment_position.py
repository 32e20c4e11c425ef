"""``attachment_position``: a recorded attachment is elsewhere than recorded.

A clamp or weight placed by hand on a long cable, or a position measured
along the sagged cable rather than the chord, can be off by centimetres to
decimetres. One position per recorded attachment, shared by the tests of
its setup.
"""

from __future__ import annotations

from .base import Effect, Option, Quantity, Tolerance, at_pair, named_values, pm, set_attachments


class AttachmentPosition(Effect):
    name = "attachment_position"
    meaning = "an attachment is elsewhere than recorded"
    quantities = (Quantity("position", "m", per="attachment"),)
    shared_by = "the tests of its setup"
    tolerance = Tolerance("position", 0.02, relative=False, unit="m")
    parameter_kind = "position"
    truth_key = "attachment_positions"
    option = Option("--move", "NAME@X", "an attachment truly at X m (repeatable)", repeatable=True)

    def applicable(self, campaign, tests):
        return needs_attachment(self.name, campaign, tests)

    def describe(self, values, sigmas, cable):
        where = ", ".join(f"{a} at {pm(v, sigmas['position'].get(a))} m" for a, v in values["position"].items())
        return f"attachments elsewhere than recorded ({where})"

    def check_truth(self, value, field):
        return named_values(value, field, positive=True)

    def apply_truth(self, truth, value):
        set_attachments(truth, value, "position", self.truth_key)

    def truth_json(self, value):
        return dict(value)

    def parse_option(self, given):
        return dict(at_pair(item, self.option.flag) for item in given)


def needs_attachment(effect: str, campaign, tests) -> str | None:
    """Why an effect on recorded attachments has nothing to act on (None when it has)."""
    setups = list(dict.fromkeys(t.setup for t in tests))
    if any(campaign.setup(s).attachments for s in setups):
        return None
    return (f"{effect} needs a recorded attachment in the setup of a measured test, and the measured "
            f"tests' setups ({', '.join(setups)}) have none")


EFFECT = AttachmentPosition()
