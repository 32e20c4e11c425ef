"""Checks every acceleration record passes, whatever its source.

HDF5 (:mod:`~stcs_ident.io.records.hdf5`), CSV
(:mod:`~stcs_ident.io.records.csv_text`) and SEP005
(:mod:`~stcs_ident.io.records.sep005`) each read their own input, then hand
its parts to :func:`validated_record`, which checks them, converts to m/s²
and drops dead and clipped channels (:mod:`~stcs_ident.io.records.screening`).
The result is a :class:`~stcs_ident.core.record.Record`.
:func:`check_positions` and :func:`check_duration` check a record against
the cable it was measured on.

Errors
------
Every problem raises :class:`~stcs_ident.core.errors.InputError` whose text is
one line, ``"<file>: field '<field>': <what is wrong>"``. The fields are
those of the file: ``format``, ``version``, ``sampling_rate``, ``unit``,
``start_time``, ``acceleration``, ``channel_name``, ``channel_position``, ``channel_direction``
(and ``time`` for CSV). A file that is missing, unreadable or not HDF5 or
CSV has no field. Non-finite samples are refused, naming the channel and
its first bad sample (0-based index).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from ...core.errors import InputError
from ...core.record import (
    STANDARD_GRAVITY,
    Record,
    check_directions,
    check_finite,
    check_names,
    check_position_values,
    check_shape,
    sampling_rate,
)
from ...core.times import check_instant
from .screening import screen_channels

__all__ = [
    "TIME_TOLERANCE",
    "UNITS",
    "Positions",
    "UnknownPositions",
    "check_bandwidth",
    "check_duration",
    "check_positions",
    "check_sampling_rate",
    "names_from_positions",
    "one_line",
    "overridden",
    "position_list",
    "positions_by_name",
    "rate_from_time",
    "unit_scale",
    "validated_record",
]

#: Units a record may be in, as data loggers spell them, with their factor to m/s²: the one table of every
#: reader (HDF5's ``unit``, SEP005's ``unit_str``, the CSV reader's ``unit``).
UNITS = {
    "m/s^2": 1.0, "m/s²": 1.0, "m/s2": 1.0, "m s^-2": 1.0, "m s-2": 1.0,
    "mm/s^2": 1e-3, "mm/s²": 1e-3, "mm/s2": 1e-3,
    "g": STANDARD_GRAVITY, "G": STANDARD_GRAVITY, "mg": 1e-3 * STANDARD_GRAVITY,
}


def unit_scale(unit, file: str | None = None, field: str = "unit") -> float:
    """The factor from ``unit`` (a spelling of :data:`UNITS`, surrounding blanks ignored) to m/s².

    Raises
    ------
    InputError
        Naming ``field`` and listing the spellings accepted, for any other unit (a velocity or a
        displacement is not an acceleration; ``"gal"`` or ``"ft/s^2"`` are not in use on cables here).
    """
    spelled = str(unit).strip() if isinstance(unit, str) else unit
    if spelled not in UNITS:
        raise InputError(f"unknown unit {unit!r}; use one of {', '.join(UNITS)}", field=field, file=file)
    return UNITS[spelled]
#: Largest relative spread of time steps accepted as uniform sampling.
TIME_TOLERANCE = 1e-6

Positions = Mapping[str, float] | Iterable[float]


# Checks against the cable


def check_positions(record: Record, length: float, file: str | None = None) -> None:
    """Refuse a channel placed outside the span [0, ``length``] m.

    ``file`` (default ``record.source``) is named in the error.
    """
    outside = np.flatnonzero((record.channel_positions < 0) | (record.channel_positions > length))
    if outside.size:
        index = int(outside[0])
        raise InputError(
            f"channel {record.channel_names[index]!r} at {record.channel_positions[index]:g} m "
            f"lies outside the cable span [0, {length:g}] m",
            field="channel_position", file=file or record.source,
        )


def check_duration(record: Record, f1: float, periods: float = 5, file: str | None = None) -> None:
    """Refuse a record shorter than ``periods`` periods of mode 1 (``f1`` in Hz)."""
    if not f1 > 0:
        raise ValueError(f"f1 must be > 0 Hz, got {f1!r}")
    minimum = periods / f1
    if record.duration < minimum:
        raise InputError(
            f"the record lasts {record.duration:.4g} s, shorter than {periods:g} periods of mode 1 "
            f"({f1:.4g} Hz): at least {minimum:.4g} s needed",
            field="acceleration", file=file or record.source,
        )


def check_bandwidth(record: Record, f1: float, usable: float = 0.45, margin: float = 1.15,
                    file: str | None = None) -> None:
    """Refuse a record sampled too slowly to hold mode 1 (``f1`` in Hz, with ``margin`` for a model error):
    its analysis band ends at ``usable`` × the sampling rate, below the anti-aliasing filter's roll-off."""
    needed = margin * f1 / usable
    if record.sampling_rate < needed:
        raise InputError(
            f"{record.sampling_rate:.4g} Hz resolves frequencies up to {usable * record.sampling_rate:.4g} Hz, "
            f"below mode 1 ({f1:.4g} Hz): at least {needed:.4g} Hz needed",
            field="sampling_rate", file=file or record.source,
        )


# Validation shared by every source


