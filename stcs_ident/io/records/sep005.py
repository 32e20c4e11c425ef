"""Acceleration records to and from the SDyPy SEP005 channel-dict convention.

One dict per channel, with ``data``, ``fs`` (or a uniform ``time``),
``name``, ``quantity`` and ``unit_str``; ``position`` (m from end A) is our
extension. SEP005 names no key for a channel's direction (it allows any
further key), so ``direction`` is our extension too: ``"in"``, ``"out"``,
``"axial"`` or an angle in degrees, or an axis of the sensor (``"X"``,
``"+Y"``, ``"-Z"``) that the reader option ``axes`` places on the cable
(:mod:`~stcs_ident.io.records.directions`). A channel without it is
in-plane; channels none of which has it give no directions. A record read from them passes the checks of every record source
(:mod:`~stcs_ident.io.records.validation`); its errors name no file unless
given one (``source``).

As a file (:class:`Sep005Reader`, :func:`write_sep005`), the channel dicts
are a JSON list (``.json``), ``data`` and ``time`` as lists of numbers.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from ...core.errors import InputError
from ...core.files import atomic_file
from ...core.planes import direction_text
from ...core.record import Record
from .base import RecordReader, file_head
from .directions import file_directions
from .rates import FileRate, resolved_rate
from .validation import (
    UNITS,
    Positions,
    check_sampling_rate,
    one_line,
    position_list,
    positions_by_name,
    rate_from_time,
    unit_scale,
    validated_record,
)

__all__ = ["READER", "Sep005Reader", "from_sep005", "read_sep005", "to_sep005", "write_sep005"]



def to_sep005(record: Record) -> list[dict[str, Any]]:
    """The record as SDyPy SEP005 channel dicts, one per channel.

    Each has ``data`` (1-D, m/s²), ``fs`` (Hz), ``name``, ``quantity``
    (``"acceleration"``), ``unit_str`` (``"m/s^2"``), ``position`` (m from
    end A, our extension) and, when known, ``start_timestamp``,
    ``temperature`` (°C, our extension) and ``direction`` (our extension).
    """
    channels = []
    for index, name in enumerate(record.channel_names):
        channel = {
            "name": name,
            "data": record.acceleration[:, index].copy(),
            "fs": record.sampling_rate,
            "quantity": "acceleration",
            "unit_str": "m/s^2",
            "position": float(record.channel_positions[index]),
        }
        if record.start_time is not None:
            channel["start_timestamp"] = record.start_time
        if record.temperature is not None:
            channel["temperature"] = record.temperature
        if record.channel_directions is not None:
            channel["direction"] = direction_text(record.channel_directions[index])
        channels.append(channel)
    return channels


def from_sep005(channels: Iterable[Mapping[str, Any]], positions: Positions | None = None, *,
                source: str | None = None, axes: Any = None) -> Record:
    """Build a record from SDyPy SEP005 channel dicts.

    Parameters
    ----------
    channels : iterable of dict
        Each with ``name``, ``data`` (1-D), ``unit_str`` (``"m/s^2"``,
        ``"m/s²"`` or ``"g"``), ``fs`` (Hz) or a uniform ``time``, and
        optionally ``quantity`` (acceleration), ``start_timestamp``,
        ``position``, ``temperature`` (°C) and ``direction``. All channels share one length and sampling rate.
    positions : mapping or sequence of float, optional
        Positions of the channels without a ``position`` key.
    source : str, optional
        The file the channels were read from: named in errors and warnings, and the record's ``source``.
    axes : table of axis to direction, optional
        The reader option ``axes``: places directions given as axes X, Y, Z on the cable.

    Raises
    ------
    InputError
        As :func:`~stcs_ident.io.records.hdf5.read_record`, naming ``source`` (if given) and the channel.
    """
    try:
        return _from_sep005(channels, positions, source, axes)
    except InputError as err:
        if source is None or err.file is not None:
            raise
        raise err.with_file(source) from None


def _from_sep005(channels: Iterable[Mapping[str, Any]], positions: Positions | None, source: str | None,
                 axes: Any = None) -> Record:
    channels = list(channels)
    if not channels:
        raise InputError("no channels", field="acceleration")
    names = [_sep005_name(channel, index) for index, channel in enumerate(channels)]
    data = [_sep005_data(channel, name) for channel, name in zip(channels, names)]
    lengths = {name: x.size for name, x in zip(names, data)}
    if len(set(lengths.values())) > 1:
        raise InputError(f"channels differ in length: {lengths}", field="acceleration")
    rates = [_sep005_rate(channel, name, x.size) for channel, name, x in zip(channels, names, data)]
    if not np.allclose(rates, rates[0], rtol=1e-9, atol=0):
        raise InputError(f"channels differ in sampling rate: {dict(zip(names, rates))}", field="sampling_rate")
    lookup = dict(positions_by_name(names, positions, source)) if positions is not None else {}
    lookup.update({name: channel["position"] for name, channel in zip(names, channels) if "position" in channel})
    start_time = next((c["start_timestamp"] for c in channels if c.get("start_timestamp") is not None), None)
    temperature = next((c["temperature"] for c in channels if c.get("temperature") is not None), None)
    directions = file_directions([channel.get("direction") for channel in channels], names, axes=axes,
                                 file=source, field="direction")
    return validated_record(
        np.column_stack(data), rates[0], names, position_list(names, lookup, source),
        unit="m/s^2", start_time=start_time, source=source, temperature=temperature, directions=directions,
    )


class Sep005Reader(RecordReader):
    """SEP005 channel dicts stored as a JSON list (:func:`read_sep005`).

    By content: a file whose first non-blank character opens a JSON list.
    """

    name = "sep005"
    suffixes = (".json",)

    def can_open(self, path: str | os.PathLike) -> bool:
        return file_head(path).lstrip(b"\xef\xbb\xbf \t\r\n")[:1] == b"["

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`read_sep005`; its channel dicts carry their rate and unit (of the options, ``axes`` applies,
        and ``sampling_rate`` must agree with the channels' rate unless ``override_sampling_rate``,
        :mod:`~stcs_ident.io.records.rates`)."""
        record = read_sep005(path, positions, axes=options.get("axes"))
        given = options.get("sampling_rate")
        if given is None:
            return record
        replaced = list(record.replaced)
        rate = resolved_rate(given, FileRate(record.sampling_rate, "channels' rate (fs or time)"),
                             override=bool(options.get("override_sampling_rate", False)), file=record.source,
                             replaced=replaced)
        return replace(record, sampling_rate=rate, replaced=tuple(replaced))  # within its rounding: the given


