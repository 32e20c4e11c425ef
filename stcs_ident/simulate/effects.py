"""Hidden effects: how the true cable differs from the one a campaign describes.

A simulated campaign describes the nominal cable; its records come from a
*true* model that may differ in ways the campaign file does not say (a
mass nobody wrote down, a weight clamped elsewhere, a tension a few per
cent off, ends that are not quite clamped). :class:`Effects` lists them and
:func:`true_model` applies them, so that identification and diagnosis can
be tested against a known truth. The effect names of
:attr:`Effects.names` are those of the ``diagnose`` vocabulary in
``interface.md``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from ..errors import ModelError
from ..model import Attachment, Boundary, Cable

__all__ = ["Effects", "true_model"]

_EXTRA_MASS = "(extra mass)"
_EXTRA_SPRING = "(extra spring)"


def _ratio(value: Any, name: str) -> float | None:
    if value is None:
        return None
    v = _number(value, name)
    if v <= 0:
        raise ModelError(f"must be > 0, got {value!r}", field=name)
    return v


def _number(value: Any, name: str) -> float:
    if isinstance(value, bool):
        raise ModelError(f"must be a number, got {value!r}", field=name)
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"must be a number, got {value!r}", field=name) from None
    if math.isnan(v):
        raise ModelError("must not be NaN", field=name)
    return v


def _pair(value: Any, name: str, what: str) -> tuple[float, float] | None:
    """(amount >= 0, position) with finite numbers, or None."""
    if value is None:
        return None
    try:
        amount, position = value
    except (TypeError, ValueError):
        raise ModelError(f"must be a pair ({what}, position)", field=name) from None
    amount, position = _number(amount, name), _number(position, name)
    if not (math.isfinite(amount) and amount >= 0 and math.isfinite(position)):
        raise ModelError(f"needs a finite {what} >= 0 and a finite position, got {value!r}", field=name)
    return amount, position


def _named(value: Any, name: str, positive: bool) -> tuple[tuple[str, float], ...]:
    """A mapping or pairs (attachment name, value) as a sorted tuple of pairs."""
    try:
        items = [(k, v) for k, v in (value.items() if isinstance(value, Mapping) else value)]
    except (TypeError, ValueError):
        raise ModelError("must map attachment names to values", field=name) from None
    out = {}
    for key, v in items:
        where = f"{name}[{key}]"
        v = _number(v, where)
        if not math.isfinite(v) or v < 0 or (positive and v == 0):
            raise ModelError(f"must be finite and {'> 0' if positive else '>= 0'}, got {v!r}", field=where)
        if key in out:
            raise ModelError("given twice", field=where)
        out[str(key)] = v
    return tuple(sorted(out.items()))


@dataclass(frozen=True)
class Effects:
    """Differences between the true cable and the nominal one (all optional).

    Parameters
    ----------
    tension_ratio : float, optional
        True tension / stated tension.
    EI_ratio : float, optional
        True bending stiffness / nominal EI.
    length_ratio : float, optional
        True vibrating length / nominal chord length. Positions (of
        attachments, sensors, impulses) stay measured from end A, as in
        the solver's ``length`` override, so the change is at end B.
    end_stiffness : (float, float), optional
        True rotational stiffness of the ends (k_A, k_B), N m/rad;
        ``math.inf`` is clamped, 0 pinned.
    extra_mass : (float, float), optional
        An unrecorded point mass (kg, position m from A).
    extra_spring : (float, float), optional
        An unrecorded transverse spring to ground (N/m, position m from A).
    attachment_positions : mapping of str to float, optional
        True positions (m) of named attachments (moved attachments).
    attachment_masses : mapping of str to float, optional
        True masses (kg) of named attachments.

    Mappings are stored as sorted tuples of (name, value) pairs so the
    object stays hashable.
    """

    tension_ratio: float | None = None
    EI_ratio: float | None = None
    length_ratio: float | None = None
    end_stiffness: tuple[float, float] | None = None
    extra_mass: tuple[float, float] | None = None
    extra_spring: tuple[float, float] | None = None
    attachment_positions: tuple[tuple[str, float], ...] = field(default=())
    attachment_masses: tuple[tuple[str, float], ...] = field(default=())

    def __post_init__(self):
        set_ = object.__setattr__
        for name in ("tension_ratio", "EI_ratio", "length_ratio"):
            set_(self, name, _ratio(getattr(self, name), f"effects.{name}"))
        if self.end_stiffness is not None:
            try:
                ka, kb = self.end_stiffness
            except (TypeError, ValueError):
                raise ModelError("must be a pair (k_A, k_B)", field="effects.end_stiffness") from None
            ends = (_number(ka, "effects.end_stiffness"), _number(kb, "effects.end_stiffness"))
            if min(ends) < 0:
                raise ModelError(f"must be >= 0, got {self.end_stiffness!r}", field="effects.end_stiffness")
            set_(self, "end_stiffness", ends)
        set_(self, "extra_mass", _pair(self.extra_mass, "effects.extra_mass", "mass"))
        set_(self, "extra_spring", _pair(self.extra_spring, "effects.extra_spring", "stiffness"))
        set_(self, "attachment_positions",
             _named(self.attachment_positions, "effects.attachment_positions", positive=True))
        set_(self, "attachment_masses", _named(self.attachment_masses, "effects.attachment_masses", positive=False))

    @property
    def names(self) -> list[str]:
        """The effects present, in the ``diagnose`` vocabulary of ``interface.md``."""
        present = [
            ("tension", self.tension_ratio is not None),
            ("bending_stiffness", self.EI_ratio is not None),
            ("attachment_position", bool(self.attachment_positions)),
            ("attachment_mass", bool(self.attachment_masses)),
            ("unmodeled_mass", self.extra_mass is not None),
            ("unmodeled_support", self.extra_spring is not None),
            ("end_restraint", self.end_stiffness is not None),
            ("length", self.length_ratio is not None),
        ]
        return [name for name, on in present if on]

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON (only the effects present; inf written as the string "inf")."""
        out: dict[str, Any] = {}
        for name in ("tension_ratio", "EI_ratio", "length_ratio"):
            if getattr(self, name) is not None:
                out[name] = getattr(self, name)
        if self.end_stiffness is not None:
            out["end_stiffness"] = [k if math.isfinite(k) else "inf" for k in self.end_stiffness]
        if self.extra_mass is not None:
            out["extra_mass"] = {"mass": self.extra_mass[0], "position": self.extra_mass[1]}
        if self.extra_spring is not None:
            out["extra_spring"] = {"stiffness": self.extra_spring[0], "position": self.extra_spring[1]}
        if self.attachment_positions:
            out["attachment_positions"] = dict(self.attachment_positions)
        if self.attachment_masses:
            out["attachment_masses"] = dict(self.attachment_masses)
        return out


