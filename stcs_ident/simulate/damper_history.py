"""A damper's coefficient along a simulated archive: the temperature's pull and the damper's failures.

A viscous damper's dashpot coefficient at a record's time t and air temperature θ is

    c(t, θ) = c_ref · exp(−a (θ − θ_ref)) · Π_i g_i(t)

- c_ref, the coefficient the campaign records (at θ_ref, the archive's mean
  temperature);
- a, the damper's temperature coefficient (per °C): the dashpot's force is
  that of silicone oil sheared through a gap or an orifice, proportional to
  the oil's viscosity, and a polydimethylsiloxane oil's viscosity falls to
  about 0.4 of itself from 38 °C to 99 °C (its viscosity–temperature
  coefficient, 1 − η(99 °C)/η(38 °C) ≈ 0.6): a = ln(1/0.4)/61 ≈ 0.015 per °C
  (:data:`DAMPER_TEMPERATURE_COEFFICIENT`), so the daily ±6 °C moves the
  coefficient by about ±9 %; viscous dampers stiffen in the cold;
- g_i(t), one factor per :class:`DamperChange` of that damper (1 before its
  time):

  ``leak``
      a leaking damper (lost oil, a worn seal): g = 1 − f from the time on;
  ``loss``
      a slow loss: g falls linearly from 1 at the time to 1 − f after
      ``days`` and stays there;
  ``seizure``
      the damper seizes (corroded rod, blocked orifice, gelled oil) and the
      node it holds nearly stops: g = :data:`SEIZURE_FACTOR` (20) from the time
      on. A damper sized near or below the optimum of the first modes
      (κ_n = π n x_d c / (l √(H m)) of 0.3 to 1) then sits far past every
      mode's optimum (κ of 6 to 20 and more), where the damping it adds
      falls as 1/κ and the frequencies rise towards those of the span with
      the damper's node pinned (by up to x_d/l): on campaigns/damped-stay
      (κ₁ = 0.48) the dashpot's share of mode 1's damping ratio falls from
      0.88 % to 0.27 %, mode 3's from 1.2 % to 0.09 %, and f₁ rises 2.0 %.

Several changes of one damper multiply.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime

from ..core.errors import ModelError
from ..core.model import Attachment, Damper, real_number

__all__ = ["DAMPER_CHANGE_KINDS", "DAMPER_TEMPERATURE_COEFFICIENT", "SEIZURE_FACTOR", "DamperChange",
           "check_damper_changes", "damper_coefficients", "utc_time"]

#: Per °C: a silicone-oil damper's relative change of coefficient per degree, with the sign of a stiffening in
#: the cold (the module docstring gives its source).
DAMPER_TEMPERATURE_COEFFICIENT = 0.015
#: How much a seized damper's coefficient grows (the module docstring says why 20).
SEIZURE_FACTOR = 20.0
#: The kinds of :class:`DamperChange`.
DAMPER_CHANGE_KINDS = ("leak", "loss", "seizure")
_DAY = 86400.0


@dataclass(frozen=True)
class DamperChange:
    """A change of one cable's damper(s) from a time on (see the module docstring for the models).

    Parameters
    ----------
    cable : str
        The archive's cable; its setup must hold a damper.
    kind : str
        ``"leak"``, ``"loss"`` or ``"seizure"``.
    time : str
        ISO 8601 (UTC if no offset is given): when the change starts.
    fraction : float or None
        The share of the coefficient lost (0 < fraction < 1): at once (leak), or after ``days`` (loss). A
        seizure takes none (its coefficient grows :data:`SEIZURE_FACTOR`-fold).
    days : float or None
        A loss's duration, days (> 0); only for a loss.
    damper : str or None
        The damper's name; None: every damper of the cable.
    """

    cable: str
    kind: str
    time: str
    fraction: float | None = None
    days: float | None = None
    damper: str | None = None

    def __post_init__(self):
        if not isinstance(self.cable, str) or not self.cable:
            raise ModelError(f"must be a cable's name, got {self.cable!r}", field="damper_change.cable")
        if self.kind not in DAMPER_CHANGE_KINDS:
            raise ModelError(f"must be one of {', '.join(DAMPER_CHANGE_KINDS)}, got {self.kind!r}",
                             field="damper_change.kind")
        object.__setattr__(self, "time", utc_time(self.time, "damper_change.time").isoformat())
        if self.kind == "seizure":
            if self.fraction is not None:
                raise ModelError(f"a seizure multiplies the coefficient by {SEIZURE_FACTOR:g} and takes no fraction, "
                                 f"got {self.fraction!r}", field="damper_change.fraction")
        else:
            if self.fraction is None:
                raise ModelError(f"a {self.kind} needs the share of the coefficient lost (0 < fraction < 1)",
                                 field="damper_change.fraction")
            fraction = real_number(self.fraction, "damper_change.fraction")
            if not 0 < fraction < 1:
                raise ModelError(f"must lie between 0 and 1 (the share of the coefficient lost), got {fraction!r}",
                                 field="damper_change.fraction")
            object.__setattr__(self, "fraction", fraction)
        if self.kind == "loss":
            if self.days is None:
                raise ModelError("a loss needs its duration in days (> 0)", field="damper_change.days")
            object.__setattr__(self, "days", real_number(self.days, "damper_change.days", positive=True))
        elif self.days is not None:
            raise ModelError(f"only a loss has a duration; a {self.kind} is at once, got {self.days!r}",
                             field="damper_change.days")
        if self.damper is not None and (not isinstance(self.damper, str) or not self.damper):
            raise ModelError(f"must be a damper's name or None, got {self.damper!r}", field="damper_change.damper")

    def factor(self, time: datetime) -> float:
        """g(t): the change's factor on the coefficient at ``time`` (an aware datetime)."""
        elapsed = (time - datetime.fromisoformat(self.time)).total_seconds()
        if elapsed < 0:
            return 1.0
        if self.kind == "seizure":
            return SEIZURE_FACTOR
        if self.kind == "leak":
            return 1.0 - self.fraction
        return 1.0 - self.fraction * min(1.0, elapsed / (self.days * _DAY))

    def applies_to(self, cable: str, damper: str) -> bool:
        return self.cable == cable and (self.damper is None or self.damper == damper)