READER = Sep005Reader()


def read_sep005(path: str | os.PathLike, positions: Positions | None = None, *, axes: Any = None) -> Record:
    """Read a record from a JSON list of SEP005 channel dicts (:func:`from_sep005`, naming the file).

    Raises
    ------
    InputError
        If the file is missing or not JSON (no field), or as :func:`from_sep005`.
    """
    file = os.fspath(path)
    try:
        with open(file, encoding="utf-8-sig") as stream:
            channels = json.load(stream)
    except FileNotFoundError:
        raise InputError("file not found", file=file) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, RecursionError) as err:
        raise InputError(f"cannot read the file as JSON: {one_line(err)}", file=file) from None
    if not isinstance(channels, list):
        raise InputError(f"must be a JSON list of SEP005 channel dicts, got a {type(channels).__name__}",
                         field="acceleration", file=file)
    return from_sep005(channels, positions, source=file, axes=axes)


def write_sep005(record: Record, path: str | os.PathLike) -> None:
    """Write ``record`` as a JSON list of SEP005 channel dicts (:func:`to_sep005`), whole or not at all.

    Floats are written to the digit that gives them back exactly.
    """
    channels = [dict(channel, data=channel["data"].tolist()) for channel in to_sep005(record)]
    with atomic_file(path) as stream:
        json.dump(channels, stream)


def _sep005_name(channel: Mapping[str, Any], index: int) -> str:
    name = channel.get("name") if isinstance(channel, Mapping) else None
    if not isinstance(name, str) or not name:
        raise InputError(f"channel #{index + 1} has no 'name' (or is not a dict)", field="channel_name")
    return name


def _sep005_data(channel: Mapping[str, Any], name: str) -> np.ndarray:
    """The channel's samples in m/s²."""
    if "data" not in channel:
        raise InputError(f"channel {name!r} has no 'data'", field="acceleration")
    try:
        data = np.asarray(channel["data"], dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"channel {name!r}: 'data' is not numeric", field="acceleration") from None
    if data.ndim != 1:
        raise InputError(f"channel {name!r}: 'data' must be 1-D, got shape {data.shape}", field="acceleration")
    quantity = channel.get("quantity", "acceleration")
    if str(quantity).lower() != "acceleration":
        raise InputError(f"channel {name!r} holds {quantity!r}, not acceleration", field="acceleration")
    given = channel.get("unit_str")
    if str(given).strip() not in UNITS:
        raise InputError(f"channel {name!r}: unknown unit_str {given!r}; use one of {', '.join(UNITS)}",
                         field="unit")
    return data * unit_scale(given)


def _sep005_rate(channel: Mapping[str, Any], name: str, n_samples: int) -> float:
    if "fs" in channel:
        return check_sampling_rate(channel["fs"], None)
    if "time" in channel:
        time = np.asarray(channel["time"], dtype=float).reshape(-1)
        if time.size != n_samples:
            raise InputError(f"channel {name!r}: 'time' has {time.size} values for {n_samples} samples",
                             field="sampling_rate")
        return rate_from_time(time, "sampling_rate", None)
    raise InputError(f"channel {name!r} has neither 'fs' nor 'time'", field="sampling_rate")
