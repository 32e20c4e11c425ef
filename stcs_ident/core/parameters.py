"""Uncertain model parameters: what can be corrected, and how it enters the model.

One :class:`Parameter` is one free number of an identification. It knows
its kind (tension, EI, attachment position, ...: a :class:`~stcs_ident.core.kinds.Kind`
of the registry :mod:`stcs_ident.core.kinds`, which holds each kind's unit,
bounds and override), what it belongs to (a test
for a tension, an attachment for a position, an end for a rotational
stiffness), its nominal value, the dimensionless *variable* the optimiser
and the contour grids work in, and how a value of that variable becomes an
override of :func:`stcs_ident.forward.batch_frequencies`.

The variable is the ratio to the nominal value (H̃/H, ẼI/EI, l̃_k/l_k), as
in the source paper, except

- an attachment's mass, spring or dashpot, or the cable's EI (a bare
  cable), whose nominal value is zero: the variable is then the value
  itself in the kind's unit (kg, N/m, N s/m, N m²), bounded by
  ``[0, zero_upper(campaign)]`` of its kind;
- an end's rotational stiffness k: the variable is the *fixity*
  φ = k / (k + √(EI·H)), 0 for a pinned end and 1 for a clamped one. √(EI·H)
  is the stiffness at which the end's boundary layer (length √(EI/H)) is
  half restrained, so φ spreads the range that matters over [0, 1].

:func:`parse_parameters` turns names such as ``"tension,EI"``,
``"position[W1]"`` or ``"end_stiffness[A]"`` into parameters for the
selected tests; the diagnosis step reuses it with the effect vocabulary of
``docs/effects.md`` (``bending_stiffness``, ``attachment_position``, ...),
whose names the effects register as aliases of their kinds when
:mod:`stcs_ident.effects` is imported (:mod:`stcs_ident.identify` imports it).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from . import kinds
from .errors import InputError
from .kinds import coefficient_upper
from .model import Campaign, Test

__all__ = ["POSITION_MARGIN", "Parameter", "coefficient_upper", "fixity", "overrides_for", "parse_name",
           "parse_parameters", "stiffness_of_fixity"]

#: Positions stay this fraction of the length away from the anchorages.
POSITION_MARGIN = 1e-3

_NAME = re.compile(r"^\s*([A-Za-z_]+?)(?:_ratio)?\s*(?:\[\s*([^\]]*?)\s*\])?\s*$")


@dataclass(frozen=True)
class Parameter:
    """One free parameter of an identification.

    Attributes
    ----------
    kind : str
        The name of a registered kind (:mod:`stcs_ident.core.kinds`).
    member : str or None
        The test (tension), the attachment (``"W1"``, or ``"case2:W1"`` when
        two setups of the selected tests have an attachment of that name),
        the end (``"A"``, ``"B"`` or ``"AB"`` for both ends as one
        parameter), or None for a cable property.
    nominal : float
        Nominal value in SI units (N, N m², m, kg, N/m, N m/rad).
    scale : float
        SI value of one unit of the variable: value = variable × scale.
        Unused for ``end_stiffness``, whose variable is the fixity.
    lower, upper : float
        Bounds of the variable.
    setup : str or None
        The setup of an attachment parameter.
    index : int or None
        Place of the attachment in its setup (ascending position).
    reference_stiffness : float
        √(EI·H) (N m/rad) of the fixity of an ``end_stiffness`` parameter.
    slots : tuple of (str, int)
        For an attachment parameter shared by several setups (the diagnosis's
        unmodeled mass or support, added to every setup): the (setup, index)
        pairs it sets. Empty for an attachment of one setup (``setup`` and
        ``index``).
    """

    kind: str
    member: str | None
    nominal: float
    scale: float
    lower: float
    upper: float
    setup: str | None = None
    index: int | None = None
    reference_stiffness: float = 1.0
    slots: tuple[tuple[str, int], ...] = ()

    def slot(self, setup: str) -> int | None:
        """Index of the attachment this parameter sets in ``setup`` (None: not in it)."""
        if self.slots:
            return dict(self.slots).get(setup)
        return self.index if setup == self.setup else None

    @property
    def spec(self) -> kinds.Kind:
        """The parameter's kind (:class:`~stcs_ident.core.kinds.Kind`): its unit, bounds, override, ..."""
        return kinds.get(self.kind)

    @property
    def unit(self) -> str:
        """SI unit of the parameter's value."""
        return kinds.get(self.kind).unit

    @property
    def is_fixity(self) -> bool:
        """True when the variable is an end's fixity rather than a ratio or a value."""
        return kinds.get(self.kind).variable == "fixity"

    @property
    def name(self) -> str:
        """Display name: ``EI_ratio``, ``tension_ratio[case1-L4]``, ``end_fixity[A]``."""
        return self.key if self.member is None else f"{self.key}[{self.member}]"

    @property
    def key(self) -> str:
        """JSON key of the variable (``tension_ratio``, ``mass`` for a zero-nominal mass, ...)."""
        if self.is_fixity:
            return "end_fixity"
        return f"{self.kind}_ratio" if self.is_ratio else self.kind

    @property
    def is_ratio(self) -> bool:
        """True when the variable is the ratio to the nominal value."""
        return not self.is_fixity and self.scale == self.nominal

    @property
    def start(self) -> float:
        """The variable at the nominal value."""
        return self.to_variable(self.nominal)

    def to_variable(self, value):
        """The variable at the SI value ``value``: the inverse of :meth:`to_value`."""
        if self.is_fixity:
            return fixity(value, self.reference_stiffness)
        return value / self.scale

    def to_value(self, variable):
        """SI value(s) of the variable (array-friendly)."""
        if self.is_fixity:
            return stiffness_of_fixity(variable, self.reference_stiffness)
        return np.asarray(variable, float) * self.scale

    def value_uncertainty(self, variable: float, sigma: float) -> float:
        """Standard deviation in SI units, to first order (inf where the map is singular)."""
        if not self.is_fixity:
            return abs(sigma * self.scale)
        if variable >= 1.0:
            return math.inf
        return abs(sigma) * self.reference_stiffness / (1.0 - variable) ** 2

    def applies_to(self, test: Test) -> bool:
        """Whether the parameter changes the model of ``test``."""
        belongs_to = kinds.get(self.kind).belongs_to
        if belongs_to == "test":
            return self.member == test.name
        if belongs_to == "attachment":
            return self.slot(test.setup) is not None
        return True


