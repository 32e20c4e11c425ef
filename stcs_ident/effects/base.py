"""What an effect is: the base class every effect module fills in.

An *effect* is one way in which a real cable may differ from the model a
campaign describes (a tension a few per cent off, a weight clamped
elsewhere, a mass nobody wrote down). One effect is one small module of
this package, and everything else (the diagnosis's hypotheses, the
identification parameters it frees, the report's tables and sentences, the
simulator's hidden truth, the command line's options) loops over the
registry (:mod:`stcs_ident.effects.registry`) instead of naming effects.

An effect declares

- its ``name`` in the vocabulary, a one-line ``meaning`` and the reported
  ``quantities`` (JSON keys with units, and whether there is one value per
  test, per attachment or one for the cable);
- how it frees parameters of the identification (:meth:`Effect.free_parameters`:
  by default the :mod:`stcs_ident.core.parameters` kind ``parameter_kind``);
- through its kind, the ``tolerance`` of the nominal value it changes (how
  well a user usually knows it; :class:`stcs_ident.core.kinds.Kind`), or None;
- how it changes the true model of the simulator (:meth:`Effect.check_truth`,
  :meth:`Effect.apply_truth`, keyword ``truth_key`` of
  :class:`stcs_ident.simulate.effects.Effects`) and the ``simulate`` option
  that sets it;
- how its fitted values are reported (:meth:`Effect.record`) and said in
  plain words (:meth:`Effect.describe`).

A point attachment the model lacks (an unmodeled mass or support) is an
:class:`UnmodeledAttachment`: a new attachment added to every measured
setup, with an amplitude and a position whose profile the diagnosis scans.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import numpy as np

from ..core import kinds
from ..core.errors import InputError, ModelError
from ..core.formatting import plus_minus as pm  # the effects' words use the reports' ± format
from ..core.kinds import Tolerance
from ..core.model import Attachment, Cable, Campaign, Test
from ..core.parameters import POSITION_MARGIN, Parameter, parse_parameters


@dataclass(frozen=True)
class Quantity:
    """One reported quantity of an effect.

    Attributes
    ----------
    key : str
        Its key in the diagnosis JSON (``"ratio"``, ``"EI"``, ``"position"``).
    unit : str, optional
        SI unit (``""`` for a ratio); by default that of the parameter kind
        the key names (:func:`stcs_ident.core.kinds.unit`).
    per : {"test", "attachment", None}
        One value per test, per recorded attachment, or one value.
    """

    key: str
    unit: str | None = None
    per: str | None = None

    def __post_init__(self):
        if self.unit is None:
            unit = kinds.unit(self.key)
            if unit is None:
                raise ValueError(f"quantity {self.key!r} names no parameter kind: give its unit")
            object.__setattr__(self, "unit", unit)


@dataclass(frozen=True)
class Option:
    """The ``stcs-ident simulate`` option that hides an effect in the records."""

    flag: str
    metavar: str
    help: str
    repeatable: bool = False


@dataclass
class Truth:
    """The true configuration the simulator builds, effect by effect.

    ``origin`` maps an attachment's name to the ``effects.<key>`` field that
    put it where it is (an error then names that field).
    """

    cable: Cable
    attachments: list[Attachment]
    tension: float
    origin: dict[str, str] = field(default_factory=dict)
    #: The field blamed for a recorded attachment that falls outside the true span.
    span_field: str = "effects"


@dataclass(frozen=True)
class Context:
    """What :meth:`Effect.record` needs besides the parameter."""

    cable: Cable
    symmetric: bool


class Effect:
    """Base class of an effect (see the module docstring).

    Subclasses set the class attributes and override what differs; an
    instance is registered with :func:`stcs_ident.effects.registry.register`.
    """

    #: Name in the vocabulary (``diagnose --effects``, JSON ``effects``).
    name: ClassVar[str] = ""
    #: One line: what the effect means physically.
    meaning: ClassVar[str] = ""
    #: Reported quantities.
    quantities: ClassVar[tuple[Quantity, ...]] = ()
    #: How the parameters are shared ("one per test", "all tests", ...).
    shared_by: ClassVar[str] = "all tests"
    #: Part of the source paper's correction (tension and EI re-estimated), the gain's baseline.
    baseline: ClassVar[bool] = False
    #: Kind of identification parameter it frees (a name of :mod:`stcs_ident.core.kinds`).
    parameter_kind: ClassVar[str | None] = None
    #: True for an attachment the nominal model lacks (position scanned by the diagnosis).
    unmodeled: ClassVar[bool] = False
    #: Keyword of :class:`~stcs_ident.simulate.effects.Effects` that hides the effect.
    truth_key: ClassVar[str] = ""
    #: The ``simulate`` option that hides it (None: none).
    option: ClassVar[Option | None] = None
    #: Considered by the diagnosis when asked for by name even where :meth:`applicable` gives a reason
    #: (a reason why it is not considered by default).
    opt_in: ClassVar[bool] = False
    #: Left out without a note where :meth:`applicable` gives a reason and the effect was not asked for (a
    #: refinement of another effect that only some data can tell apart: a support acting in one plane).
    quiet: ClassVar[bool] = False

    def __repr__(self) -> str:
        return f"<effect {self.name}>"

    @property
    def tolerance(self) -> Tolerance | None:
        """Default tolerance of the nominal value the effect changes: that of its parameter kind (None:
        no kind, or nothing nominal the campaign can state a tolerance of)."""
        return kinds.get(self.parameter_kind).tolerance if self.parameter_kind else None

    # ---- identification and diagnosis --------------------------------------------------------

    def applicable(self, campaign: Campaign, tests: Sequence[Test]) -> str | None:
        """Why the effect cannot be a hypothesis for these tests (None when it can)."""
        return None

    def free_parameters(self, campaign: Campaign, tests: Sequence[Test]) -> list[Parameter]:
        """The identification parameters the effect frees for the measured ``tests``."""
        return list(parse_parameters(campaign, tests, self.parameter_kind))

    def prior_width(self, p: Parameter, tolerance: float | None) -> float | None:
        """Standard width of the Gaussian prior of ``p`` (variable units) that the tolerance of the
        nominal value gives, or None (no tolerance, or a relative one of a zero nominal value)."""
        if tolerance is None or self.tolerance is None:
            return None
        if self.tolerance.relative:
            return tolerance if p.is_ratio else None
        return tolerance / p.scale

    def record(self, p: Parameter, variable: float, sigma: float, value: float, value_sigma: float | None,
               values: dict, sigmas: dict, context: Context) -> None:
        """Put one fitted parameter into ``values`` and ``sigmas`` (this effect's entries, JSON units).

        ``variable``/``sigma`` are the optimiser's variable and its standard
        deviation, ``value``/``value_sigma`` the same in SI units. The default
        reports the SI value under the first quantity's key (by member when
        the quantity is per test or attachment).
        """
        quantity = self.quantities[0]
        if quantity.per is None:
            values[quantity.key], sigmas[quantity.key] = value, value_sigma
        else:
            values.setdefault(quantity.key, {})[p.member] = value
            sigmas.setdefault(quantity.key, {})[p.member] = value_sigma

    def describe(self, values: Mapping, sigmas: Mapping, cable: Cable) -> str:
        """The fitted effect in plain words, with values and uncertainties."""
        shown = ", ".join(f"{k} = {v}" for k, v in values.items())
        return f"{self.name} ({shown})"

    # ---- simulation -----------------------------------------------------------------------------

    def check_truth(self, value: Any, field: str) -> Any:
        """``value`` of :class:`~stcs_ident.simulate.effects.Effects` checked and normalised
        (hashable); raises ModelError naming ``field``."""
        raise NotImplementedError

    def apply_truth(self, truth: Truth, value: Any) -> None:
        """Change the true configuration ``truth`` in place."""
        raise NotImplementedError

    def truth_json(self, value: Any) -> Any:
        """``value`` as plain JSON data (truth.json)."""
        return value

    def parse_option(self, given: Any) -> Any:
        """The value of the ``simulate`` option as given on the command line (a string, or a list
        of strings for a repeatable option); raises InputError naming the option."""
        return number(given, self.option.flag, error=InputError)


class UnmodeledAttachment(Effect):
    """A point attachment the nominal model lacks: an amplitude and a position.

    The nominal campaign gets a zero-amplitude attachment named
    ``attachment_name`` in every measured setup (so its predictions are
    unchanged); the amplitude (``amount_kind``: ``"mass"`` or
    ``"stiffness"``) and the position are one parameter each, with a slot per
    setup.
    """

    unmodeled = True
    shared_by = "all tests (one attachment added to every measured setup)"
    #: Name of the added attachment.
    attachment_name: ClassVar[str] = ""
    #: The amplitude's parameter kind and Attachment field (``"mass"``, ``"stiffness"``, ``"coefficient"``).
    amount_kind: ClassVar[str] = "mass"
    #: Words for the thing (``"mass"``, ``"support"``).
    noun: ClassVar[str] = ""

    @property
    def amount_unit(self) -> str:
        """The amplitude's SI unit: that of its parameter kind."""
        return kinds.get(self.amount_kind).unit

    def amount_upper(self, campaign: Campaign, tests: Sequence[Test]) -> float:
        """Upper bound of the amplitude (SI)."""
        raise NotImplementedError

    def amount_starts(self, campaign: Campaign, tests: Sequence[Test], position: float) -> tuple[float, ...]:
        """Amplitudes (SI) from which the diagnosis's profile scan also starts at ``position``, beside the
        value carried over from the previous position; none by default (an amplitude whose effect grows
        monotonically needs no other)."""
        return ()

    def attachment(self, name: str, position: float, amount: float = 0.0) -> Attachment:
        """The attachment the effect adds (the diagnosis's at amplitude 0, the simulator's at ``amount``): a
        point with ``amount`` as its ``amount_kind`` (none at 0: an amplitude the point cannot hold, a dashpot, is
        the fit's override), acting in both planes."""
        return Attachment(name, position, **({self.amount_kind: amount} if amount else {}))

    def unmodeled_parameters(self, campaign: Campaign, tests: Sequence[Test], slots: tuple[tuple[str, int], ...],
                             x0: float, fixed: bool) -> list[Parameter]:
        """The amplitude (and, unless ``fixed``, the position) of the added attachment."""
        cable = campaign.cable
        name = self.attachment_name
        params = [Parameter(self.amount_kind, name, 0.0, 1.0, 0.0, self.amount_upper(campaign, tests), slots=slots)]
        if not fixed:
            lo, hi = POSITION_MARGIN * cable.length / x0, (1 - POSITION_MARGIN) * cable.length / x0
            params.append(Parameter("position", name, x0, x0, lo, hi, slots=slots))
        return params

    def record(self, p, variable, sigma, value, value_sigma, values, sigmas, context):
        if p.kind == "position" and context.symmetric and value > context.cable.length / 2:
            value = context.cable.length - value
        values[p.kind], sigmas[p.kind] = value, value_sigma

    def describe(self, values, sigmas, cable):
        amount = pm(values[self.amount_kind], sigmas.get(self.amount_kind), self.amount_unit)
        return f"an unmodeled {self.noun} of {amount} near {pm(values['position'], sigmas.get('position'), 'm')}"

    def check_truth(self, value, field):
        if value is None:
            return None
        try:
            amount, position = value
        except (TypeError, ValueError):
            raise ModelError(f"must be a pair ({self.amount_kind}, position)", field=field) from None
        amount, position = number(amount, field), number(position, field)
        if not (math.isfinite(amount) and amount >= 0 and math.isfinite(position)):
            raise ModelError(f"needs a finite {self.amount_kind} >= 0 and a finite position, got {value!r}",
                             field=field)
        return amount, position

    def apply_truth(self, truth, value):
        amount, position = value
        name = f"({self.truth_key.replace('_', ' ')})"
        truth.attachments.append(self.attachment(name, position, amount))
        truth.origin[name] = f"effects.{self.truth_key}"

    def truth_json(self, value):
        return {self.amount_kind: value[0], "position": value[1]}

    def parse_option(self, given):
        amount, position = at_pair(given, self.option.flag)
        return number(amount, self.option.flag, error=InputError), position


