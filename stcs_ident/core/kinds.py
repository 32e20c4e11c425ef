"""Parameter kinds: one record per kind of model parameter, in one registry.

A *kind* is a model quantity an identification may free: the tension of a
test, the cable's EI, an attachment's position or mass, an end's
rotational stiffness. Everything the package needs to know about a kind
lives in its :class:`Kind` record: its SI unit and the symbol of its
figures, what it belongs to, the model field it reads and the override of
:func:`stcs_ident.forward.batch_frequencies` it sets, the default bounds of
its variable and the span of its contour grid, what the variable is when
the nominal value is zero, the campaign's ``[tolerance]`` key, and the
other names it answers to. The rest of the package loops over
:func:`kinds` or asks :func:`get` instead of keeping tables of its own.

Adding a kind is one record and one call:

>>> from stcs_ident.core import kinds
>>> kinds.get("EI").unit
'N m^2'
>>> toy = kinds.register(kinds.Kind("linear_density", unit="kg/m", symbol="μ", belongs_to="cable",
...                                 attribute="mass_per_length", override="mass_per_length"))
>>> kinds.resolve("linear_density")
'linear_density'
>>> kinds.unregister("linear_density")

The effects (:mod:`stcs_ident.effects`) add their names as aliases of the
kind they free (``bending_stiffness`` → ``EI``) with :func:`add_alias` when
they are registered; this module never imports them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .model import Campaign

#: What a kind may belong to: one value per test, one for the cable, one per attachment, one per end.
BELONGS_TO = ("test", "cable", "attachment", "end")
#: What the optimiser's variable may be: the ratio to the nominal value, or an end's fixity.
VARIABLES = ("ratio", "fixity")


@dataclass(frozen=True)
class Tolerance:
    """How well a nominal value is usually known: one key of a campaign's ``[tolerance]`` table.

    Attributes
    ----------
    key : str
        Key of the campaign's ``[tolerance]`` table.
    default : float
        Used when the campaign gives none.
    relative : bool
        Relative (a fraction of the nominal value) or absolute (SI units).
    unit : str
        Unit of an absolute tolerance.
    """

    key: str
    default: float
    relative: bool = True
    unit: str = ""


@dataclass(frozen=True)
class Kind:
    """One kind of model parameter.

    Attributes
    ----------
    name : str
        The kind's name (``Parameter.kind``, ``identify --params``).
    unit : str
        SI unit of its value, as tables, notes and figures write it.
    symbol : str
        Symbol of the value in figures (``H`` gives the axis label ``H̃/H``).
    belongs_to : {"test", "cable", "attachment", "end"}
        One value per test (a tension), one for the cable, one per
        attachment, or one per end.
    override : str or None
        Keyword of :func:`stcs_ident.forward.batch_frequencies` the value
        sets (``"positions"`` for an attachment's position); None for an end,
        whose member names the keyword (``end_a``, ``end_b``).
    attribute : str
        Field of the :class:`~stcs_ident.core.model.Test`,
        :class:`~stcs_ident.core.model.Cable`,
        :class:`~stcs_ident.core.model.Attachment` or (for an end)
        :class:`~stcs_ident.core.model.Boundary` that holds the nominal
        value; default the name. An attachment without that field does not
        have the kind (only a damper has a ``coefficient``).
    bounds : (float, float)
        Default bounds of the variable (a ratio unless the nominal value is
        zero, see ``zero_upper``).
    grid : (float, float)
        Default span of a contour grid over the ratio (clipped to the bounds).
    variable : {"ratio", "fixity"}
        The optimiser's variable: the ratio to the nominal value, or for an
        end's rotational stiffness k the fixity φ = k / (k + √(EI·H)).
    zero_upper : callable or None
        When the nominal value is zero the variable is the value itself (in
        ``unit``), bounded by ``[0, zero_upper(campaign)]``; None: a zero
        nominal value has no ratio and is refused.
    tolerance : Tolerance or None
        The campaign's ``[tolerance]`` key of the nominal value and its
        default; None when the campaign cannot state one.
    aliases : tuple of str
        Other names the kind answers to (``ei``, ``rotational_stiffness``).
    amplitude : bool
        Gives an effect without a tolerance its size (a mass, a spring, a
        dashpot, an end restraint): the diagnosis names such an effect only
        when the data establish that size.
    noted_in_si : bool
        A note's point gives the kind's SI value (False: its variable, as
        for a tension ratio or an end fixity).
    noun : str
        What a member is called in messages (default ``belongs_to``).
    """

    name: str
    unit: str
    symbol: str
    belongs_to: str
    override: str | None
    attribute: str = ""
    bounds: tuple[float, float] = (0.5, 2.0)
    grid: tuple[float, float] = (0.9, 1.1)
    variable: str = "ratio"
    zero_upper: Callable[[Campaign], float] | None = None
    tolerance: Tolerance | None = None
    aliases: tuple[str, ...] = ()
    amplitude: bool = False
    noted_in_si: bool = True
    noun: str = ""

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"a kind's name must be an identifier, got {self.name!r}")
        if self.belongs_to not in BELONGS_TO:
            raise ValueError(f"kind {self.name}: belongs_to must be one of {BELONGS_TO}, got {self.belongs_to!r}")
        if self.variable not in VARIABLES:
            raise ValueError(f"kind {self.name}: variable must be one of {VARIABLES}, got {self.variable!r}")
        if (self.override is None) != (self.belongs_to == "end"):
            raise ValueError(f"kind {self.name}: an end's kind has no override, every other kind has one")
        lo, hi = self.bounds
        if not lo < hi:
            raise ValueError(f"kind {self.name}: bounds must be increasing, got {self.bounds!r}")
        object.__setattr__(self, "attribute", self.attribute or self.name)
        object.__setattr__(self, "noun", self.noun or self.belongs_to)
        object.__setattr__(self, "aliases", tuple(self.aliases))


_KINDS: dict[str, Kind] = {}
#: Aliases added by :func:`add_alias` (the effects' names), apart from the kinds' own.
_ADDED: dict[str, str] = {}


def register(kind: Kind) -> Kind:
    """Add ``kind`` to the registry (after the others) and return it.

    Raises
    ------
    TypeError
        For anything but a :class:`Kind`.
    ValueError
        For a name or alias already taken, or a ``[tolerance]`` key another
        kind already has.
    """
    if not isinstance(kind, Kind):
        raise TypeError(f"a kind must be a Kind instance, got {kind!r}")
    for name in (kind.name, *kind.aliases):
        if name in _KINDS or name in aliases():
            raise ValueError(f"the name {name!r} is already taken by a parameter kind")
    if kind.tolerance is not None and kind.tolerance.key in tolerance_keys():
        raise ValueError(f"the tolerance key {kind.tolerance.key!r} is already taken")
    _KINDS[kind.name] = kind
    return kind


def unregister(name: str) -> None:
    """Remove a kind (a test's own, when the test is done) and the aliases added for it."""
    _KINDS.pop(name, None)
    for alias in [a for a, k in _ADDED.items() if k == name]:
        del _ADDED[alias]


def get(name: str) -> Kind:
    """The kind called ``name`` (KeyError if there is none; see :func:`resolve` for aliases)."""
    return _KINDS[name]


def kinds() -> tuple[Kind, ...]:
    """Every registered kind, in registration order."""
    return tuple(_KINDS.values())


def names() -> tuple[str, ...]:
    """Every registered kind's name, in registration order."""
    return tuple(_KINDS)


def add_alias(alias: str, kind: str) -> None:
    """Let ``alias`` name the kind ``kind`` (an effect's name: ``bending_stiffness`` → ``EI``).

    Raises
    ------
    ValueError
        For an unknown kind, or an alias that names a kind or another kind's alias.
    """
    if kind not in _KINDS:
        raise ValueError(f"no parameter kind {kind!r} to alias as {alias!r}; known: {', '.join(_KINDS)}")
    taken = aliases().get(alias)
    if alias in _KINDS or (taken is not None and taken != kind):
        raise ValueError(f"the name {alias!r} is already taken by a parameter kind")
    _ADDED[alias] = kind


def remove_alias(alias: str) -> None:
    """Undo :func:`add_alias` (a kind's own aliases stay)."""
    _ADDED.pop(alias, None)


def aliases() -> dict[str, str]:
    """Every other name of a kind → the kind: the added aliases first, then the kinds' own."""
    own = {a: k.name for k in _KINDS.values() for a in k.aliases}
    return {**_ADDED, **own}


def resolve(word: str) -> str | None:
    """The kind ``word`` names: a kind's name or alias, as given, in lower case, or a kind's name in
    another case (``ei``, ``Ei``); None when it names none."""
    known = aliases()
    kind = word if word in _KINDS else known.get(word, known.get(word.lower()))
    if kind is None:
        kind = next((k for k in _KINDS if k.lower() == word.lower()), None)
    return kind


def unit(name: str) -> str | None:
    """SI unit of the kind ``name`` names (an alias too), or None when it names no kind."""
    kind = resolve(name)
    return None if kind is None else _KINDS[kind].unit


def tolerance_keys() -> tuple[str, ...]:
    """The keys of a campaign's ``[tolerance]`` table: those of the registered kinds."""
    return tuple(k.tolerance.key for k in _KINDS.values() if k.tolerance is not None)


def mean_tension(campaign: Campaign) -> float:
    """Mean stated tension of the campaign's tests (N; 1 without tests)."""
    return float(np.mean([t.tension for t in campaign.tests])) if campaign.tests else 1.0


def coefficient_upper(campaign: Campaign) -> float:
    """Largest dashpot worth a search (N s/m): 1000 √(H m), thirty times the optimum of mode 1 for a
    damper at 1 % of the length (η = c π x_d/(l √(H m)) = 1)."""
    return 1e3 * math.sqrt(mean_tension(campaign) * campaign.cable.mass_per_length)


def _cable_mass(campaign: Campaign) -> float:
    """The whole cable's mass (kg): the largest point mass worth a search."""
    return campaign.cable.mass_per_length * campaign.cable.length


def _stiff_support(campaign: Campaign) -> float:
    """100 H / l (N/m): a spring a hundred times the cable's own transverse stiffness, near a fixed point."""
    return 100.0 * mean_tension(campaign) / campaign.cable.length


def bare_EI_upper(campaign: Campaign) -> float:
    """Largest EI worth a search on a bare cable (N m²): T_max l² / 4, at which ξ = l √(T/EI) drops to 2
    for the campaign's largest tension. Below ξ ≈ 2 bending, not tension, sets even the first mode: the
    member is a beam, and a campaign that calls it a cable with EI = 0 is wrong in more than its EI."""
    tension = max((t.tension for t in campaign.tests), default=1.0)
    return tension * campaign.cable.length**2 / 4.0


for _kind in (
    Kind("tension", "N", "H", "test", "tension", bounds=(0.5, 2.0), grid=(0.9, 1.1),
         tolerance=Tolerance("tension", 0.02), noted_in_si=False),
    Kind("EI", "N m^2", "EI", "cable", "EI", bounds=(0.01, 100.0), grid=(0.5, 1.5), zero_upper=bare_EI_upper,
         tolerance=Tolerance("EI", 0.3), aliases=("ei",)),
    Kind("length", "m", "l", "cable", "length", bounds=(0.8, 1.2), grid=(0.97, 1.03),
         tolerance=Tolerance("length", 0.002)),
    # A cable's mass per length comes from its strand count and sheath, from tables: the filler, grease and
    # sheath thickness make it uncertain by about a percent, and the tension goes with it one to one.
    Kind("mass_per_length", "kg/m", "m", "cable", "mass_per_length", bounds=(0.5, 2.0), grid=(0.9, 1.1),
         tolerance=Tolerance("mass_per_length", 0.01)),
    # A position's bounds keep it a margin away from the anchorages (core.parameters), whatever these say.
    Kind("position", "m", "x", "attachment", "positions", bounds=(0.0, 1.0), grid=(0.9, 1.1),
         tolerance=Tolerance("position", 0.02, relative=False, unit="m")),
    Kind("mass", "kg", "M", "attachment", "masses", bounds=(0.0, 10.0), grid=(0.5, 1.5), zero_upper=_cable_mass,
         tolerance=Tolerance("mass", 0.02), amplitude=True),
    Kind("stiffness", "N/m", "s", "attachment", "stiffnesses", bounds=(0.0, 100.0), grid=(0.5, 1.5),
         zero_upper=_stiff_support, aliases=("attachment_stiffness",), amplitude=True),
    Kind("coefficient", "N s/m", "c", "attachment", "coefficients", bounds=(0.01, 100.0), grid=(0.5, 1.5),
         zero_upper=coefficient_upper, tolerance=Tolerance("coefficient", 0.2), aliases=("damper",),
         amplitude=True, noun="damper"),
    Kind("end_stiffness", "N m/rad", "k", "end", None, attribute="rotational_stiffness", bounds=(0.0, 1.0),
         grid=(0.0, 1.0), variable="fixity",
         aliases=("rotational_stiffness",), amplitude=True, noted_in_si=False),
):
    register(_kind)
