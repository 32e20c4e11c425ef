"""What a cable on a bridge records besides its own in-plane response, as validated data (all off by default).

:class:`BridgeConditions` groups it, given as ``bridge=`` to
:func:`~stcs_ident.simulate.simulate.simulate_record` (and
:func:`~stcs_ident.simulate.simulate_campaign.simulate_campaign`):

- ``out_of_plane_ratio``: the rms of the out-of-plane ambient pressure, relative to the in-plane one (each
  plane gets its own, independent pressure);
- ``misalignment``: per channel, degrees by which the sensor's true axis is turned from the direction its
  record states (towards out-of-plane for a transverse channel, towards in-plane for an axial one);
- ``anchorage_motion``: :class:`StructuralMode` s, the deck's and the pylon's modes moving an anchorage;
- ``traffic``: :class:`Traffic`, vehicles crossing: bursts that swell the deck motion and add broadband
  motion while they last.

How the cable answers is :mod:`~stcs_ident.simulate.anchorage`'s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.errors import ModelError
from ..core.model import real_number

__all__ = ["ENDS", "BridgeConditions", "StructuralMode", "Traffic"]

#: The cable's ends: A at x = 0, B at x = l.
ENDS = ("A", "B")


@dataclass(frozen=True)
class StructuralMode:
    """A mode of the deck or a pylon that moves one anchorage of the cable.

    The anchorage's acceleration is a narrow-band Gaussian process: white noise through a lightly damped
    SDOF band-pass 2iζω_sω / (ω_s² − ω² + 2iζω_sω) (unit gain at ω_s), scaled to the rms ``amplitude``.

    Parameters
    ----------
    frequency : float
        Hz, the structure's natural frequency f_s.
    amplitude : float
        m/s², expected rms of the anchorage's acceleration along ``direction`` (harmonics not counted).
    damping : float
        0 < ζ < 1 of the structure's mode (the band's relative half-width).
    end : "A" or "B"
        The anchorage that moves: A at x = 0, B at x = l.
    direction : (in, out, axial)
        Components of the motion: in-plane transverse, out-of-plane transverse, along the chord; normalised
        to unit length (a deck's vertical motion at an inclined cable's anchorage is mostly in-plane with an
        axial part: (cos θ, 0, sin θ), θ the cable's inclination).
    harmonics : sequence of float
        rms of the 2nd, 3rd, ... harmonics relative to the fundamental (a structure's nonlinearity):
        harmonic h is r_h A(t) cos(h θ(t)), A e^{iθ} the fundamental's analytic signal. Harmonics at or
        above the Nyquist frequency are skipped.
    """

    frequency: float
    amplitude: float
    damping: float = 0.01
    end: str = "B"
    direction: tuple[float, float, float] = (1.0, 0.0, 0.0)
    harmonics: tuple[float, ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "frequency", real_number(self.frequency, "structural_mode.frequency",
                                                          positive=True))
        object.__setattr__(self, "amplitude", real_number(self.amplitude, "structural_mode.amplitude",
                                                          nonnegative=True))
        object.__setattr__(self, "damping", _ratio(self.damping, "structural_mode.damping"))
        object.__setattr__(self, "end", _end(self.end, "structural_mode.end"))
        object.__setattr__(self, "direction", _unit(self.direction, "structural_mode.direction"))
        object.__setattr__(self, "harmonics", tuple(
            real_number(h, "structural_mode.harmonics", nonnegative=True) for h in _sequence(
                self.harmonics, "structural_mode.harmonics")))

    def to_dict(self) -> dict:
        return {"frequency": self.frequency, "amplitude": self.amplitude, "damping": self.damping,
                "end": self.end, "direction": list(self.direction), "harmonics": list(self.harmonics)}


@dataclass(frozen=True)
class Traffic:
    """Vehicles crossing the bridge: non-stationary bursts.

    Crossings start at Poisson arrival times (``rate_per_hour``; from ``duration_s`` before the record, so a
    record may open in one). Each has the envelope e(t) = sin²(π (t − t_i) / D) over its duration D; while
    it lasts the deck's motion (every :class:`StructuralMode`) is multiplied by 1 + ``amplitude`` · Σ e_i(t),
    and the anchorage ``end`` gets broadband motion: white acceleration (to the Nyquist frequency) of rms
    ``broadband`` · Σ e_i(t) m/s² along ``direction``.

    Parameters
    ----------
    rate_per_hour : float
        > 0, mean number of crossings per hour.
    duration_s : float
        > 0, s, of one crossing.
    amplitude : float
        >= 0, how much a crossing swells the deck motion at its peak (2: three times the motion).
    broadband : float
        >= 0, m/s², rms of the broadband anchorage acceleration at a crossing's peak.
    end, direction :
        Of the broadband motion, as for :class:`StructuralMode`.
    """

    rate_per_hour: float
    duration_s: float = 8.0
    amplitude: float = 2.0
    broadband: float = 0.0
    end: str = "B"
    direction: tuple[float, float, float] = (1.0, 0.0, 0.0)

    def __post_init__(self):
        object.__setattr__(self, "rate_per_hour", real_number(self.rate_per_hour, "traffic.rate_per_hour",
                                                              positive=True))
        object.__setattr__(self, "duration_s", real_number(self.duration_s, "traffic.duration_s", positive=True))
        for name in ("amplitude", "broadband"):
            object.__setattr__(self, name, real_number(getattr(self, name), f"traffic.{name}", nonnegative=True))
        object.__setattr__(self, "end", _end(self.end, "traffic.end"))
        object.__setattr__(self, "direction", _unit(self.direction, "traffic.direction"))

    def to_dict(self) -> dict:
        return {"rate_per_hour": self.rate_per_hour, "duration_s": self.duration_s, "amplitude": self.amplitude,
                "broadband": self.broadband, "end": self.end, "direction": list(self.direction)}


@dataclass(frozen=True)
class BridgeConditions:
    """A cable on a bridge: both planes loaded, sensors misaligned, anchorages moving, traffic; all off.

    ``BridgeConditions()`` adds nothing: the record of in-plane channels is the one simulated without it.

    Parameters
    ----------
    out_of_plane_ratio : float
        >= 0: the out-of-plane ambient pressure's rms over the in-plane one's (1: the same loading; the two
        pressures are independent). Acts only where a channel reads out-of-plane motion.
    misalignment : float, sequence of float or None
        Degrees, one for all channels or one per channel: the sensor's true axis is turned by this much from
        the direction the record states. A transverse channel stated at β reads the transverse motion at
        β + δ, cos(β+δ)·in + sin(β+δ)·out (a channel said "in" leaks tan δ of the out-of-plane motion
        relative to its in-plane reading); an axial channel reads cos δ·axial + sin δ·in.
    anchorage_motion : sequence of StructuralMode
        The deck's and pylons' modes moving the anchorages.
    traffic : Traffic or None
        Crossing vehicles.
    """

    out_of_plane_ratio: float = 1.0
    misalignment: float | tuple[float, ...] | None = None
    anchorage_motion: tuple[StructuralMode, ...] = ()
    traffic: Traffic | None = None

    def __post_init__(self):
        object.__setattr__(self, "out_of_plane_ratio", real_number(self.out_of_plane_ratio,
                                                                   "bridge.out_of_plane_ratio", nonnegative=True))
        if self.misalignment is not None:
            if np.ndim(self.misalignment) == 0:
                value = real_number(self.misalignment, "bridge.misalignment")
            else:
                value = tuple(real_number(v, "bridge.misalignment")
                              for v in _sequence(self.misalignment, "bridge.misalignment"))
            object.__setattr__(self, "misalignment", value)
        modes = tuple(_sequence(self.anchorage_motion, "bridge.anchorage_motion"))
        for m in modes:
            if not isinstance(m, StructuralMode):
                raise ModelError(f"must hold StructuralMode objects, got {type(m).__name__}",
                                 field="bridge.anchorage_motion")
        object.__setattr__(self, "anchorage_motion", modes)
        if self.traffic is not None and not isinstance(self.traffic, Traffic):
            raise ModelError(f"must be a Traffic or None, got {type(self.traffic).__name__}", field="bridge.traffic")

    @property
    def moves_anchorages(self) -> bool:
        """Whether an anchorage moves (a structural mode, or traffic with broadband motion)."""
        return bool(self.anchorage_motion) or (self.traffic is not None and self.traffic.broadband > 0)

    def misalignment_per_channel(self, n_channels: int) -> np.ndarray:
        """Degrees, one per channel (zeros without misalignment)."""
        if self.misalignment is None:
            return np.zeros(n_channels)
        if isinstance(self.misalignment, float):
            return np.full(n_channels, self.misalignment)
        if len(self.misalignment) != n_channels:
            raise ModelError(f"gives {len(self.misalignment)} values for {n_channels} channels",
                             field="bridge.misalignment")
        return np.asarray(self.misalignment, float)

    def to_dict(self) -> dict:
        """JSON-ready: the parts that are on."""
        out: dict = {"out_of_plane_ratio": self.out_of_plane_ratio}
        if self.misalignment is not None:
            out["misalignment"] = (self.misalignment if isinstance(self.misalignment, float)
                                   else list(self.misalignment))
        if self.anchorage_motion:
            out["anchorage_motion"] = [m.to_dict() for m in self.anchorage_motion]
        if self.traffic is not None:
            out["traffic"] = self.traffic.to_dict()
        return out


def _ratio(value, name: str) -> float:
    value = real_number(value, name, positive=True)
    if value >= 1:
        raise ModelError(f"must satisfy 0 < damping < 1, got {value!r}", field=name)
    return value


def _end(value, name: str) -> str:
    if isinstance(value, str) and value.strip().upper() in ENDS:
        return value.strip().upper()
    raise ModelError(f'must be "A" (x = 0) or "B" (x = l), got {value!r}', field=name)


def _sequence(value, name: str) -> tuple:
    if isinstance(value, str | bytes) or not hasattr(value, "__iter__"):
        raise ModelError(f"must be a sequence, got {value!r}", field=name)
    return tuple(value)


def _unit(value, name: str) -> tuple[float, float, float]:
    parts = _sequence(value, name)
    if len(parts) != 3:
        raise ModelError(f"must give 3 components (in-plane, out-of-plane, axial), got {len(parts)}", field=name)
    v = [real_number(p, name) for p in parts]
    norm = math.sqrt(sum(p * p for p in v))
    if norm == 0:
        raise ModelError("must not be zero: give the (in, out, axial) components of the motion", field=name)
    return tuple(p / norm for p in v)
