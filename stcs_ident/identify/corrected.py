"""The campaign with identified values in place of the nominal ones.

Used to chain identifications the way the source paper does (tension and EI
from the bare cable first, then the attachment positions of the loaded
cable with those values), and by the diagnosis step to start from a
corrected model.
"""

from __future__ import annotations

from dataclasses import replace

from ..core.model import Boundary, Campaign
from .result import IdentificationResult


def corrected_campaign(campaign: Campaign, result: IdentificationResult) -> Campaign:
    """``campaign`` with every identified parameter set to its estimate.

    Tensions replace the tests' measured tensions; EI, length and mass per
    length the cable's; positions, masses and springs the attachments' of
    their setup; an end fixity the boundary's rotational stiffness.
    """
    cable = campaign.cable
    tests = {t.name: t for t in campaign.tests}
    setups = {s.name: list(s.attachments) for s in campaign.setups}
    for p, value in zip(result.parameters, result.values):
        value = float(value)
        spec = p.spec
        if spec.belongs_to == "test":
            tests[p.member] = replace(tests[p.member], **{spec.attribute: value})
        elif spec.belongs_to == "cable":
            cable = replace(cable, **{spec.attribute: value})
        elif spec.belongs_to == "end":
            ends = {"A": ("boundary_a",), "B": ("boundary_b",), "AB": ("boundary_a", "boundary_b")}[p.member]
            cable = replace(cable, **{end: Boundary(value) for end in ends})
        else:
            for setup, index in p.slots or ((p.setup, p.index),):
                atts = setups[setup]
                atts[index] = replace(atts[index], **{spec.attribute: value})
    new_setups = tuple(replace(s, attachments=tuple(setups[s.name])) for s in campaign.setups)
    return replace(campaign, cable=cable, setups=new_setups, tests=tuple(tests[t.name] for t in campaign.tests))