def fixity(stiffness, reference: float):
    """φ = k / (k + k_ref): 0 pinned, 1 clamped (k = inf)."""
    k = np.asarray(stiffness, float)
    with np.errstate(invalid="ignore"):
        phi = np.where(np.isinf(k), 1.0, k / (k + reference))
    return float(phi) if phi.ndim == 0 else phi


def stiffness_of_fixity(phi, reference: float):
    """k = k_ref φ / (1 − φ): the inverse of :func:`fixity` (inf at φ = 1)."""
    phi = np.asarray(phi, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(phi >= 1.0, np.inf, reference * phi / (1.0 - phi))
    return float(k) if k.ndim == 0 else k


def _known_names() -> str:
    return ", ".join([*kinds.names(), *kinds.aliases()])


def _split(spec: str | Iterable[str]) -> list[str]:
    """``"tension,EI"`` or ``["tension", "EI"]`` → names; commas inside [] kept."""
    items = [spec] if isinstance(spec, str) else list(spec)
    out = []
    for item in items:
        if not isinstance(item, str):
            raise InputError(f"parameter names must be strings, got {item!r}", field="params")
        out += [part for part in re.split(r",(?![^\[]*\])", item) if part.strip()]
    if not out:
        raise InputError("no parameter named", field="params")
    return out


def parse_name(name: str) -> tuple[str, str | None]:
    """``"position[W1]"`` → ``("position", "W1")``; aliases resolved, unknown names refused."""
    match = _NAME.match(name)
    kind = kinds.resolve(match.group(1)) if match else None
    if kind is None:
        raise InputError(f"unknown parameter {name.strip()!r}; known: {_known_names()}", field="params")
    return kind, (match.group(2) or None)


def parse_parameters(campaign: Campaign, tests: Sequence[Test], spec: str | Iterable[str] = "tension,EI",
                     bounds: Mapping[str, tuple[float, float]] | None = None) -> tuple[Parameter, ...]:
    """Free parameters named by ``spec`` for the selected ``tests``.

    Parameters
    ----------
    campaign : Campaign
    tests : sequence of Test
        The tests fitted together; a tension is one parameter per test,
        everything else is shared (an attachment by all tests of its setup).
    spec : str or iterable of str
        Comma-separated names: ``tension``, ``EI``, ``length``,
        ``mass_per_length``, ``position``, ``mass``, ``stiffness``,
        ``end_stiffness`` (one fixity for both ends; ``end_stiffness[A]``,
        ``end_stiffness[B]`` for one end each), any other registered kind
        (:func:`stcs_ident.core.kinds.register`), or an alias from the effect
        vocabulary (``bending_stiffness``, ``attachment_position``,
        ``attachment_mass``, ``end_restraint``). A member in brackets
        restricts a per-test or per-attachment kind: ``tension[case1-L4]``,
        ``position[W1]``, ``position[case2:W1]``. A ``_ratio`` suffix is
        accepted (``EI_ratio``).
    bounds : mapping, optional
        ``{name: (lower, upper)}`` in variable units (ratios; the kind's unit
        for a zero-nominal mass, spring, dashpot or EI; fixity in [0, 1]), keyed by a kind
        (``"EI"``, ``"position"``) or a display name
        (``"position_ratio[W1]"``, ``"position[W1]"``). They replace the
        campaign's ``[bounds]`` (``campaign.bounds``), which replace the
        kinds' default bounds.

    Returns
    -------
    tuple of Parameter

    Raises
    ------
    InputError
        ``field="params"`` for an unknown name, a member that does not exist
        or a parameter named twice; ``field="bounds.<name>"`` for bounds that
        are not increasing or exclude the nominal value.
    """
    cable = campaign.cable
    tension_scale = float(np.mean([t.tension for t in tests])) if tests else 1.0
    k_ref = math.sqrt(max(cable.EI, 1e-12) * tension_scale)
    params: list[Parameter] = []
    for name in _split(spec):
        kind, member = parse_name(name)
        params += _expand(campaign, tests, kind, member, name.strip(), k_ref)
    names = [p.name for p in params]
    for n in names:
        if names.count(n) > 1:
            raise InputError(f"parameter {n} is named twice", field="params")
    for kind in dict.fromkeys(p.kind for p in params if p.spec.belongs_to == "end"):
        ends = {p.member for p in params if p.kind == kind}
        if "AB" in ends and len(ends) > 1:
            raise InputError(f"{kind} for both ends and for one end at once", field="params")
    for key in dict(campaign.bounds):
        if key not in kinds.names():
            raise InputError(f"unknown parameter kind {key!r}; known: {', '.join(kinds.names())}",
                             field=f"bounds.{key}")
    given = {**dict(campaign.bounds), **dict(bounds or {})}  # the keyword wins over the campaign's [bounds]
    return tuple(_with_bounds(p, given, cable.length) for p in params)


def _expand(campaign: Campaign, tests: Sequence[Test], kind: str, member: str | None, name: str,
            k_ref: float) -> list[Parameter]:
    cable = campaign.cable
    spec = kinds.get(kind)
    lo, hi = spec.bounds
    if spec.belongs_to == "test":
        chosen = [t for t in tests if member is None or t.name == member]
        if not chosen:
            known = ", ".join(t.name for t in tests)
            raise InputError(f"{name}: no selected test named {member!r} (selected: {known})", field="params")
        return [Parameter(kind, t.name, getattr(t, spec.attribute), getattr(t, spec.attribute), lo, hi)
                for t in chosen]
    if spec.belongs_to == "cable":
        if member is not None:
            raise InputError(f"{name}: {kind} is a cable property and takes no [member]", field="params")
        nominal = float(getattr(cable, spec.attribute))
        if nominal <= 0:
            if spec.zero_upper is None:
                raise InputError(f"{name}: the nominal {kind} is 0, so it has no ratio", field="params")
            # Zero nominal (a bare cable's EI): the variable is the value itself, in the kind's unit.
            return [Parameter(kind, None, 0.0, 1.0, 0.0, spec.zero_upper(campaign))]
        return [Parameter(kind, None, nominal, nominal, lo, hi)]
    if spec.belongs_to == "end":
        ends = {"A": cable.boundary_a, "B": cable.boundary_b}
        if member is None:
            if cable.boundary_a != cable.boundary_b:
                return [Parameter(kind, e, getattr(b, spec.attribute), 1.0, lo, hi, reference_stiffness=k_ref)
                        for e, b in ends.items()]
            return [Parameter(kind, "AB", getattr(cable.boundary_a, spec.attribute), 1.0, lo, hi,
                              reference_stiffness=k_ref)]
        end = member.upper()
        if end not in ends:
            raise InputError(f"{name}: the end must be A or B, got {member!r}", field="params")
        return [Parameter(kind, end, getattr(ends[end], spec.attribute), 1.0, lo, hi, reference_stiffness=k_ref)]
    return _attachment_parameters(campaign, tests, spec, member, name)


def _attachment_parameters(campaign: Campaign, tests: Sequence[Test], spec: kinds.Kind, member: str | None,
                           name: str) -> list[Parameter]:
    kind = spec.name
    setups = list(dict.fromkeys(t.setup for t in tests))
    found = [(s, i, a) for s in setups for i, a in enumerate(campaign.setup(s).attachments)
             if hasattr(a, spec.attribute)]
    if not found:
        raise InputError(f"{name}: the setups of the selected tests have no {spec.noun}", field="params")
    counts: dict[str, int] = {}
    for _, _, a in found:
        counts[a.name] = counts.get(a.name, 0) + 1
    chosen = []
    for s, i, a in found:
        label = a.name if counts[a.name] == 1 else f"{s}:{a.name}"
        if member is None or member in (a.name, f"{s}:{a.name}"):
            chosen.append((s, i, a, label))
    if not chosen:
        known = ", ".join(dict.fromkeys(a.name for _, _, a in found))
        raise InputError(f"{name}: no attachment {member!r} in the selected tests' setups (known: {known})",
                         field="params")
    out = []
    cable = campaign.cable
    for s, i, a, label in chosen:
        nominal = getattr(a, spec.attribute)
        if kind == "position":
            lo, hi = POSITION_MARGIN * cable.length / nominal, (1 - POSITION_MARGIN) * cable.length / nominal
            out.append(Parameter(kind, label, nominal, nominal, lo, hi, setup=s, index=i))
            continue
        if nominal > 0:
            out.append(Parameter(kind, label, nominal, nominal, *spec.bounds, setup=s, index=i))
            continue
        if spec.zero_upper is None:
            raise InputError(f"{name}: the nominal {kind} of {label} is 0, so it has no ratio", field="params")
        # Zero nominal: the variable is the value itself, bounded by the cable's own scale.
        out.append(Parameter(kind, label, 0.0, 1.0, 0.0, spec.zero_upper(campaign), setup=s, index=i))
    return out


def _with_bounds(p: Parameter, bounds: Mapping[str, tuple[float, float]], length: float) -> Parameter:
    """Apply a user bound (by display name first, then by kind) and check it."""
    candidates = [p.name, f"{p.kind}[{p.member}]" if p.member else p.kind, p.key, p.kind]
    given = next((bounds[c] for c in candidates if c in bounds), None)
    lo, hi = (p.lower, p.upper) if given is None else given
    field = f"bounds.{p.name}"
    try:
        lo, hi = float(lo), float(hi)
    except (TypeError, ValueError):
        raise InputError(f"must be two numbers (lower, upper), got {given!r}", field=field) from None
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo >= hi:
        raise InputError(f"must satisfy lower < upper (finite), got [{lo:g}, {hi:g}]", field=field)
    if not lo <= p.start <= hi:
        raise InputError(f"bounds [{lo:g}, {hi:g}] exclude the nominal value {p.start:g}", field=field)
    if p.kind == "position":
        lo = max(lo, POSITION_MARGIN * length / p.nominal)
        hi = min(hi, (1 - POSITION_MARGIN) * length / p.nominal)
    elif p.spec.zero_upper is None and not p.is_fixity:  # always a ratio
        if lo <= 0:
            raise InputError(f"the lower bound must be > 0, got {lo:g}", field=field)
    elif lo < 0:
        raise InputError(f"the lower bound must be >= 0, got {lo:g}", field=field)
    if p.is_fixity and hi > 1:
        raise InputError(f"the fixity lies in [0, 1], got upper bound {hi:g}", field=field)
    return Parameter(p.kind, p.member, p.nominal, p.scale, lo, hi, p.setup, p.index, p.reference_stiffness,
                     p.slots)


def overrides_for(test: Test, parameters: Sequence[Parameter], X: np.ndarray, n_attachments: int,
                  nominal_attachments: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Overrides of ``batch_frequencies`` for ``test`` at the variable rows ``X`` (k, p).

    Only what a parameter of this test touches is overridden; ``tension`` is
    always returned (shape (k,)).
    """
    k = X.shape[0]
    out: dict[str, np.ndarray] = {"tension": np.full(k, test.tension)}
    for j, p in enumerate(parameters):
        if not p.applies_to(test):
            continue
        column = X[:, j]
        spec = p.spec
        slot = spec.override
        if spec.belongs_to == "end":
            value = p.to_value(column)
            for end in ("end_a", "end_b") if p.member == "AB" else ("end_a" if p.member == "A" else "end_b",):
                out[end] = np.broadcast_to(value, (k,)).astype(float)
        elif spec.belongs_to == "attachment":
            if slot not in out:
                out[slot] = np.tile(nominal_attachments[slot], (k, 1))
            out[slot][:, p.slot(test.setup)] = p.to_value(column)
        else:
            out[slot] = p.to_value(column) * np.ones(k)
    return out
