"""The registry of effects: the one place that knows which effects exist.

The built-in effects register themselves when :mod:`stcs_ident.effects` is
imported, in the order of the vocabulary; :func:`register` adds another
(a user's or a test's own effect) at the end. Everything that loops over
effects (hypotheses, simulator, report, command line) reads
:func:`effects` or :func:`get`.

Registering an effect that frees a parameter kind under another name
(``bending_stiffness`` frees ``EI``) adds its name as an alias of the kind
in :mod:`stcs_ident.core.kinds`, so that identification accepts it; the
campaign's ``[tolerance]`` keys are the kinds' (an effect's tolerance is its
kind's). The kinds never import the effects.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from ..core import kinds
from ..core.errors import InputError
from .base import Effect

_REGISTRY: dict[str, Effect] = {}


def register(effect: Effect) -> Effect:
    """Add ``effect`` (an :class:`~stcs_ident.effects.base.Effect` instance) to the vocabulary.

    Raises
    ------
    ValueError
        For an effect without a name, a name or ``truth_key`` already taken, an unknown
        ``parameter_kind`` (register the kind first), a name that another kind answers to, or a
        tolerance whose key is no kind's.
    """
    if not isinstance(effect, Effect) or not effect.name:
        raise ValueError(f"an effect must be an Effect instance with a name, got {effect!r}")
    if effect.name in _REGISTRY:
        raise ValueError(f"an effect named {effect.name!r} is already registered")
    if effect.truth_key and any(e.truth_key == effect.truth_key for e in _REGISTRY.values()):
        raise ValueError(f"the simulator keyword {effect.truth_key!r} is already taken")
    kind = effect.parameter_kind
    if kind is not None and kind not in kinds.names():
        raise ValueError(f"effect {effect.name!r} frees the unknown parameter kind {kind!r}; known: "
                         f"{', '.join(kinds.names())}")
    declared = effect.tolerance
    if declared is not None and declared.key not in kinds.tolerance_keys():
        raise ValueError(f"effect {effect.name!r} declares the tolerance key {declared.key!r}, which no "
                         f"parameter kind has (a tolerance belongs to a kind: core.kinds.Kind.tolerance)")
    if kind is not None and effect.name != kind:
        kinds.add_alias(effect.name, kind)
    _REGISTRY[effect.name] = effect
    return effect


def unregister(name: str) -> None:
    """Remove an effect (a test's own effect, when the test is done) and the alias it added."""
    effect = _REGISTRY.pop(name, None)
    if effect is not None and effect.parameter_kind is not None and effect.name != effect.parameter_kind:
        kinds.remove_alias(effect.name)


def effects() -> tuple[Effect, ...]:
    """Every registered effect, in vocabulary order."""
    return tuple(_REGISTRY.values())


def names() -> tuple[str, ...]:
    """Every registered effect's name, in vocabulary order."""
    return tuple(_REGISTRY)


def get(name: str) -> Effect:
    """The effect called ``name`` (KeyError if there is none)."""
    return _REGISTRY[name]


def by_truth_key(key: str) -> Effect | None:
    """The effect hidden by the simulator keyword ``key`` (or named ``key``), or None."""
    for e in _REGISTRY.values():
        if key in (e.truth_key, e.name):
            return e
    return None


def in_order(chosen: Iterable[str]) -> tuple[str, ...]:
    """``chosen`` effect names in vocabulary order (unknown names dropped)."""
    chosen = set(chosen)
    return tuple(n for n in _REGISTRY if n in chosen)


def baseline() -> tuple[str, ...]:
    """The effects of the source paper's correction (tension and EI re-estimated)."""
    return tuple(e.name for e in _REGISTRY.values() if e.baseline)


def tolerance_keys() -> tuple[str, ...]:
    """The keys of a campaign's ``[tolerance]`` table: those of the parameter kinds
    (:func:`stcs_ident.core.kinds.tolerance_keys`), every effect's among them."""
    return kinds.tolerance_keys()


def tolerance(campaign, effect: str) -> float | None:
    """The tolerance of the nominal value ``effect`` changes: the campaign's ``[tolerance]`` value for
    its key, else the effect's default (None when the effect changes no nominal value)."""
    declared = get(effect).tolerance
    if declared is None:
        return None
    return dict(campaign.tolerance).get(declared.key, declared.default)


def parse(spec: str | Sequence[str] | None) -> tuple[str, ...]:
    """``"tension,unmodeled_mass"`` → effect names in vocabulary order; None → all.

    Raises
    ------
    InputError
        ``field="effects"`` for a name outside the vocabulary or none at all.
    """
    if spec is None:
        return names()
    items = [spec] if isinstance(spec, str) else list(spec)
    chosen = [part.strip() for item in items for part in str(item).split(",") if part.strip()]
    if not chosen:
        raise InputError("no effect named", field="effects")
    for name in chosen:
        if name not in _REGISTRY:
            raise InputError(f"unknown effect {name!r}; the vocabulary is: {', '.join(_REGISTRY)}", field="effects")
    return in_order(chosen)
