"""The two planes of transverse motion, and the directions of a record's channels.

A cable moves transversely in its own vertical plane (in-plane, the plane of its chord and its sag) and
normal to it (out-of-plane). The out-of-plane motion obeys the same beam–string equation without the
additional tension of sag-extensibility: that tension depends only on the in-plane displacement, because the
static profile lies in the cable's plane. So the out-of-plane modes are those of the same model with no
additional tension (tension model ``"none"``, as for a cable without ``EA``).

Attachments act per plane:

- a clamped mass moves with the cable in both planes;
- a spring to ground has its ``stiffness`` in-plane and its ``stiffness_out`` out-of-plane (None: the same);
- a damper acts along its own axis, at ``angle`` from the cable's plane: its dashpot, spring and moving mass
  give cos²α of their values to the in-plane motion and sin²α to the out-of-plane motion. The cross terms
  (a velocity in one plane making a force in the other, c sinα cosα) are neglected: the planes are solved
  uncoupled, exact at α = 0° and 90°, and the coupling is of the order of the damper's effect times
  sinα cosα elsewhere.

A channel's direction is ``"in"`` (in-plane transverse, the default), ``"out"`` (out-of-plane transverse),
``"axial"`` (along the chord) or an angle in degrees from the in-plane direction towards the out-of-plane
one (a sensor turned on the cable: 0 is ``"in"``, 90 is ``"out"``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from .errors import ModelError

#: The planes, in the order results list them.
PLANES = ("in", "out")
#: Their names in tables and messages.
PLANE_NAMES = {"in": "in-plane", "out": "out-of-plane"}
#: Named channel directions (besides an angle in degrees).
DIRECTIONS = ("in", "out", "axial")


def check_plane(value: Any, field: str = "plane") -> str:
    """``value`` as one of :data:`PLANES`; ModelError naming ``field`` otherwise."""
    if isinstance(value, str) and value in PLANES:
        return value
    raise ModelError(f'must be "in" (in-plane) or "out" (out-of-plane), got {value!r}', field=field)


def check_direction(value: Any, field: str = "direction") -> str | float:
    """A channel direction: ``"in"``, ``"out"``, ``"axial"`` or an angle in degrees (a finite number, taken
    modulo 360 into (-180, 180]; 0 and 90 become ``"in"`` and ``"out"``)."""
    if isinstance(value, str):
        text = value.strip().lower()
        if text in DIRECTIONS:
            return text
        try:
            value = float(text)
        except ValueError:
            raise ModelError(f'must be "in", "out", "axial" or an angle in degrees, got {value!r}',
                             field=field) from None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not _finite(value):
        raise ModelError(f'must be "in", "out", "axial" or an angle in degrees, got {_short(value)}', field=field)
    angle = float(value) % 360.0
    angle = angle - 360.0 if angle > 180.0 else angle
    return {0.0: "in", 90.0: "out"}.get(angle, angle)


def _finite(value: float) -> bool:
    """Whether ``value`` is a finite float (an integer beyond a float's range is not: TOML integers are
    unbounded)."""
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def _short(value: Any) -> str:
    """``repr(value)`` for a message, an integer of hundreds of digits shortened to its size."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**30:
        return "an integer beyond the range of a float"  # (str() of one of 4300 digits or more raises)
    return repr(value)


def direction_angle(direction: str | float) -> float | None:
    """The angle of a transverse direction, radians from in-plane towards out-of-plane; None for axial."""
    if direction == "axial":
        return None
    if direction == "in":
        return 0.0
    if direction == "out":
        return math.pi / 2
    return math.radians(float(direction))


def direction_plane(direction: str | float) -> str | None:
    """The plane a channel mostly sees (the nearer one; "in" at exactly 45°); None for an axial channel."""
    angle = direction_angle(direction)
    if angle is None:
        return None
    return "in" if abs(math.cos(angle)) >= abs(math.sin(angle)) else "out"


def direction_text(direction: str | float) -> str:
    """How tables and files write a direction: ``in``, ``out``, ``axial``, or the angle (``12.5``)."""
    return direction if isinstance(direction, str) else f"{direction:g}"


