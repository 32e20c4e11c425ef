"""Effects: the ways a real cable may differ from its nominal model.

One module per effect (``tension``, ``bending_stiffness``, ...), each
defining an :class:`~stcs_ident.effects.base.Effect` and registering it
here, in the order of the vocabulary. Everything else reads the registry:

>>> from stcs_ident import effects
>>> effects.names()[:2]
('tension', 'bending_stiffness')

To add an effect, subclass :class:`~stcs_ident.effects.base.Effect` (or
:class:`~stcs_ident.effects.base.UnmodeledAttachment`), fill in its class
attributes and the methods that differ from the defaults, and call
:func:`register` with an instance (see the README's Development section).
"""

from __future__ import annotations

from . import (
    attachment_mass,
    attachment_position,
    bending_stiffness,
    damper,
    damper_coefficient,
    end_restraint,
    length,
    support_in_plane,
    support_out_of_plane,
    tension,
    unmodeled_mass,
    unmodeled_support,
)
from .base import Context, Effect, Option, Quantity, RecordedAttachment, Tolerance, Truth, UnmodeledAttachment
from .registry import (
    baseline,
    by_truth_key,
    effects,
    get,
    in_order,
    names,
    parse,
    register,
    tolerance,
    tolerance_keys,
    unregister,
)

for _module in (tension, bending_stiffness, attachment_position, attachment_mass, unmodeled_mass, unmodeled_support,
                support_in_plane, support_out_of_plane, end_restraint, length, damper, damper_coefficient):
    register(_module.EFFECT)

__all__ = [
    "Context", "Effect", "Option", "Quantity", "RecordedAttachment", "Tolerance", "Truth", "UnmodeledAttachment",
    "baseline",
    "by_truth_key", "effects", "get", "in_order", "names", "parse", "register", "tolerance", "tolerance_keys",
    "unregister",
]
