"""Model objects: cable, boundary, attachment, setup, test, campaign.

Frozen dataclasses in SI units (lengths in m, masses in kg, forces in N,
angles in radians), validated when built; an invalid value raises
:class:`~stcs_ident.core.errors.ModelError` naming the field. Units other than
SI appear only at the edges (campaign files give the inclination in
degrees; tables print kN).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from .boundary import Boundary
from .checks import (  # noqa: F401 (re-exported: the checks were defined here, and are imported from here)
    BANDS,
    FREQUENCY_BAND,
    MAX_MODE,
    checked_bounds,
    finite_number,
    frequency,
    in_band,
    mode_number,
    non_negative_number,
    positive_number,
    real_number,
)
from .errors import ModelError
from .planes import check_direction, check_plane

#: Most attachments in one setup. Every frequency evaluation solves the cable with a segment per attachment,
#: and its time grows steeply with their number (6 modes of an 8 m hanger: 5 ms with 20, 1 s with 50,
#: 94 s with 200): beyond this an identification or a diagnosis, hundreds of evaluations, would take hours.
MAX_ATTACHMENTS = 50


@dataclass(frozen=True)
class Cable:
    """A tensioned, shallow-sag cable with bending stiffness.

    Parameters
    ----------
    length : float
        Chord length l between anchorages A (x = 0) and B (x = l), m.
    mass_per_length : float
        m, kg/m.
    EI : float
        Bending stiffness, N m^2 (0 for a string).
    EA : float or None
        Axial stiffness, N; ``None`` ignores sag-extensibility.
    inclination : float
        Chord angle from horizontal, radians, |θ| <= π/2 (±π/2: a vertical cable, a hanger, without sag:
        :attr:`chord_cosine` is then exactly 0).
    gravity : float
        m/s^2.
    boundary_a, boundary_b : Boundary
        Rotational restraint at A and at B.
    """

    length: float
    mass_per_length: float
    EI: float
    EA: float | None = None
    inclination: float = 0.0
    gravity: float = 9.81
    boundary_a: Boundary = field(default_factory=Boundary.clamped)
    boundary_b: Boundary = field(default_factory=Boundary.clamped)

    def __post_init__(self):
        set_ = object.__setattr__
        for quantity, zero in (("length", False), ("mass_per_length", False), ("EI", True)):
            set_(self, quantity, in_band(getattr(self, quantity), f"cable.{quantity}", quantity, zero))
        if self.EA is not None:
            set_(self, "EA", in_band(self.EA, "cable.EA", "EA"))
        theta = finite_number(self.inclination, "cable.inclination")
        if abs(theta) > math.pi / 2:
            raise ModelError(f"must satisfy |inclination| <= 90 degrees, got {math.degrees(theta):g}",
                             field="cable.inclination")
        set_(self, "inclination", theta)
        set_(self, "gravity", in_band(self.gravity, "cable.gravity", "gravity", zero=True))
        for name in ("boundary_a", "boundary_b"):
            if not isinstance(getattr(self, name), Boundary):
                raise ModelError("must be a Boundary", field=f"cable.{name}")

    @property
    def chord_cosine(self) -> float:
        """cos θ, exactly 0 for a vertical cable: the one place the inclination's cosine is taken (cos(π/2) is
        6e-17 in floating point, which would give a vertical hanger a sag of 1e-17 of a horizontal one's and an
        in-plane share of a deck's vertical motion). Snapped below :data:`VERTICAL_COSINE`."""
        return chord_components(self.inclination)[0]

    @property
    def chord_sine(self) -> float:
        """sin θ, exactly ±1 for a vertical cable (:attr:`chord_cosine`)."""
        return chord_components(self.inclination)[1]

    @property
    def vertical(self) -> bool:
        """Whether the chord is vertical (|θ| = 90°, to :data:`VERTICAL_COSINE`): no sag, no sag-extensibility,
        the in-plane and out-of-plane families equal (bar the attachments' springs and dampers per plane)."""
        return self.chord_cosine == 0.0

    @property
    def weight_per_length(self) -> float:
        """w = m g cos θ, the weight per unit length normal to the chord (N/m); 0 for a vertical cable."""
        return self.mass_per_length * self.gravity * self.chord_cosine


#: |cos θ| below this is a vertical chord (cos θ = 0, sin θ = ±1 exactly). cos(π/2) = 6.1e-17; the nearest
#: inclination a campaign can mean that is not vertical, 89.9999 degrees, has cos θ = 1.7e-6.
VERTICAL_COSINE = 1e-12


