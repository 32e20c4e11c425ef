"""``support_in_plane``: a spring the model lacks, acting in the cable's plane only.

A support that holds the cable vertically and lets it swing sideways (a
saddle, a vertical tie): one stiffness (N/m) at one position (m), the same
in every test; the out-of-plane modes do not see it. Considered where both
planes' modes are measured.
"""

from __future__ import annotations

from .unmodeled_support import OnePlaneSupport


class SupportInPlane(OnePlaneSupport):
    name = "support_in_plane"
    meaning = "a transverse spring the model lacks, acting in-plane only"
    attachment_name = "(in-plane support)"
    noun = "in-plane support"
    truth_key = "extra_spring_in"
    plane = "in"


EFFECT = SupportInPlane()