class RecordedAttachment(Effect):
    """A recorded attachment's value differs from the record: one value per attachment (``attribute``:
    ``"position"`` or ``"mass"``), shared by the tests of its setup; the simulator's truth maps attachment
    names to true values, set by a repeatable ``NAME@VALUE`` option."""

    shared_by = "the tests of its setup"
    #: The Attachment field the effect changes.
    attribute: ClassVar[str] = ""
    #: Whether a true value must be > 0 (a position) or may be 0 (a mass).
    positive: ClassVar[bool] = False

    def applicable(self, campaign, tests):
        setups = list(dict.fromkeys(t.setup for t in tests))
        if any(campaign.setup(s).attachments for s in setups):
            return None
        return (f"{self.name} needs a recorded attachment in the setup of a measured test, and the measured "
                f"tests' setups ({', '.join(setups)}) have none")

    def check_truth(self, value, field):
        return named_values(value, field, positive=self.positive)

    def apply_truth(self, truth, value):
        set_attachments(truth, value, self.attribute, self.truth_key)

    def truth_json(self, value):
        return dict(value)

    def parse_option(self, given):
        return dict(at_pair(item, self.option.flag) for item in given)


# ---- small helpers shared by the effect modules --------------------------------------------------

def number(value: Any, field: str, error: type[Exception] = ModelError) -> float:
    """``value`` as a float that is not NaN (a bool is not a number)."""
    if isinstance(value, bool):
        raise error(f"must be a number, got {value!r}", field=field)
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise error(f"must be a number, got {value!r}", field=field) from None
    if math.isnan(v):
        raise error("must not be NaN", field=field)
    return v