def chord_components(inclination: float) -> tuple[float, float]:
    """(cos θ, sin θ) of a chord at ``inclination`` θ (radians), with a vertical chord exact: (0, ±1) when
    |cos θ| < :data:`VERTICAL_COSINE`. Everything that projects onto the chord or normal to it takes these."""
    c, s = math.cos(inclination), math.sin(inclination)
    if abs(c) < VERTICAL_COSINE:
        return 0.0, math.copysign(1.0, s)
    return c, s


def _check_point(obj, kind: str) -> str:
    """The checks an attachment and a damper share (name, position, mass, stiffness); returns the field prefix."""
    if not isinstance(obj.name, str) or not obj.name:
        raise ModelError("must be a non-empty string", field=f"{kind}.name")
    where = f"{kind}[{obj.name}]"
    object.__setattr__(obj, "position", positive_number(obj.position, f"{where}.position"))
    object.__setattr__(obj, "mass", in_band(obj.mass, f"{where}.mass", "mass", zero=True))
    object.__setattr__(obj, "stiffness", in_band(obj.stiffness, f"{where}.stiffness", "stiffness", zero=True))
    return where


@dataclass(frozen=True)
class Attachment:
    """A point mass and/or transverse spring clamped on the cable.

    Parameters
    ----------
    name : str
    position : float
        Distance from end A along the chord, m.
    mass : float
        kg.
    stiffness : float
        Transverse spring to ground in the cable's plane, N/m.
    stiffness_out : float or None
        The spring out of the cable's plane, N/m (keyword only); None: the same as ``stiffness``.
    """

    name: str
    position: float
    mass: float = 0.0
    stiffness: float = 0.0
    stiffness_out: float | None = field(default=None, kw_only=True)

    def __post_init__(self):
        where = _check_point(self, "attachment")
        if self.stiffness_out is not None:
            object.__setattr__(self, "stiffness_out", in_band(self.stiffness_out, f"{where}.stiffness_out",
                                                              "stiffness", zero=True))


@dataclass(frozen=True)
class Damper(Attachment):
    """A transverse damper from the cable to ground: a viscous dashpot, with an optional parallel spring and
    moving mass. At its point it adds the dynamic stiffness ``stiffness + s coefficient + s² mass`` for the
    complex eigenvalue s; with one, the modes are complex (frequency |s|/2π, damping ratio −Re(s)/|s|).

    A damper is an attachment (its spring and moving mass are one) with a dashpot: it sits among a setup's
    attachments, ordered by position, and everything that moves or weighs an attachment applies to it.

    Parameters
    ----------
    name : str
    position : float
        Distance from end A along the chord, m.
    mass : float
        Moving mass of the damper, kg.
    stiffness : float
        Spring in parallel with the dashpot, N/m.
    coefficient : float
        Dashpot, N s/m (> 0; keyword only).
    angle : float
        The damper's axis, radians from the cable's plane (keyword only; 0: in-plane). Its dashpot, spring
        and moving mass act cos²α in-plane and sin²α out-of-plane (:mod:`stcs_ident.core.planes`).
    """

    coefficient: float = field(default=0.0, kw_only=True)
    angle: float = field(default=0.0, kw_only=True)

    def __post_init__(self):
        where = _check_point(self, "damper")
        object.__setattr__(self, "coefficient", in_band(self.coefficient, f"{where}.coefficient", "coefficient"))
        angle = finite_number(self.angle, f"{where}.angle")
        if abs(angle) > math.pi:
            raise ModelError(f"must lie within ±180 degrees, got {math.degrees(angle):g}", field=f"{where}.angle")
        object.__setattr__(self, "angle", angle)
        if self.stiffness_out is not None:
            raise ModelError("a damper acts along its axis: give its angle, not a stiffness_out",
                             field=f"{where}.stiffness_out")


def _noun(a: Attachment) -> str:
    """``"damper"`` or ``"attachment"``: how fields and messages name it."""
    return "damper" if isinstance(a, Damper) else "attachment"


def has_dampers(attachments) -> bool:
    """Whether any of ``attachments`` is a :class:`Damper` (its modes are complex)."""
    return any(isinstance(a, Damper) for a in attachments)