def validated_record(
    acceleration: Any, sampling_rate: Any, names: Any, positions: Any,
    *, unit: str, start_time: str | None, source: str | None, temperature: float | None = None,
    replaced: Iterable[tuple[str, Any, Any]] = (), directions: Any = None, notes: Iterable[str] = (),
) -> Record:
    """Check the parts of a record, convert to m/s², drop dead and clipped channels (``replaced``: the file's
    values that the campaign's options replaced, :func:`overridden`; ``directions``: one per channel, or None
    when the file gives none; ``notes``: what the reader did that a user should know, the record's ``notes``)."""
    file = source
    given = acceleration
    acceleration = check_shape(np.asarray(acceleration, dtype=float), file)
    names = check_names(names, acceleration.shape[1], file)
    positions = check_position_values(positions, names, file)
    if directions is not None:
        directions = check_directions(directions, names, file)
    sampling_rate = check_sampling_rate(sampling_rate, file)
    scale = unit_scale(unit, file)
    if start_time is not None:
        _check_start_time(start_time, file)
    check_finite(acceleration, names, file)
    if scale != 1.0:  # in place when the array is ours already (converted to float64 above)
        acceleration = acceleration * scale if acceleration is given else _scale(acceleration, scale)
    keep, dropped = screen_channels(acceleration, names, file)
    if dropped:  # (indexing copies the record: only when a channel goes)
        acceleration = acceleration[:, keep]
    return Record(
        acceleration=acceleration, sampling_rate=sampling_rate,
        channel_names=tuple(names[k] for k in keep), channel_positions=positions[keep],
        start_time=start_time, source=source, dropped=tuple(dropped), temperature=temperature,
        replaced=tuple(replaced),
        channel_directions=None if directions is None else tuple(directions[k] for k in keep), notes=tuple(notes),
    )


def overridden(name: str, found: Any, options: Mapping[str, Any], replaced: list) -> Any:
    """Option ``name``'s value where the options give it, else ``found`` (the file's; None: the file has none).

    A given value that differs from the file's is recorded in ``replaced`` as ``(name, given, found)`` (the
    record carries it, the report says so).
    """
    given = options.get(name)
    if given is None:
        return found
    if found is not None and found != given:
        replaced.append((name, given, found))
    return given


def names_from_positions(n_channels: int, positions: Mapping[str, Any] | None, file: str | None,
                         what: str = "columns") -> list[str]:
    """Channel names for a file that gives none: the campaign's channel table, in its order, one per column."""
    names = list(positions or {})
    if len(names) != n_channels:
        raise InputError(f"the file names no channels and holds {n_channels} {what}, but the campaign's channel "
                         f"table ([test.channels]) lists {len(names)}: list one channel per {what[:-1]}, in order",
                         field="channel_name", file=file)
    return names


def check_sampling_rate(value: Any, file: str | None) -> float:
    """``value`` as a sampling rate, Hz (:func:`~stcs_ident.core.record.sampling_rate`), naming ``file``."""
    return sampling_rate(value, file=file)


def _check_start_time(value: Any, file: str | None) -> None:
    check_instant(value, field="start_time", file=file)  # the one rule for times (core/times.py)


def _scale(array: np.ndarray, factor: float) -> np.ndarray:
    array *= factor
    return array


class UnknownPositions(dict):
    """Positions for a reader when none are known nor needed (the quick ``tension --record``, which numbers the
    peaks from their spacing, not from shapes): every channel, named or not, at 0 m. Empty as a mapping, yet
    true (a reader's ``positions or {}`` keeps it)."""

    def __bool__(self) -> bool:
        return True


def positions_by_name(names: list[str], positions: Positions, file: str | None) -> dict[str, Any]:
    """Positions given as ``{name: position}`` or in channel order, by name (every channel at 0 m for
    :class:`UnknownPositions`)."""
    if isinstance(positions, UnknownPositions):
        return dict.fromkeys(names, 0.0)
    if isinstance(positions, Mapping):
        unknown = [key for key in positions if key not in names]
        if unknown:
            raise InputError(f"position given for unknown channel {unknown[0]!r}; channels are {', '.join(names)}",
                             field="channel_position", file=file)
        return dict(positions)
    try:
        values = list(positions)
    except TypeError:
        raise InputError("positions must be a mapping or a sequence", field="channel_position", file=file) from None
    if len(values) != len(names):
        raise InputError(f"{len(values)} positions for {len(names)} channels", field="channel_position", file=file)
    return dict(zip(names, values))


def position_list(names: list[str], lookup: Mapping[str, Any], file: str | None) -> list[Any]:
    """The position of each of ``names`` from ``lookup``, in channel order; every channel needs one."""
    missing = [name for name in names if name not in lookup]
    if missing:
        raise InputError(f"no position for channel {missing[0]!r}", field="channel_position", file=file)
    return [lookup[name] for name in names]


def rate_from_time(time: np.ndarray, field: str, file: str | None) -> float:
    """Sampling rate, Hz, of uniformly spaced sample times."""
    if time.size < 2:
        raise InputError("needs at least two samples to give the sampling rate", field=field, file=file)
    if not np.all(np.isfinite(time)):
        index = int(np.argmin(np.isfinite(time)))
        raise InputError(f"sample {index} has no finite time", field=field, file=file)
    step = (time[-1] - time[0]) / (time.size - 1)
    steps = np.diff(time)
    worst = int(np.argmax(np.abs(steps - step)))
    if step <= 0 or abs(steps[worst] - step) > TIME_TOLERANCE * step:
        raise InputError(
            f"not uniformly sampled: step {worst} ({time[worst]:.9g} s to {time[worst + 1]:.9g} s) "
            f"is {steps[worst]:.6g} s against {step:.6g} s on average (tolerance {TIME_TOLERANCE:g} relative)",
            field=field, file=file,
        )
    return float(1.0 / step)


def one_line(err: BaseException) -> str:
    """An exception's text on one line, for an error message that quotes it."""
    return " ".join(str(err).split()) or type(err).__name__
