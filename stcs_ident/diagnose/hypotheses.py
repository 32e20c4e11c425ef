"""Hypotheses: the nominal model extended by effects of the fixed vocabulary.

Each effect of ``interface.md`` becomes free parameters of the
identification step (:mod:`stcs_ident.identify.parameters`), shared across
tests where the physics says so:

===================== ============================================ =====================
effect                parameters                                    shared by
===================== ============================================ =====================
tension               tension ratio                                 one per test
bending_stiffness     EI ratio                                      all tests
attachment_position   position of every recorded attachment         the tests of its setup
attachment_mass       mass of every recorded attachment             the tests of its setup
unmodeled_mass        mass (kg) and position (m) of a point mass    all tests
unmodeled_support     stiffness (N/m) and position of a spring      all tests
end_restraint         fixity of the ends (both ends one value)      all tests
length                vibrating length ratio                        all tests
===================== ============================================ =====================

An unmodeled mass or support is a new attachment added to every setup
(mass and stiffness zero in the nominal model, so the nominal predictions
are unchanged), whose parameters carry one ``slot`` per setup.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from ..identify.parameters import Parameter, parse_parameters
from ..model import Attachment, Campaign, Test

#: The effect vocabulary of ``interface.md``, in its order.
EFFECTS = ("tension", "bending_stiffness", "attachment_position", "attachment_mass", "unmodeled_mass",
           "unmodeled_support", "end_restraint", "length")

#: Name of the attachment that carries an unmodeled mass or support.
UNMODELED = {"unmodeled_mass": "(unmodeled mass)", "unmodeled_support": "(unmodeled support)"}

#: The identification parameter names of the other effects.
_SPEC = {"tension": "tension", "bending_stiffness": "EI", "attachment_position": "position",
         "attachment_mass": "mass", "end_restraint": "end_stiffness", "length": "length"}

#: Positions stay this fraction of the length away from the anchorages (as in identify).
POSITION_MARGIN = 1e-3

#: An unmodeled attachment keeps this fraction of the length from a recorded one.
CLEARANCE = 5e-3


@dataclass(frozen=True)
class Hypothesis:
    """The nominal model with some effects switched on.

    Attributes
    ----------
    effects : tuple of str
        In vocabulary order; empty for the nominal model.
    campaign : Campaign
        The campaign the parameters refer to: the nominal one, with the
        unmodeled attachments added to every setup.
    parameters : tuple of Parameter
    owners : tuple of str
        The effect of each parameter.
    """

    effects: tuple[str, ...]
    campaign: Campaign
    parameters: tuple[Parameter, ...]
    owners: tuple[str, ...]

    @property
    def label(self) -> str:
        return " + ".join(self.effects) if self.effects else "nominal"


def parse_effects(spec: str | Sequence[str] | None) -> tuple[str, ...]:
    """``"tension,unmodeled_mass"`` → effect names in vocabulary order; None → all.

    Raises
    ------
    InputError
        ``field="effects"`` for a name outside the vocabulary or none at all.
    """
    if spec is None:
        return EFFECTS
    items = [spec] if isinstance(spec, str) else list(spec)
    names = [part.strip() for item in items for part in str(item).split(",") if part.strip()]
    if not names:
        raise InputError("no effect named", field="effects")
    for name in names:
        if name not in EFFECTS:
            raise InputError(f"unknown effect {name!r}; the vocabulary is: {', '.join(EFFECTS)}", field="effects")
    return tuple(e for e in EFFECTS if e in names)


def recorded_attachments(campaign: Campaign, tests: Sequence[Test]) -> list[tuple[str, Attachment]]:
    """(setup, attachment) of every recorded attachment in the setups of ``tests``."""
    setups = dict.fromkeys(t.setup for t in tests)
    return [(s, a) for s in setups for a in campaign.setup(s).attachments]


def applicable(campaign: Campaign, tests: Sequence[Test], effect: str) -> str | None:
    """Why ``effect`` cannot be a hypothesis for these tests (None when it can)."""
    if effect in ("attachment_position", "attachment_mass") and not recorded_attachments(campaign, tests):
        used = ", ".join(dict.fromkeys(t.setup for t in tests))
        return (f"{effect} needs a recorded attachment in the setup of a measured test, and the measured "
                f"tests' setups ({used}) have none")
    if effect == "bending_stiffness" and campaign.cable.EI <= 0:
        return "bending_stiffness has no ratio: the nominal EI is 0"
    return None


def free_positions(campaign: Campaign, tests: Sequence[Test], n: int = 25) -> np.ndarray:
    """Candidate positions (m) of an unmodeled attachment: a grid over the span, clear of recorded ones."""
    length = campaign.cable.length
    grid = np.linspace(0.03, 0.97, n) * length
    taken = np.array([a.position for _, a in recorded_attachments(campaign, tests)])
    if taken.size:
        grid = grid[np.min(np.abs(grid[:, None] - taken[None, :]), axis=1) > CLEARANCE * length]
    return grid


def clear_position(campaign: Campaign, tests: Sequence[Test], x: float) -> float:
    """``x`` moved off any recorded attachment (the solver needs distinct nodes)."""
    length = campaign.cable.length
    x = float(np.clip(x, 2 * POSITION_MARGIN * length, (1 - 2 * POSITION_MARGIN) * length))
    for _, a in recorded_attachments(campaign, tests):
        if abs(x - a.position) < CLEARANCE * length / 2:
            x = a.position + math.copysign(CLEARANCE * length / 2, x - a.position if x != a.position else -1.0)
    return x


def build(campaign: Campaign, tests: Sequence[Test], effects: Sequence[str],
          positions: Mapping[str, float] | None = None, fixed: Sequence[str] = ()) -> Hypothesis:
    """The hypothesis ``effects`` for the measured ``tests``.

    Parameters
    ----------
    campaign : Campaign
        The nominal campaign.
    tests : sequence of Test
        The measured tests (a tension is one parameter per test).
    effects : sequence of str
        Names from :data:`EFFECTS`.
    positions : mapping, optional
        Position (m) of the unmodeled attachments, by effect; default a
        third of the span. They are added to the setups of ``tests`` only.
    fixed : sequence of str
        Unmodeled effects whose position is held at ``positions`` (the
        profile scan of :mod:`.fitting`): only their amplitude is free.
    """
    effects = tuple(e for e in EFFECTS if e in effects)
    positions = dict(positions or {})
    cable = campaign.cable
    augmented = campaign
    extra = [e for e in effects if e in UNMODELED]
    if extra:
        new = {e: Attachment(UNMODELED[e], clear_position(campaign, tests, positions.get(e, cable.length / 3)))
               for e in extra}
        if len(new) == 2 and abs(new[extra[0]].position - new[extra[1]].position) < CLEARANCE * cable.length / 2:
            a = new[extra[1]]
            new[extra[1]] = replace(a, position=clear_position(campaign, tests, a.position + CLEARANCE * cable.length))
        used = {t.setup for t in tests}
        setups = tuple(replace(s, attachments=(*s.attachments, *new.values())) if s.name in used else s
                       for s in campaign.setups)
        augmented = replace(campaign, setups=setups)
    params: list[Parameter] = []
    owners: list[str] = []
    standard = [e for e in effects if e in _SPEC]
    if standard:
        parsed = parse_parameters(campaign, tests, ",".join(_SPEC[e] for e in standard))
        for p in parsed:
            if p.index is not None and extra:  # the unmodeled attachments shift the indices
                name = campaign.setup(p.setup).attachments[p.index].name
                index = [a.name for a in augmented.setup(p.setup).attachments].index(name)
                p = replace(p, index=index)
            params.append(p)
            owners.append(next(e for e in standard if _SPEC[e] == p.kind))
    mean_tension = float(np.mean([t.tension for t in tests]))
    for e in extra:
        name = UNMODELED[e]
        slots = tuple((s.name, [a.name for a in s.attachments].index(name)) for s in augmented.setups
                      if s.name in used)
        x0 = next(a.position for a in augmented.setup(tests[0].setup).attachments if a.name == name)
        if e == "unmodeled_mass":
            params.append(Parameter("mass", name, 0.0, 1.0, 0.0, cable.mass_per_length * cable.length, slots=slots))
        else:
            params.append(Parameter("stiffness", name, 0.0, 1.0, 0.0, 100.0 * mean_tension / cable.length,
                                    slots=slots))
        owners.append(e)
        if e not in fixed:
            lo, hi = POSITION_MARGIN * cable.length / x0, (1 - POSITION_MARGIN) * cable.length / x0
            params.append(Parameter("position", name, x0, x0, lo, hi, slots=slots))
            owners.append(e)
    return Hypothesis(effects, augmented, tuple(params), tuple(owners))


def hypothesis_sets(effects: Sequence[str], max_effects: int = 2) -> list[tuple[str, ...]]:
    """The nominal model, every single effect and every pair (up to ``max_effects``)."""
    out: list[tuple[str, ...]] = [()]
    for k in range(1, max_effects + 1):
        out += list(itertools.combinations(effects, k))
    return out