@dataclass(frozen=True)
class Setup:
    """What is attached where: a named, position-ordered set of attachments."""

    name: str
    attachments: tuple[Attachment, ...] = ()

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ModelError("must be a non-empty string", field="setup.name")
        atts = tuple(self.attachments)
        if len(atts) > MAX_ATTACHMENTS:
            raise ModelError(f"has {len(atts)} attachments; at most {MAX_ATTACHMENTS} per setup (every frequency "
                             "evaluation solves a segment per attachment, and the time grows steeply with their "
                             "number: an identification would take hours)", field=f"setup[{self.name}].attachment")
        for a in atts:
            if not isinstance(a, Attachment):
                raise ModelError("must hold Attachment objects", field=f"setup[{self.name}].attachment")
        names = [a.name for a in atts]
        for a in atts:
            if names.count(a.name) > 1:
                raise ModelError(f"duplicate name {a.name!r} (attachments and dampers share the names of a setup)",
                                 field=f"setup[{self.name}].{_noun(a)}[{a.name}].name")
        atts = tuple(sorted(atts, key=lambda a: a.position))
        for a, b in itertools.pairwise(atts):
            if a.position == b.position:
                raise ModelError(
                    f"{_noun(a)} {a.name!r} and {_noun(b)} {b.name!r} are at the same position {a.position} m",
                    field=f"setup[{self.name}].{_noun(b)}[{b.name}].position",
                )
        object.__setattr__(self, "attachments", atts)

    def check_span(self, length: float) -> None:
        """Raise if an attachment is not strictly inside the span (0, length)."""
        for a in self.attachments:
            if not 0 < a.position < length:
                raise ModelError(
                    f"position {a.position} m is outside the span (0, {length}) m",
                    field=f"setup[{self.name}].{_noun(a)}[{a.name}].position",
                )


@dataclass(frozen=True)
class Test:
    """One tension level of one setup, with measured data.

    Parameters
    ----------
    name, setup : str
    tension : float
        Measured static tension H along the chord, N.
    frequencies : tuple of float or None
        Measured natural frequencies, Hz.
    modes : tuple of int or None
        Mode numbers of ``frequencies`` (default 1..N).
    record : str or None
        Path of an acceleration record, relative to the campaign directory.
    reference : tuple of (name, tuple of float)
        Frequencies (Hz) computed by others for the same modes (a paper's
        own model, say), shown beside ours; each list is ordered by
        ``modes``.
    channels : tuple of (name, float)
        The record's channel positions, m from end A, for a record whose
        file gives none (CSV); a mapping is accepted.
    uncertainty : tuple of float or None
        The stated standard uncertainty (1σ) of ``frequencies``, Hz: one
        value per frequency (one number is accepted and repeated). None:
        not stated (the identification then takes the rounding of the
        table, and says so).
    record_format : tuple of (key, value)
        How to read the record's file (``[test.record_format]``: unit,
        sampling_rate, separator, ...; io checks the keys and values); a
        mapping is accepted.
    planes : tuple of str or None
        The plane of each of ``frequencies``: ``"in"`` (in-plane, the
        default for all) or ``"out"`` (out-of-plane); mode numbers count
        per plane. None without frequencies.
    channel_directions : tuple of (name, direction)
        The record's channel directions (``"in"``, ``"out"``, ``"axial"`` or
        degrees: :mod:`stcs_ident.core.planes`), for a record whose file
        gives none; a mapping is accepted.
    """

    __test__ = False  # not a pytest class

    name: str
    setup: str
    tension: float
    frequencies: tuple[float, ...] | None = None
    modes: tuple[int, ...] | None = None
    record: str | None = None
    reference: tuple[tuple[str, tuple[float, ...]], ...] = ()
    channels: tuple[tuple[str, float], ...] = ()
    uncertainty: tuple[float, ...] | None = None
    record_format: tuple[tuple[str, Any], ...] = ()
    planes: tuple[str, ...] | None = None
    channel_directions: tuple[tuple[str, str | float], ...] = ()

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ModelError("must be a non-empty string", field="test.name")
        where = f"test[{self.name}]"
        if self.record is not None:
            object.__setattr__(self, "record", _path(self.record, f"{where}.record"))
        object.__setattr__(self, "record_format", _record_format(self.record_format, f"{where}.record_format"))
        object.__setattr__(self, "channel_directions", _directions(self.channel_directions,
                                                                   f"{where}.channels"))
        channels = tuple(dict(self.channels).items())
        for name, _ in channels:
            if not isinstance(name, str) or not name:
                raise ModelError(f"channel names must be non-empty strings, got {name!r}", field=f"{where}.channels")
        object.__setattr__(self, "channels", tuple(
            (name, finite_number(position, f"{where}.channels.{name}")) for name, position in channels))
        object.__setattr__(self, "tension", in_band(self.tension, f"{where}.tension", "tension"))
        if self.frequencies is not None:
            freqs = tuple(frequency(f, f"{where}.frequencies") for f in self.frequencies)
            if not freqs:
                raise ModelError("must not be empty", field=f"{where}.frequencies")
            object.__setattr__(self, "frequencies", freqs)
            modes = self.modes if self.modes is not None else tuple(range(1, len(freqs) + 1))
            modes = tuple(modes)
            if len(modes) != len(freqs):
                raise ModelError(
                    f"has {len(modes)} entries but frequencies has {len(freqs)}", field=f"{where}.modes"
                )
            for k in modes:
                mode_number(k, f"{where}.modes")
            planes = ("in",) * len(freqs) if self.planes is None else tuple(self.planes)
            if len(planes) != len(freqs):
                raise ModelError(f"has {len(planes)} entries but frequencies has {len(freqs)}",
                                 field=f"{where}.planes")
            planes = tuple(check_plane(p, f"{where}.planes") for p in planes)
            if len(set(zip(planes, modes))) != len(modes):
                raise ModelError("mode numbers must be distinct" + (" within each plane" if "out" in planes else ""),
                                 field=f"{where}.modes")
            object.__setattr__(self, "modes", modes)
            object.__setattr__(self, "planes", planes)
        elif self.modes is not None:
            raise ModelError("given without frequencies", field=f"{where}.modes")
        else:  # planes are those of frequencies (a copy of a test without its frequencies drops them)
            object.__setattr__(self, "planes", None)
        if self.uncertainty is not None:
            field_name = f"{where}.uncertainty"
            if self.frequencies is None:
                raise ModelError("needs the test's frequencies", field=field_name)
            given = self.uncertainty
            values = tuple(given) if isinstance(given, (tuple, list)) else (given,) * len(self.frequencies)
            if len(values) != len(self.frequencies):
                raise ModelError(f"has {len(values)} values but frequencies has {len(self.frequencies)} (give one "
                                 "number for all, or one per frequency)", field=field_name)
            checked = []
            for u, f in zip(values, self.frequencies):
                u = finite_number(u, field_name)
                if not 0 < u < f:
                    raise ModelError(f"must be > 0 Hz and below its frequency ({f:g} Hz), got {u!r}",
                                     field=field_name)
                checked.append(u)
            object.__setattr__(self, "uncertainty", tuple(checked))
        reference = tuple((str(k), tuple(v)) for k, v in self.reference)
        for label, values in reference:
            field_name = f"{where}.reference.{label}"
            if self.modes is None:
                raise ModelError("needs the test's frequencies and modes", field=field_name)
            if len(values) != len(self.modes):
                raise ModelError(f"has {len(values)} values but modes has {len(self.modes)}", field=field_name)
            for f in values:
                frequency(f, field_name)
        object.__setattr__(self, "reference", tuple((k, tuple(float(f) for f in v)) for k, v in reference))


