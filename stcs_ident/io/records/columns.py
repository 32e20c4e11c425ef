"""Which columns of a text record are acceleration channels, in what unit, and where they are on the cable.

A text file (CSV, TOA5, LVM) may hold columns that are not accelerations: a record counter, a battery
voltage, a temperature. The reader option ``channels`` names the acceleration channels; the other columns are
left out, and the record's ``notes`` list them. A file whose columns carry units (TOA5's units line, LVM's
``Y_Unit_Label``) tells them itself: without ``channels``, a column whose unit is one of acceleration
(:data:`~.validation.UNITS`) is a channel and every other column is left out; each channel has its own unit,
which the option ``unit`` replaces (the record's ``replaced`` says where it differs). The channel positions
come from the campaign's channel table; a refusal names the option that would fix it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ...core.errors import InputError
from .validation import UNITS, position_list, positions_by_name, unit_scale

__all__ = ["Selection", "by_channels", "by_units", "text_positions"]


@dataclass(frozen=True)
class Selection:
    """The channels of a text record: their names, the scale of each to m/s², what was left out and replaced.

    Parameters
    ----------
    names : tuple of str
        The channel columns, in file order.
    scales : tuple of float
        Each channel's factor to m/s².
    left_out : tuple of (str, str, str)
        (column, why, detail) for each column not read: ``("BattV", "not an acceleration unit", "Volts")``,
        ``("temp", "not in channels", "")``.
    replaced : tuple of (str, str, str)
        ``("unit of <column>", given, file's)`` where the option ``unit`` replaced a column's unit.
    """

    names: tuple[str, ...]
    scales: tuple[float, ...]
    left_out: tuple[tuple[str, str, str], ...] = ()
    replaced: tuple[tuple[str, str, str], ...] = field(default_factory=tuple)

    def notes(self) -> tuple[str, ...]:
        """One note listing the columns left out, grouped by why (none if none)."""
        if not self.left_out:
            return ()
        reasons: dict[str, list[str]] = {}
        for name, why, detail in self.left_out:
            reasons.setdefault(why, []).append(f"{name} ({detail})" if detail else name)
        return tuple(f"columns left out ({why}): {', '.join(names)}" for why, names in reasons.items())


def _check_channels(columns: Sequence[str], channels: Sequence[str], file: str, excluded: Mapping[str, str]) -> None:
    for name in channels:
        if name in excluded:
            raise InputError(f"channels names {name!r}, {excluded[name]}: not an acceleration channel",
                             field="channels", file=file)
        if name not in columns:
            raise InputError(f"channels names {name!r}, not a column of the file (columns: "
                             f"{', '.join(map(repr, columns))})", field="channels", file=file)


def by_channels(columns: Sequence[str], channels: Sequence[str] | None, unit: str, file: str,
                excluded: Mapping[str, str] | None = None) -> Selection:
    """The channels of a file without units: those ``channels`` names (every column without it), all in
    ``unit``; ``excluded`` maps columns that cannot be channels (the time column) to why."""
    excluded = dict(excluded or {})
    if channels is None:
        names = [name for name in columns if name not in excluded]
        left: list[tuple[str, str, str]] = []
    else:
        _check_channels(columns, channels, file, excluded)
        wanted = set(channels)
        names = [name for name in columns if name in wanted]
        left = [(name, "not in channels", "") for name in columns if name not in wanted and name not in excluded]
    scale = unit_scale(unit, file)
    return Selection(tuple(names), (scale,) * len(names), tuple(left))


def by_units(columns: Sequence[str], units: Sequence[str], channels: Sequence[str] | None, unit: str | None,
             file: str, excluded: Mapping[str, str] | None = None) -> Selection:
    """The channels of a file whose columns carry units (``units[k]`` is column ``k``'s, as the file spells
    it); see the module docstring. ``excluded`` maps columns that cannot be channels (the time column) to why.

    Raises
    ------
    InputError
        Field ``channels``: a name that is no column, or no column with a unit of acceleration and no
        ``channels``; field ``unit``: a channel named in ``channels`` whose unit is not one of acceleration
        and no ``unit`` option.
    """
    excluded = dict(excluded or {})
    own = dict(zip(columns, (str(u).strip() for u in units)))
    if channels is not None:
        _check_channels(columns, channels, file, excluded)
        wanted = set(channels)
        names = [name for name in columns if name in wanted]
        left = [(name, "not in channels", "") for name in columns if name not in wanted and name not in excluded]
    else:
        names = [name for name in columns if name not in excluded and own[name] in UNITS]
        left = [(name, "not an acceleration unit", own[name] or "no unit") for name in columns
                if name not in excluded and own[name] not in UNITS]
        if not names:
            found = ", ".join(f"{name} {own[name]!r}" for name in columns if name not in excluded) or "none"
            raise InputError(f"no column has a unit of acceleration ({', '.join(UNITS)}); the columns' units: "
                             f"{found}: give channels = [\"<column>\", ...] in record_format naming the "
                             "acceleration channels (and unit, the unit they are in)", field="channels", file=file)
    scales, replaced = [], []
    for name in names:
        if unit is not None:
            if own[name] in UNITS and own[name] != unit:
                replaced.append((f"unit of {name}", unit, own[name]))
            scales.append(unit_scale(unit, file))
        elif own[name] in UNITS:
            scales.append(UNITS[own[name]])
        else:
            raise InputError(f"channel {name!r} is in {own[name] or 'no unit'!r}, not a unit of acceleration "
                             f"({', '.join(UNITS)}): give unit in record_format (the unit of every channel read)",
                             field="unit", file=file)
    return Selection(tuple(names), tuple(scales), tuple(left), tuple(replaced))


def text_positions(selection: Selection, positions: Mapping[str, Any] | None, file: str,
                   channels_given: bool) -> list[Any]:
    """Each channel's position from the campaign's channel table, refusing in one line what is missing, saying
    where positions are given and, where a column without one may not be a channel, the option ``channels``."""
    names = list(selection.names)
    table = positions if positions is not None else {}  # (the object itself: positions_by_name may know its kind)
    why = {name: reason for name, reason, _ in selection.left_out}
    for key in table:
        if key not in names and key in why:
            reason = why[key]
            raise InputError(f"the channel table lists {key!r}, a column left out ({reason}); "
                             + ("add it to channels in record_format" if channels_given else
                                "give channels in record_format naming the acceleration channels"),
                             field="channel_position", file=file)
    lookup = positions_by_name(names, table, file)
    missing = [name for name in names if name not in lookup]
    if missing:
        listed = [name for name in names if name in lookup]
        fix = "list its channels in the test's [test.channels] (m from end A)"
        if not channels_given:
            suggestion = ", ".join(f'"{name}"' for name in listed) or '"<column>", ...'
            fix += (f", or, if {missing[0]!r} is not an acceleration channel, give channels = [{suggestion}] in "
                    "record_format naming those that are")
        raise InputError(f"no position for channel {missing[0]!r}; a text record gives no positions: {fix}",
                         field="channel_position", file=file)
    return position_list(names, lookup, file)
