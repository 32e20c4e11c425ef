"""``damper``: a damper the model lacks.

A stay's damper left out of the campaign file, a guide pipe's neoprene
ring acting as a dashpot, a temporary damper from construction: one
viscous dashpot (N s/m) to ground at one position (m), the same in every
test. It shifts the frequencies like a stiff support near an end and adds
a damping ratio that first rises and then falls with the mode number
(Krenk's universal curve), which tells it apart when damping ratios are
measured.
"""

from __future__ import annotations

import math

from ..core.errors import ModelError
from ..core.kinds import coefficient_upper, mean_tension
from ..core.model import Damper
from .base import Option, Quantity, UnmodeledAttachment


class UnmodeledDamper(UnmodeledAttachment):
    name = "damper"
    meaning = "a damper the model lacks"
    quantities = (Quantity("coefficient"), Quantity("position"))
    attachment_name = "(unmodeled damper)"
    amount_kind = "coefficient"
    noun = "damper"
    truth_key = "extra_damper"
    option = Option("--extra-damper", "NS/M@X", "an unmodelled viscous damper at X m")
    opt_in = True

    def applicable(self, campaign, tests):
        setups = list(dict.fromkeys(t.setup for t in tests))
        if any(isinstance(a, Damper) for s in setups for a in campaign.setup(s).attachments):
            return None
        return ("a missing damper is considered on a cable with a recorded damper, or when asked for "
                "(--effects ...,damper)")

    def amount_upper(self, campaign, tests):
        return coefficient_upper(campaign)

    def amount_starts(self, campaign, tests, position):
        """Dashpots a decade below, at and a decade above mode 1's optimum for a damper at ``position``
        (η₁ = c π d/(l √(H m)) = 0.1, 1, 10, d the distance to the nearer end).

        A damper's damping ratios rise and then fall with its dashpot (Krenk's universal curve), so the
        fit of a dashpot has a basin on either side of the optimum, and one started from the dashpot of the
        previous position of the scan could stay in the wrong one, or in a region where the model has no
        modes to give (a large dashpot far from the ends makes a mode overdamped).
        """
        cable = campaign.cable
        distance = max(min(position, cable.length - position), 1e-6 * cable.length)
        optimum = math.sqrt(mean_tension(campaign) * cable.mass_per_length) * cable.length / (math.pi * distance)
        upper = self.amount_upper(campaign, tests)
        return tuple(min(eta * optimum, upper) for eta in (0.1, 1.0, 10.0))

    def check_truth(self, value, field):
        checked = super().check_truth(value, field)
        if checked is not None and not (checked[0] > 0 and math.isfinite(checked[0])):
            raise ModelError(f"needs a dashpot > 0, got {value!r}", field=field)
        return checked

    def apply_truth(self, truth, value):
        amount, position = value
        name = "(extra damper)"
        truth.attachments.append(Damper(name, position, coefficient=amount))
        truth.origin[name] = f"effects.{self.truth_key}"


EFFECT = UnmodeledDamper()