@dataclass(frozen=True)
class Published:
    """A result published elsewhere for this campaign, to be shown beside ours.

    Parameters
    ----------
    parameter : str
        The identified quantity it compares with, as ``identify`` names it
        (``"EI_ratio"``, ``"tension_ratio"``).
    low, high : float
        The published value or range.
    basis : float or None
        The value the published ratio is relative to, when it is not this
        campaign's nominal (SI units).
    source : str
        Where it was published.
    """

    parameter: str
    low: float
    high: float
    basis: float | None = None
    source: str = ""

    def __post_init__(self):
        where = f"published[{self.parameter}]"
        if not isinstance(self.parameter, str) or not self.parameter:
            raise ModelError("must be a non-empty string", field="published.parameter")
        low = finite_number(self.low, f"{where}.low")
        high = finite_number(self.high, f"{where}.high")
        if high < low:
            raise ModelError(f"must be >= low ({low}), got {high}", field=f"{where}.high")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)
        if self.basis is not None:
            object.__setattr__(self, "basis", positive_number(self.basis, f"{where}.basis"))


@dataclass(frozen=True)
class Campaign:
    """One cable, its setups and its tests."""

    name: str
    cable: Cable
    setups: tuple[Setup, ...] = ()
    tests: tuple[Test, ...] = ()
    description: str = ""
    directory: str | None = None
    published: tuple[Published, ...] = ()
    #: Tolerances the campaign gives (``[tolerance]``): (key, value) pairs, sorted by key; a key not
    #: given takes its effect's default (:func:`stcs_ident.effects.tolerance`).
    tolerance: tuple[tuple[str, float], ...] = ()
    #: How to read the records of every test (top-level ``[record_format]``; a test's own keys win), and the
    #: channel positions of records whose files give none (top-level ``[channels]``; a test's own table wins).
    record_format: tuple[tuple[str, Any], ...] = ()
    channels: tuple[tuple[str, float], ...] = ()
    #: Default bounds of the identification's variables (``[bounds]``): (kind, (lower, upper)) pairs, sorted
    #: by kind, in the variable's units (a ratio to nominal; the kind's SI unit when the nominal value is 0;
    #: the fixity of an end). A kind not given keeps its registered bounds (:mod:`stcs_ident.core.kinds`).
    bounds: tuple[tuple[str, tuple[float, float]], ...] = ()
    #: The channel directions of records whose files give none (top-level ``[channels]``; a test's own wins).
    channel_directions: tuple[tuple[str, str | float], ...] = ()
    #: Frequencies of the structure the cable hangs from (deck, pylon: ``[structure] frequencies``), Hz: peaks at
    #: them or their harmonics in the records are structural, never numbered.
    structural_frequencies: tuple[float, ...] = ()

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ModelError("must be a non-empty string", field="campaign.name")
        object.__setattr__(self, "bounds", checked_bounds(self.bounds))
        object.__setattr__(self, "published", tuple(self.published))
        given = dict(self.tolerance)
        if len(given) != len(tuple(self.tolerance)):
            raise ModelError("a key is given twice", field="tolerance")
        for key, value in given.items():
            v = finite_number(value, f"tolerance.{key}")
            if v < 0:
                raise ModelError(f"must be >= 0, got {value!r}", field=f"tolerance.{key}")
            given[key] = v
        object.__setattr__(self, "tolerance", tuple(sorted(given.items())))
        object.__setattr__(self, "record_format", _record_format(self.record_format, "record_format"))
        object.__setattr__(self, "channels", tuple(
            (name, finite_number(position, f"channels.{name}")) for name, position in dict(self.channels).items()))
        object.__setattr__(self, "channel_directions", _directions(self.channel_directions, "channels"))
        object.__setattr__(self, "structural_frequencies", tuple(
            frequency(f, "structure.frequencies") for f in self.structural_frequencies))
        object.__setattr__(self, "setups", tuple(self.setups))
        object.__setattr__(self, "tests", tuple(self.tests))
        _unique((s.name for s in self.setups), "setup")
        _unique((t.name for t in self.tests), "test")
        for s in self.setups:
            s.check_span(self.cable.length)
        known = {s.name for s in self.setups}
        for t in self.tests:
            if t.setup not in known:
                raise ModelError(f"names unknown setup {t.setup!r}", field=f"test[{t.name}].setup")

    def setup(self, name: str) -> Setup:
        for s in self.setups:
            if s.name == name:
                return s
        raise KeyError(name)

    def test(self, name: str) -> Test:
        for t in self.tests:
            if t.name == name:
                return t
        raise KeyError(name)


