"""``support_out_of_plane``: a spring the model lacks, acting out of the cable's plane only.

A guide that holds the cable sideways and lets it move vertically (a
lateral restrainer, a horizontal tie): one stiffness (N/m) at one position
(m), the same in every test; the in-plane modes do not see it. Considered
where both planes' modes are measured.
"""

from __future__ import annotations

from .unmodeled_support import OnePlaneSupport


class SupportOutOfPlane(OnePlaneSupport):
    name = "support_out_of_plane"
    meaning = "a transverse spring the model lacks, acting out-of-plane only"
    attachment_name = "(out-of-plane support)"
    noun = "out-of-plane support"
    truth_key = "extra_spring_out"
    plane = "out"


EFFECT = SupportOutOfPlane()