def check_damper_changes(changes: Sequence[DamperChange], setups: Mapping[str, Sequence[Attachment]]) -> tuple:
    """``changes`` as a tuple, each naming a cable of ``setups`` (cable → its attachments) that has a damper,
    and, if it names one, a damper of that cable; ModelError naming the field otherwise."""
    changes = tuple(changes)
    for change in changes:
        if not isinstance(change, DamperChange):
            raise ModelError(f"must be a DamperChange, got {type(change).__name__}", field="damper_change")
        if change.cable not in setups:
            raise ModelError(f"no cable named {change.cable!r} (cables: {', '.join(setups)})",
                             field="damper_change.cable")
        names = [a.name for a in setups[change.cable] if isinstance(a, Damper)]
        if not names:
            raise ModelError(f"cable {change.cable!r} has no damper in its setup", field="damper_change.cable")
        if change.damper is not None and change.damper not in names:
            raise ModelError(f"cable {change.cable!r} has no damper named {change.damper!r} (its dampers: "
                             f"{', '.join(names)})", field="damper_change.damper")
    return changes


def damper_coefficients(cable: str, attachments: Sequence[Attachment], time: datetime, temperature: float, *,
                        temperature_coefficient: float, reference_temperature: float,
                        changes: Sequence[DamperChange] = ()) -> dict[str, float]:
    """c(t, θ) of every damper among ``attachments`` (name → N s/m), by the module docstring's law."""
    pull = math.exp(-temperature_coefficient * (temperature - reference_temperature))
    out = {}
    for a in attachments:
        if isinstance(a, Damper):
            c = a.coefficient * pull
            for change in changes:
                if change.applies_to(cable, a.name):
                    c *= change.factor(time)
            out[a.name] = c
    return out


def utc_time(text, field: str) -> datetime:
    """``text`` (ISO 8601) as an aware datetime, UTC when it gives no offset; ModelError naming ``field``."""
    try:
        time = datetime.fromisoformat(str(text))
    except ValueError:
        raise ModelError(f"is not an ISO 8601 time: {text!r}", field=field) from None
    return time.replace(tzinfo=UTC) if time.tzinfo is None else time
