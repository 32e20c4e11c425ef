"""Acceleration records in National Instruments TDMS files (npTDMS).

The record is one group's channels (the ``group`` option, or the file's
only group with channels), one TDMS channel per record channel, named as in
the file; their positions come from the campaign's channel table. From each
channel's properties: ``wf_increment`` (s) gives the sampling rate,
``wf_start_time`` the start time, ``unit_string`` the unit; the options
``start_time`` and ``unit`` replace or stand in for them; ``sampling_rate``
stands in for a missing ``wf_increment`` and must agree with one within 1e-6
relative unless ``override_sampling_rate`` (:mod:`~.rates`).
Every channel must agree on the rate and the unit and have as many samples.

A channel's property ``direction`` gives its direction: ``in``, ``out``,
``axial`` or an angle in degrees (text or a number), or an axis of the
sensor (``X``, ``+Y``, ``-Z``) that the reader option ``axes`` places on the
cable (:mod:`~stcs_ident.io.records.directions`). A channel without it is
in-plane; a file where no channel has it gives no directions.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from datetime import UTC, datetime
from typing import Any

import numpy as np
from nptdms import TdmsFile

from ...core.errors import InputError
from ...core.record import Record
from .base import RecordReader, file_head
from .directions import file_directions
from .rates import FileRate, resolved_rate
from .validation import one_line, overridden, position_list, positions_by_name, validated_record

__all__ = ["READER", "TdmsReader", "record_from_tdms"]

#: Relative difference of two channels' sampling increments still taken as one rate.
RATE_AGREEMENT = 1e-9


class TdmsReader(RecordReader):
    """TDMS records (:func:`record_from_tdms`). By content: the lead-in tag ``TDSm``."""

    name = "tdms"
    suffixes = (".tdms",)

    def can_open(self, path: str | os.PathLike) -> bool:
        return file_head(path, 4) == b"TDSm"

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`record_from_tdms` with the options ``group``, ``sampling_rate``, ``unit``, ``axes`` and
        ``override_sampling_rate``."""
        return record_from_tdms(path, positions, group=options.get("group"),
                                sampling_rate=options.get("sampling_rate"), unit=options.get("unit"),
                                axes=options.get("axes"),
                                override_sampling_rate=bool(options.get("override_sampling_rate", False)))


READER = TdmsReader()


def record_from_tdms(path: str | os.PathLike, positions: Mapping[str, float] | None = None, *,
                     group: str | None = None, sampling_rate: float | None = None,
                     unit: str | None = None, axes: Any = None, override_sampling_rate: bool = False) -> Record:
    """Read a record from a TDMS file (see the module docstring).

    Raises
    ------
    InputError
        Naming the file: not TDMS, no such group (field ``group``), several groups and no ``group`` option,
        channels that disagree, no sampling rate (field ``sampling_rate``), and the checks of every record.
    """
    file = os.fspath(path)
    if not os.path.exists(file):
        raise InputError("file not found", file=file)
    try:
        tdms = TdmsFile.read(file)
    except (OSError, ValueError, KeyError, IndexError, TypeError, EOFError) as err:
        raise InputError(f"not a TDMS file this toolkit reads: {one_line(err)}", file=file) from None
    groups = {g.name: g for g in tdms.groups() if g.channels()}
    if not groups:
        raise InputError("holds no channel with data (not a TDMS record?)", field="acceleration", file=file)
    if group is None:
        if len(groups) != 1:
            raise InputError(f"cannot tell the record's group (groups with channels: {', '.join(groups) or 'none'}):"
                             " give group = \"<name>\" in record_format", field="group", file=file)
        group = next(iter(groups))
    if group not in groups:
        raise InputError(f"no group {group!r} with channels (groups: {', '.join(groups) or 'none'}); give the "
                         "right one as group in record_format", field="group", file=file)
    channels = groups[group].channels()
    names = [channel.name for channel in channels]
    lengths = {len(channel) for channel in channels}
    if len(lengths) != 1:
        raise InputError(f"the channels of group {group!r} have different lengths ({sorted(lengths)})",
                         field="acceleration", file=file)
    replaced: list = []
    rate = resolved_rate(sampling_rate, _file_rate(channels, file), override=override_sampling_rate, file=file,
                         replaced=replaced)
    if rate is None:
        raise InputError("no sampling rate: the channels have no wf_increment; give sampling_rate in record_format",
                         field="sampling_rate", file=file)
    unit = overridden("unit", _agreed(channels, "unit_string", file), {"unit": unit}, replaced) or "m/s^2"
    start = _agreed(channels, "wf_start_time", file)
    acceleration = np.column_stack([np.asarray(channel[:], dtype=float) for channel in channels])
    channel_positions = position_list(names, positions_by_name(names, positions or {}, file), file)
    directions = file_directions([_property(channel, "direction") for channel in channels], names, axes=axes,
                                 file=file, field="direction")
    return validated_record(acceleration, rate, names, channel_positions, unit=unit,
                            start_time=None if start is None else _iso_utc(start), source=file, replaced=replaced,
                            directions=directions)


def _property(channel: Any, key: str) -> Any:
    """The channel's property ``key`` as a Python value (numpy scalars unwrapped); None if it has none."""
    value = channel.properties.get(key)
    return value.item() if isinstance(value, np.generic) else value


def _file_rate(channels: list, file: str) -> FileRate | None:
    increments = [channel.properties.get("wf_increment") for channel in channels]
    if all(step is None for step in increments):
        return None
    if any(step is None for step in increments) or not all(float(step) > 0 for step in increments):
        raise InputError(f"every channel needs a wf_increment > 0, got {increments}; give sampling_rate in "
                         "record_format", field="sampling_rate", file=file)
    steps = np.asarray(increments, dtype=float)
    if np.ptp(steps) > RATE_AGREEMENT * steps[0]:
        raise InputError(f"the channels are sampled at different rates (wf_increment {sorted(set(steps))} s)",
                         field="sampling_rate", file=file)
    return FileRate(float(1.0 / steps[0]), "wf_increment", detail=f"{steps[0]:.10g} s")


def _agreed(channels: list, key: str, file: str) -> Any:
    """The channels' common property ``key`` (None if none has it); channels that disagree are refused."""
    values = [channel.properties.get(key) for channel in channels]
    given = [v for v in values if v is not None]
    if not given:
        return None
    if any(str(v) != str(given[0]) for v in values):
        field = "unit" if key == "unit_string" else "start_time"
        raise InputError(f"the channels disagree on {key} ({', '.join(map(str, values))})", field=field, file=file)
    return given[0]


def _iso_utc(value: Any) -> str:
    """A TDMS time stamp (UTC; numpy datetime64 as npTDMS gives it) as ISO 8601 with its offset."""
    stamp = np.datetime64(value, "us").astype(datetime)
    return stamp.replace(tzinfo=UTC).isoformat()