def _path(value: Any, field: str) -> str:
    """A path as given (a non-empty string; a path-like is taken as its string) that the system can open: no
    NUL character (which ends a path at the system's interface: ``open`` and ``stat`` refuse it)."""
    import os

    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if not isinstance(value, str) or not value:
        raise ModelError(f"must be a non-empty string (a path), got {value!r}", field=field)
    if "\0" in value:
        raise ModelError(f"holds a NUL character, which no path can: {value!r}", field=field)
    return value


def _directions(value: Any, field: str) -> tuple[tuple[str, str | float], ...]:
    """Channel directions as (name, direction) pairs (:func:`~stcs_ident.core.planes.check_direction`)."""
    return tuple((str(name), check_direction(d, f"{field}.{name}.direction")) for name, d in dict(value).items())


def _record_format(value: Any, field: str) -> tuple[tuple[str, Any], ...]:
    """Reader options as (key, value) pairs, lists as tuples (the values are io's to check)."""
    pairs = tuple(dict(value).items())
    for key, _ in pairs:
        if not isinstance(key, str) or not key:
            raise ModelError(f"keys must be non-empty strings, got {key!r}", field=field)
    return tuple((key, tuple(v) if isinstance(v, list) else v) for key, v in pairs)


def _unique(names: Iterable[str], kind: str) -> None:
    seen = set()
    for n in names:
        if n in seen:
            raise ModelError(f"duplicate {kind} name {n!r}", field=f"{kind}[{n}].name")
        seen.add(n)