def positive_ratio(value: Any, field: str) -> float | None:
    """A ratio > 0 (None stays None)."""
    if value is None:
        return None
    v = number(value, field)
    if v <= 0:
        raise ModelError(f"must be > 0, got {value!r}", field=field)
    return v


def named_values(value: Any, field: str, positive: bool) -> tuple[tuple[str, float], ...]:
    """A mapping or pairs (attachment name, value) as a sorted tuple of pairs."""
    try:
        items = [(k, v) for k, v in (value.items() if isinstance(value, Mapping) else value)]
    except (TypeError, ValueError):
        raise ModelError("must map attachment names to values", field=field) from None
    out: dict[str, float] = {}
    for key, v in items:
        where = f"{field}[{key}]"
        v = number(v, where)
        if not math.isfinite(v) or v < 0 or (positive and v == 0):
            raise ModelError(f"must be finite and {'> 0' if positive else '>= 0'}, got {v!r}", field=where)
        if key in out:
            raise ModelError("given twice", field=where)
        out[str(key)] = v
    return tuple(sorted(out.items()))


def set_attachments(truth: Truth, values: Sequence[tuple[str, float]], attribute: str, key: str) -> None:
    """Set ``attribute`` of the named attachments of ``truth`` (an unknown name is refused)."""
    by_name = {a.name: i for i, a in enumerate(truth.attachments)}
    for name, value in values:
        where = f"effects.{key}[{name}]"
        if name not in by_name:
            raise ModelError(f"names no attachment of this setup (known: {sorted(by_name)})", field=where)
        i = by_name[name]
        truth.attachments[i] = replace(truth.attachments[i], **{attribute: value})
        if attribute == "position":
            truth.origin[name] = where


def at_pair(text: Any, option: str) -> tuple[str, float]:
    """``"20@8.3"`` → ``("20", 8.3)`` (the part after @ a number)."""
    try:
        a, b = str(text).split("@")
        x = float(b)
    except ValueError:
        raise InputError(f"expected VALUE@VALUE, got {text!r}", field=option) from None
    if not math.isfinite(x):
        raise InputError(f"the position must be finite, got {b!r}", field=option)
    return a, x


def scaled(sigma: float | None, factor: float) -> float | None:
    """``sigma / factor`` (None stays None)."""
    return None if sigma is None else sigma / factor


def mean_tension(tests: Sequence[Test]) -> float:
    """Mean stated tension of ``tests`` (N)."""
    return float(np.mean([t.tension for t in tests]))
