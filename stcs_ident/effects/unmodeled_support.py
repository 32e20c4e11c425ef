"""``unmodeled_support``: a transverse spring to ground the model lacks.

A cable guide, a deviator, a neoprene bearing in the anchor pipe or a
cross-tie that touches the cable: one stiffness (N/m) at one position (m),
the same in every test.
"""

from __future__ import annotations

from .base import Option, Quantity, UnmodeledAttachment, mean_tension


class UnmodeledSupport(UnmodeledAttachment):
    name = "unmodeled_support"
    meaning = "a transverse spring the model lacks"
    quantities = (Quantity("stiffness"), Quantity("position"))
    attachment_name = "(unmodeled support)"
    amount_kind = "stiffness"
    noun = "support"
    truth_key = "extra_spring"
    option = Option("--extra-spring", "K@X", "an unmodelled transverse spring (N/m) at X m")

    def amount_upper(self, campaign, tests):
        return 100.0 * mean_tension(tests) / campaign.cable.length


EFFECT = UnmodeledSupport()
