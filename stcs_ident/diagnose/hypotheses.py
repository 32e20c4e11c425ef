"""Hypotheses: the nominal model extended by effects of the registry.

Each registered effect (:mod:`stcs_ident.effects`) becomes free parameters
of the identification step (:mod:`stcs_ident.core.parameters`), shared
across tests as the effect declares (a tension one per test, EI by all
tests, an attachment's position by the tests of its setup).

An unmodeled attachment (an effect whose ``unmodeled`` is true: a mass or a
support the model lacks) is a new attachment added to every setup (its
amplitude zero in the nominal model, so the nominal predictions are
unchanged), whose parameters carry one ``slot`` per setup.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from .. import effects as registry
from ..core.model import Attachment, Campaign, Test
from ..core.parameters import Parameter
from ..effects.base import POSITION_MARGIN

__all__ = ["CLEARANCE", "POSITION_MARGIN", "Hypothesis", "applicable", "build", "clear_position", "free_positions",
           "hypothesis_sets", "parse_effects", "recorded_attachments", "unmodeled_name"]

#: An unmodeled attachment keeps this fraction of the length from a recorded one.
CLEARANCE = 5e-3


def unmodeled_name(effect: str) -> str | None:
    """Name of the attachment an unmodeled effect adds (None for any other effect)."""
    e = registry.get(effect)
    return e.attachment_name if e.unmodeled else None


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
    """``"tension,unmodeled_mass"`` → effect names in vocabulary order; None → all registered.

    Raises
    ------
    InputError
        ``field="effects"`` for a name outside the vocabulary or none at all.
    """
    return registry.parse(spec)


def recorded_attachments(campaign: Campaign, tests: Sequence[Test]) -> list[tuple[str, Attachment]]:
    """(setup, attachment) of every recorded attachment in the setups of ``tests``."""
    setups = dict.fromkeys(t.setup for t in tests)
    return [(s, a) for s in setups for a in campaign.setup(s).attachments]


def applicable(campaign: Campaign, tests: Sequence[Test], effect: str) -> str | None:
    """Why ``effect`` cannot be a hypothesis for these tests (None when it can): the effect's own reason, or a
    tolerance of 0 (the campaign says the nominal value is known exactly)."""
    if registry.tolerance(campaign, effect) == 0:
        key = registry.get(effect).tolerance.key
        return f"{effect} is not considered: the campaign's [tolerance] {key} = 0 says the nominal value is exact"
    return registry.get(effect).applicable(campaign, tests)


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
        Names of registered effects.
    positions : mapping, optional
        Position (m) of the unmodeled attachments, by effect; default a
        third of the span. They are added to the setups of ``tests`` only.
    fixed : sequence of str
        Unmodeled effects whose position is held at ``positions`` (the
        profile scan of :mod:`.fitting`): only their amplitude is free.
    """
    effects = registry.in_order(effects)
    positions = dict(positions or {})
    cable = campaign.cable
    augmented = campaign
    extra = [e for e in effects if registry.get(e).unmodeled]
    used = {t.setup for t in tests}
    if extra:
        new = {e: registry.get(e).attachment(unmodeled_name(e),
                                             clear_position(campaign, tests, positions.get(e, cable.length / 3)))
               for e in extra}
        if len(new) == 2 and abs(new[extra[0]].position - new[extra[1]].position) < CLEARANCE * cable.length / 2:
            a = new[extra[1]]
            new[extra[1]] = replace(a, position=clear_position(campaign, tests, a.position + CLEARANCE * cable.length))
        setups = tuple(replace(s, attachments=(*s.attachments, *new.values())) if s.name in used else s
                       for s in campaign.setups)
        augmented = replace(campaign, setups=setups)
    params: list[Parameter] = []
    owners: list[str] = []
    for e in effects:
        if e in extra:
            continue
        for p in registry.get(e).free_parameters(campaign, tests):
            if p.index is not None and extra:  # the unmodeled attachments shift the indices
                name = campaign.setup(p.setup).attachments[p.index].name
                index = [a.name for a in augmented.setup(p.setup).attachments].index(name)
                p = replace(p, index=index)
            params.append(p)
            owners.append(e)
    for e in extra:
        effect = registry.get(e)
        name = effect.attachment_name
        slots = tuple((s.name, [a.name for a in s.attachments].index(name)) for s in augmented.setups
                      if s.name in used)
        x0 = next(a.position for a in augmented.setup(tests[0].setup).attachments if a.name == name)
        new_params = effect.unmodeled_parameters(campaign, tests, slots, x0, fixed=e in fixed)
        params += new_params
        owners += [e] * len(new_params)
    return Hypothesis(effects, augmented, tuple(params), tuple(owners))


def hypothesis_sets(effects: Sequence[str], max_effects: int = 2) -> list[tuple[str, ...]]:
    """The nominal model, every single effect and every pair (up to ``max_effects``), and, with pairs, the
    baseline (the source paper's correction of tension and EI) plus each further effect."""
    out: list[tuple[str, ...]] = [()]
    for k in range(1, max_effects + 1):
        out += list(itertools.combinations(effects, k))
    baseline = registry.baseline()
    if max_effects >= 2 and baseline and set(baseline) <= set(effects):
        out += [registry.in_order((*baseline, e)) for e in effects if e not in baseline]
    return out
