"""``unmodeled_support``: a transverse spring to ground the model lacks.

A cable guide, a deviator, a neoprene bearing in the anchor pipe or a
cross-tie that touches the cable: one stiffness (N/m) at one position (m),
the same in every test, acting in both planes.

:class:`OnePlaneSupport` is the same spring acting in one plane only (a
guide that holds the cable sideways but lets it move vertically, a tie
along one direction): the base of ``support_in_plane`` and
``support_out_of_plane``, whose spring is a :class:`DirectionalSupport`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

from ..core.model import Attachment
from ..core.planes import PLANES
from .base import Option, Quantity, UnmodeledAttachment, mean_tension


@dataclass(frozen=True)
class DirectionalSupport(Attachment):
    """A spring to ground along one axis, ``angle`` radians from the cable's plane (keyword only; 0: in-plane,
    π/2: out-of-plane). Like a damper's spring (:mod:`stcs_ident.core.planes`), it gives cos²α of its stiffness
    (and of its mass) to the in-plane motion and sin²α to the out-of-plane one; it has no dashpot."""

    angle: float = field(default=0.0, kw_only=True)
    #: No dashpot (read by the planes' projection and the solver, as a damper's).
    coefficient: ClassVar[float] = 0.0


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


class OnePlaneSupport(UnmodeledSupport):
    """An unmodeled spring acting in ``plane`` only. Told from :class:`UnmodeledSupport` only by the modes of
    the other plane, so considered only where both planes' modes are measured."""

    #: The plane the spring acts in.
    plane: ClassVar[str] = "in"
    option = None
    quiet = True  # on one plane's modes (most campaigns) it is unmodeled_support: no note each time

    def attachment(self, name, position, amount=0.0):
        angle = 0.0 if self.plane == "in" else math.pi / 2
        return DirectionalSupport(name, position, stiffness=amount, angle=angle)

    def applicable(self, campaign, tests):
        seen = {p for t in tests for p in (t.planes or ("in",) * len(t.modes or ()))}
        if seen >= set(PLANES):
            return None
        return (f"{self.name} needs measured modes in both planes (with one plane's modes it cannot be told from "
                f"unmodeled_support)")
