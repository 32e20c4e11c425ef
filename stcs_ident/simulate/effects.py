"""Hidden effects: how the true cable differs from the one a campaign describes.

A simulated campaign describes the nominal cable; its records come from a
*true* model that may differ in ways the campaign file does not say (a
mass nobody wrote down, a weight clamped elsewhere, a tension a few per
cent off, ends that are not quite clamped). :class:`Effects` holds them,
each under the keyword its effect declares (``truth_key`` of
:mod:`stcs_ident.effects`), and :func:`true_model` applies them, effect by
effect, so that identification and diagnosis can be tested against a known
truth.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from .. import effects as registry
from ..core.errors import ModelError
from ..core.model import Attachment, Cable, Damper
from ..effects.base import Truth

__all__ = ["Effects", "true_model"]


class Effects:
    """Differences between the true cable and the nominal one (all optional).

    ``Effects(tension_ratio=1.02, extra_mass=(9.6, 5.2))``: one keyword per
    effect, the ``truth_key`` its module declares (the effect's name is
    accepted too). The built-in keywords:

    - ``tension_ratio``: true tension / stated tension;
    - ``EI_ratio``: true bending stiffness / nominal EI;
    - ``attachment_positions``, ``attachment_masses``: {attachment: true
      position m / mass kg};
    - ``extra_mass``, ``extra_spring``: an unrecorded point mass (kg,
      position m) or transverse spring (N/m, position m);
    - ``end_stiffness``: true rotational stiffness of the ends (k_A, k_B),
      N m/rad (``math.inf`` clamped, 0 pinned);
    - ``length_ratio``: true vibrating length / chord length (positions
      stay measured from end A, so the change is at end B).

    Values are checked when built (a ModelError names ``effects.<keyword>``);
    the object is immutable and hashable. A keyword not given reads as None.

    Raises
    ------
    TypeError
        For a keyword no registered effect declares.
    """

    __slots__ = ("_values",)

    def __init__(self, **values: Any):
        checked: dict[str, Any] = {}
        for key, value in values.items():
            effect = registry.by_truth_key(key)
            if effect is None:
                raise TypeError(f"Effects() got an unexpected keyword argument {key!r}")
            if value is None:
                continue
            v = effect.check_truth(value, f"effects.{effect.truth_key}")
            if v is not None and v != ():
                checked[effect.name] = v
        order = registry.names()
        object.__setattr__(self, "_values", tuple(sorted(checked.items(), key=lambda kv: order.index(kv[0]))))

    def __setattr__(self, name, value):
        raise AttributeError("Effects is immutable")

    def __reduce__(self):
        return (_from_items, (self._values,))

    def __getattr__(self, key: str) -> Any:
        effect = registry.by_truth_key(key)
        if effect is None:
            raise AttributeError(key)
        return dict(self._values).get(effect.name)

    def __eq__(self, other) -> bool:
        return isinstance(other, Effects) and self._values == other._values

    def __hash__(self) -> int:
        return hash(self._values)

    def __repr__(self) -> str:
        shown = ", ".join(f"{registry.get(n).truth_key}={v!r}" for n, v in self._values)
        return f"Effects({shown})"

    def __bool__(self) -> bool:
        return bool(self._values)

    def items(self) -> tuple[tuple[str, Any], ...]:
        """(effect name, checked value) of every effect present, in vocabulary order."""
        return self._values

    @property
    def names(self) -> list[str]:
        """The effects present, in vocabulary order."""
        return [name for name, _ in self._values]

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON, by keyword (only the effects present)."""
        return {registry.get(n).truth_key: registry.get(n).truth_json(v) for n, v in self._values}


def _from_items(items: tuple) -> Effects:
    """An Effects object from checked (effect name, value) pairs (unpickling)."""
    out = Effects()
    object.__setattr__(out, "_values", tuple(items))
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
        added, names joined with ``+``), as the solver needs distinct nodes;
        a :class:`~stcs_ident.core.model.Damper` stays a Damper (merged with
        another, their dashpots add).
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
    truth = Truth(cable, list(atts), float(tension))
    for name, value in effects.items():
        registry.get(name).apply_truth(truth, value)
    length = truth.cable.length
    for a in truth.attachments:
        if not 0 < a.position < length:
            raise ModelError(f"{a.name} at {a.position} m is outside the true span (0, {length}) m",
                             field=truth.origin.get(a.name, truth.span_field))
    return truth.cable, _merge_coincident(truth.attachments), truth.tension


def _merge_coincident(atts: list[Attachment]) -> tuple[Attachment, ...]:
    """One attachment per position: masses and springs added; with a damper among them a Damper, whose
    dashpots add too (parallel dashpots to ground)."""
    merged: dict[float, Attachment] = {}
    for a in atts:
        b = merged.get(a.position)
        if b is None:
            merged[a.position] = a
            continue
        name, mass, stiffness = f"{b.name}+{a.name}", b.mass + a.mass, b.stiffness + a.stiffness
        if isinstance(a, Damper) or isinstance(b, Damper):
            coefficient = sum(x.coefficient for x in (a, b) if isinstance(x, Damper))
            merged[a.position] = Damper(name, a.position, mass, stiffness, coefficient=coefficient)
        else:
            merged[a.position] = Attachment(name, a.position, mass, stiffness)
    return tuple(sorted(merged.values(), key=lambda a: a.position))