def true_model(cable: Cable, attachments: Sequence[Attachment], tension: float,
               effects: Effects | None) -> tuple[Cable, tuple[Attachment, ...], float]:
    """Apply hidden effects to a nominal configuration.

    Parameters
    ----------
    cable, attachments, tension :
        The nominal configuration (tension in N).
    effects : Effects or None
        None returns the nominal configuration.

    Returns
    -------
    cable : Cable
    attachments : tuple of Attachment
        Sorted by position. An extra mass or spring is a new attachment
        named ``"(extra mass)"`` / ``"(extra spring)"``; attachments that
        end up at one position are merged into one (masses and stiffnesses
        added, names joined with ``+``), as the solver needs distinct nodes.
    tension : float

    Raises
    ------
    ModelError
        If an effect names an unknown attachment or puts something outside
        the true span (the field names the effect).
    """
    atts = tuple(attachments)
    if effects is None:
        return cable, tuple(sorted(atts, key=lambda a: a.position)), float(tension)
    if not isinstance(effects, Effects):
        raise ModelError(f"must be an Effects object, got {type(effects).__name__}", field="effects")
    tension = float(tension) * (effects.tension_ratio or 1.0)
    cable = _true_cable(cable, effects)
    atts = _true_attachments(atts, effects, cable.length)
    return cable, atts, tension


def _true_cable(cable: Cable, effects: Effects) -> Cable:
    changes: dict[str, Any] = {}
    if effects.EI_ratio is not None:
        changes["EI"] = cable.EI * effects.EI_ratio
    if effects.length_ratio is not None:
        changes["length"] = cable.length * effects.length_ratio
    if effects.end_stiffness is not None:
        changes["boundary_a"] = Boundary(effects.end_stiffness[0])
        changes["boundary_b"] = Boundary(effects.end_stiffness[1])
    return replace(cable, **changes) if changes else cable


def _true_attachments(atts: tuple[Attachment, ...], effects: Effects, length: float) -> tuple[Attachment, ...]:
    by_name = {a.name: a for a in atts}
    for kind, values in (("position", effects.attachment_positions), ("mass", effects.attachment_masses)):
        for name, value in values:
            if name not in by_name:
                raise ModelError(f"names no attachment of this setup (known: {sorted(by_name)})",
                                 field=f"effects.attachment_{kind}s[{name}]")
            by_name[name] = replace(by_name[name], **{kind: value})
    out = list(by_name.values())
    if effects.extra_mass is not None:
        out.append(Attachment(_EXTRA_MASS, effects.extra_mass[1], mass=effects.extra_mass[0]))
    if effects.extra_spring is not None:
        out.append(Attachment(_EXTRA_SPRING, effects.extra_spring[1], stiffness=effects.extra_spring[0]))
    for a in out:
        if not 0 < a.position < length:
            raise ModelError(f"{a.name} at {a.position} m is outside the true span (0, {length}) m",
                             field=_effect_field(a.name, effects))
    return _merge_coincident(out)


def _effect_field(name: str, effects: Effects) -> str:
    """The effect that put attachment ``name`` where it is."""
    if name == _EXTRA_MASS:
        return "effects.extra_mass"
    if name == _EXTRA_SPRING:
        return "effects.extra_spring"
    if name in dict(effects.attachment_positions):
        return f"effects.attachment_positions[{name}]"
    return "effects.length_ratio"  # a nominal position beyond the shortened span


def _merge_coincident(atts: list[Attachment]) -> tuple[Attachment, ...]:
    merged: dict[float, Attachment] = {}
    for a in atts:
        b = merged.get(a.position)
        merged[a.position] = a if b is None else Attachment(
            f"{b.name}+{a.name}", a.position, b.mass + a.mass, b.stiffness + a.stiffness)
    return tuple(sorted(merged.values(), key=lambda a: a.position))