#: What results say of a record whose channels have no direction, neither from its file nor from the campaign.
NO_DIRECTIONS_NOTE = "no channel directions given: every channel read as in-plane"


def directions_note(record) -> str | None:
    """The note for ``record``'s channel directions: :data:`NO_DIRECTIONS_NOTE` when neither its file nor the
    campaign gave any (``channel_directions`` is None, every channel read as in-plane), else None."""
    return NO_DIRECTIONS_NOTE if getattr(record, "channel_directions", None) is None else None


def plane_share(attachment, plane: str) -> float:
    """The share of an attachment's spring, dashpot and moving mass that acts in ``plane``: cos²α in-plane and
    sin²α out-of-plane for a damper at ``angle`` α; 1 for an attachment's mass (its spring: :func:`plane_view`)."""
    angle = getattr(attachment, "angle", None)
    if angle is None:
        return 1.0
    return math.cos(angle) ** 2 if plane == "in" else math.sin(angle) ** 2


def plane_view(cable, attachments: Sequence, plane: str):
    """(cable, attachments) of ``plane``'s transverse motion: in-plane, the model as given (a damper's values
    times cos²α); out-of-plane, the cable without sag-extensibility (``EA=None``), springs at
    ``stiffness_out`` and dampers at sin²α. The attachments keep their number and order (a damper whose share is
    0 in the plane stays as a weightless point), so per-attachment overrides apply alike in both planes."""
    plane = check_plane(plane)
    out = []
    for a in attachments:
        share = plane_share(a, plane)
        if getattr(a, "angle", None) is not None:  # a damper: everything along its axis
            if share == 1.0:
                out.append(a)
                continue
            mass, stiffness, coefficient = (_share_of(getattr(a, q), share, q)
                                            for q in ("mass", "stiffness", "coefficient"))
            if coefficient > 0:
                out.append(replace(a, mass=mass, stiffness=stiffness, coefficient=coefficient))
            else:  # no dashpot in this plane: a point (a damper's base class), keeping the count and order
                point = next(k for k in type(a).__mro__ if k.__name__ == "Attachment")
                out.append(point(a.name, a.position, mass, stiffness))
            continue
        if plane == "out" and getattr(a, "stiffness_out", None) is not None:
            out.append(replace(a, stiffness=a.stiffness_out, stiffness_out=None))
        else:
            out.append(a)
    if plane == "out" and cable.EA is not None:
        cable = replace(cable, EA=None)
    return cable, tuple(out)


def _share_of(value: float, share: float, quantity: str) -> float:
    """``value * share``, 0 below the smallest value the model takes of ``quantity`` (a damper at 90° has no
    in-plane share, cos²90° = 4e-33 in floating point)."""
    from .checks import BANDS

    scaled = value * share
    return scaled if scaled >= BANDS[quantity][0] else 0.0


def plane_overrides(attachments: Sequence, overrides: dict, plane: str) -> dict:
    """Per-attachment overrides of a batch (``masses``, ``stiffnesses``, ``coefficients``; last axis one value
    per attachment) turned into ``plane``'s: a damper's times its share; an attachment's ``stiffnesses``
    out-of-plane scaled by ``stiffness_out / stiffness`` (replaced by ``stiffness_out`` where the in-plane one
    is 0)."""
    import numpy as np

    plane = check_plane(plane)
    out = dict(overrides)
    shares = np.array([plane_share(a, plane) for a in attachments], float)
    dampers = np.array([getattr(a, "angle", None) is not None for a in attachments], bool)
    for key in ("masses", "coefficients"):
        if key in out and dampers.any():
            factor = np.where(dampers, shares, 1.0)
            out[key] = np.asarray(out[key], float) * factor
    if "stiffnesses" in out:
        factor = np.where(dampers, shares, 1.0)
        value = np.asarray(out["stiffnesses"], float) * factor
        if plane == "out":
            for j, a in enumerate(attachments):
                k_out = getattr(a, "stiffness_out", None)
                if k_out is None:
                    continue
                value = value.copy()
                value[..., j] = value[..., j] * (k_out / a.stiffness) if a.stiffness > 0 else k_out
        out["stiffnesses"] = value
    return out
