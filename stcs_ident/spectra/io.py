"""Read, write and convert acceleration records.

The HDF5 layout is the one of the interface contract: root attributes
``format = "stcs-record"``, ``version = 1``, ``sampling_rate`` (Hz),
``unit`` (``"m/s^2"`` or ``"g"``) and optional ``start_time`` (ISO 8601);
datasets ``/acceleration`` (n_samples, n_channels), ``/channel_name`` and
``/channel_position`` (m from end A). A record also comes from CSV
(:func:`record_from_csv`) and converts to and from the SDyPy SEP005
channel-dict convention (:func:`to_sep005`, :func:`from_sep005`). Whatever
the source, the same checks apply and the result is a
:class:`~stcs_ident.spectra.record.Record` in m/s².

Errors
------
Every problem raises :class:`~stcs_ident.errors.InputError` whose text is
one line, ``"<file>: field '<field>': <what is wrong>"``. The fields are
those of the file: ``format``, ``version``, ``sampling_rate``, ``unit``,
``start_time``, ``acceleration``, ``channel_name``, ``channel_position``
(and ``time`` for CSV). A file that is missing, unreadable or not HDF5 or
CSV has no field. Non-finite samples are refused, naming the channel and
its first bad sample (0-based index).

Channels dropped, not refused
-----------------------------
A sensor that died or saturated would spoil the spectra of a record that is
otherwise good, so its channel is dropped: a
:class:`~stcs_ident.errors.RecordWarning` names the channel and the file,
and ``Record.dropped`` keeps ``(name, reason)``.

- **Dead**: a constant channel, or one whose standard deviation is at most
  1e-12 times the largest channel's. Reason ``"dead: constant signal"``.
- **Clipped**: a saturated sensor holds its rail value for consecutive
  samples, whereas a healthy signal touches its extreme at one sample (two
  when the peak falls between samples). So only runs of at least 3
  consecutive samples exactly at the channel's maximum or minimum count as
  held; the channel is clipped when one such run lasts 20 samples or more,
  or when held samples make at least 0.5 % of the record. Reason
  ``"clipped at ±X m/s²"`` (one signed value when only one rail is held).

If every channel would be dropped, that is an ``InputError`` ("no usable
channel"), raised without warnings.
"""

from __future__ import annotations

import csv
import os
import tempfile
import warnings
from collections.abc import Iterable, Mapping
from datetime import datetime
from typing import Any

import h5py
import numpy as np
import pandas as pd

from ..errors import InputError, RecordWarning
from ..files import umask
from .record import STANDARD_GRAVITY, Record

__all__ = ["check_duration", "check_positions", "from_sep005", "read_record", "record_from_csv", "to_sep005",
           "write_record"]

FORMAT = "stcs-record"
VERSION = 1
#: Units a record may be in, with their factor to m/s².
UNITS = {"m/s^2": 1.0, "g": STANDARD_GRAVITY}

DEAD_RELATIVE_STD = 1e-12
CLIP_MIN_RUN = 3
CLIP_LONG_RUN = 20
CLIP_FRACTION = 0.005
#: Largest relative spread of time steps accepted as uniform sampling.
TIME_TOLERANCE = 1e-6

# SEP005 writes the unit as free text; the contract's spelling is "m/s^2".
_SEP005_UNITS = {"m/s^2": "m/s^2", "m/s²": "m/s^2", "m/s2": "m/s^2", "g": "g"}

Positions = Mapping[str, float] | Iterable[float]


# HDF5


def read_record(path: str | os.PathLike) -> Record:
    """Read an acceleration record from its HDF5 file (the contract's layout).

    Returns
    -------
    Record
        In m/s², ``source = str(path)``, dead and clipped channels dropped.

    Raises
    ------
    InputError
        If the file is missing or not HDF5, or an attribute or dataset is
        missing or invalid; ``.file`` and ``.field`` say where.
    """
    file = str(path)
    with _open_hdf5(file) as h5:
        if (fmt := _attr(h5.attrs, "format", str, file)) != FORMAT:
            raise InputError(f"is {fmt!r}, expected {FORMAT!r}", field="format", file=file)
        if (version := _attr(h5.attrs, "version", float, file)) != VERSION:
            raise InputError(f"unsupported version {version:g}; this toolkit reads {VERSION}", field="version",
                             file=file)
        sampling_rate = _attr(h5.attrs, "sampling_rate", float, file)
        unit = _attr(h5.attrs, "unit", str, file)
        start_time = _attr(h5.attrs, "start_time", str, file) if "start_time" in h5.attrs else None
        acceleration = _read_dataset(h5, "acceleration", file)
        names = _read_dataset(h5, "channel_name", file)
        positions = _read_dataset(h5, "channel_position", file)
    if acceleration.dtype.kind != "f":
        raise InputError(f"must be float32 or float64, got {acceleration.dtype}", field="acceleration", file=file)
    return _validated_record(acceleration, sampling_rate, names, positions, unit=unit, start_time=start_time,
                             source=file)


def write_record(record: Record, path: str | os.PathLike) -> None:
    """Write ``record`` to an HDF5 file, whole or not at all.

    The layout is the contract's, in float64 and m/s², version 1. The file
    is written beside the target under a temporary name, then renamed, so a
    failure never leaves half a record. Dropped channels are not written.
    """
    target = os.fspath(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(target)}.", dir=os.path.dirname(target) or ".")
    os.close(fd)
    try:
        with h5py.File(tmp, "w") as h5:
            h5.attrs.update(format=FORMAT, version=VERSION, sampling_rate=record.sampling_rate, unit="m/s^2")
            if record.start_time is not None:
                h5.attrs["start_time"] = record.start_time
            h5["acceleration"] = np.asarray(record.acceleration, dtype=np.float64)
            h5.create_dataset("channel_name", data=list(record.channel_names), dtype=h5py.string_dtype())
            h5["channel_position"] = np.asarray(record.channel_positions, dtype=np.float64)
        os.chmod(tmp, 0o666 & ~umask())  # mkstemp makes 0600; give the mode a plain open() would
        os.replace(tmp, target)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _open_hdf5(file: str) -> h5py.File:
    """Open ``file`` for reading; any failure is an InputError naming it."""
    if not os.path.exists(file):
        raise InputError("file not found", file=file)
    try:
        if not h5py.is_hdf5(file):
            raise InputError("not an HDF5 file", file=file)
        return h5py.File(file, "r")
    except OSError as err:
        raise InputError(f"cannot read the file: {_one_line(err)}", file=file) from err


def _attr(attrs: h5py.AttributeManager, key: str, kind: type, file: str) -> Any:
    """Root attribute ``key`` as a Python ``str`` or ``float`` (``kind``)."""
    if key not in attrs:
        raise InputError("missing root attribute", field=key, file=file)
    value = attrs[key]
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.reshape(())[()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bytes):
        value = value.decode("utf-8", errors="replace")
    if kind is str and isinstance(value, str):
        return value
    if kind is float and isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    raise InputError(f"must be a {'string' if kind is str else 'number'}, got {value!r}", field=key, file=file)


def _read_dataset(h5: h5py.File, name: str, file: str) -> np.ndarray:
    """Dataset ``name`` as an array; strings are decoded from UTF-8."""
    if name not in h5:
        raise InputError("missing dataset", field=name, file=file)
    node = h5[name]
    if not isinstance(node, h5py.Dataset):
        raise InputError("must be a dataset, found a group", field=name, file=file)
    try:
        if h5py.check_string_dtype(node.dtype) is not None:
            return np.asarray(node.asstr("utf-8")[()], dtype=object)
        return np.asarray(node[()])
    except (OSError, ValueError) as err:  # UnicodeDecodeError is a ValueError
        raise InputError(f"cannot read the dataset: {_one_line(err)}", field=name, file=file) from err


# CSV


def record_from_csv(
    path: str | os.PathLike, positions: Positions, *, time_column: str = "time", unit: str = "m/s^2"
) -> Record:
    """Read a record from CSV: a header line, a time column, one column per channel.

    Parameters
    ----------
    path : str or path-like
        The CSV file; the header names the channels.
    positions : mapping or sequence of float
        m from end A: ``{name: position}``, or one per channel in file order.
    time_column : str
        Sample times, s: uniform within ``TIME_TOLERANCE`` (relative).
    unit : {"m/s^2", "g"}
        Unit of the channel columns.

    Raises
    ------
    InputError
        As :func:`read_record`; a missing or non-uniform time has field ``time``.
    """
    file = str(path)
    header, table = _read_csv(file)
    if len(set(header)) != len(header):
        duplicate = next(name for name in header if header.count(name) > 1)
        raise InputError(f"duplicate column {duplicate!r}", field="channel_name", file=file)
    if time_column not in header:
        raise InputError(f"no {time_column!r} column among {', '.join(header)}", field="time", file=file)
    time = _numeric_column(table, header, time_column, "time", file)
    sampling_rate = _rate_from_time(time, "time", file)
    names = [name for name in header if name != time_column]
    acceleration = np.column_stack(
        [_numeric_column(table, header, name, "acceleration", file) for name in names] or [np.empty((time.size, 0))]
    )
    position_list = _position_list(names, _positions_by_name(names, positions, file), file)
    return _validated_record(
        acceleration, sampling_rate, names, position_list, unit=unit, start_time=None, source=file
    )


def _read_csv(file: str) -> tuple[list[str], pd.DataFrame]:
    """The header and the data rows of ``file`` (columns by place, so duplicates survive)."""
    try:
        with open(file, newline="", encoding="utf-8-sig") as stream:  # -sig: tolerate a BOM
            header = [name.strip() for name in next(csv.reader(stream), [])]
        if not header:
            raise InputError("empty file: no header line", file=file)
        table = pd.read_csv(file, header=None, skiprows=1, skipinitialspace=True, encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError("file not found", file=file) from None
    except pd.errors.EmptyDataError:
        raise InputError("has no samples", field="acceleration", file=file) from None
    except (OSError, UnicodeDecodeError, pd.errors.ParserError) as err:
        raise InputError(f"cannot read the file as CSV: {_one_line(err)}", file=file) from err
    if table.shape[1] != len(header):
        raise InputError(f"the header has {len(header)} columns, the rows {table.shape[1]}", file=file)
    return header, table


def _numeric_column(table: pd.DataFrame, header: list[str], name: str, field: str, file: str) -> np.ndarray:
    """Column ``name`` as floats; empty cells become NaN, text is refused."""
    column = table.iloc[:, header.index(name)]
    values = pd.to_numeric(column, errors="coerce").to_numpy(dtype=float)
    text = np.flatnonzero(np.isnan(values) & column.notna().to_numpy())
    if text.size:
        row = int(text[0])
        raise InputError(f"column {name!r}, line {row + 2}: {column.iloc[row]!r} is not a number",
                         field=field, file=file)
    return values


def _rate_from_time(time: np.ndarray, field: str, file: str | None) -> float:
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


# SEP005


def to_sep005(record: Record) -> list[dict[str, Any]]:
    """The record as SDyPy SEP005 channel dicts, one per channel.

    Each has ``data`` (1-D, m/s²), ``fs`` (Hz), ``name``, ``quantity``
    (``"acceleration"``), ``unit_str`` (``"m/s^2"``), ``position`` (m from
    end A, our extension) and, when known, ``start_timestamp``.
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
        channels.append(channel)
    return channels


def from_sep005(channels: Iterable[Mapping[str, Any]], positions: Positions | None = None) -> Record:
    """Build a record from SDyPy SEP005 channel dicts.

    Parameters
    ----------
    channels : iterable of dict
        Each with ``name``, ``data`` (1-D), ``unit_str`` (``"m/s^2"``,
        ``"m/s²"`` or ``"g"``), ``fs`` (Hz) or a uniform ``time``, and
        optionally ``quantity`` (acceleration), ``start_timestamp`` and
        ``position``. All channels share one length and sampling rate.
    positions : mapping or sequence of float, optional
        Positions of the channels without a ``position`` key.

    Raises
    ------
    InputError
        As :func:`read_record`, without a file; the message names the channel.
    """
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
    lookup = dict(_positions_by_name(names, positions, None)) if positions is not None else {}
    lookup.update({name: channel["position"] for name, channel in zip(names, channels) if "position" in channel})
    start_time = next((c["start_timestamp"] for c in channels if c.get("start_timestamp") is not None), None)
    return _validated_record(
        np.column_stack(data), rates[0], names, _position_list(names, lookup, None),
        unit="m/s^2", start_time=start_time, source=None,
    )


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
    unit = _SEP005_UNITS.get(str(channel.get("unit_str")).strip())
    if unit is None:
        raise InputError(f"channel {name!r}: unknown unit_str {channel.get('unit_str')!r}; use 'm/s^2' or 'g'",
                         field="unit")
    return data * UNITS[unit]


def _sep005_rate(channel: Mapping[str, Any], name: str, n_samples: int) -> float:
    if "fs" in channel:
        return _check_sampling_rate(channel["fs"], None)
    if "time" in channel:
        time = np.asarray(channel["time"], dtype=float).reshape(-1)
        if time.size != n_samples:
            raise InputError(f"channel {name!r}: 'time' has {time.size} values for {n_samples} samples",
                             field="sampling_rate")
        return _rate_from_time(time, "sampling_rate", None)
    raise InputError(f"channel {name!r} has neither 'fs' nor 'time'", field="sampling_rate")


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


# Validation shared by every source


def _validated_record(
    acceleration: Any, sampling_rate: Any, names: Any, positions: Any,
    *, unit: str, start_time: str | None, source: str | None,
) -> Record:
    """Check the parts of a record, convert to m/s², drop dead and clipped channels."""
    file = source
    acceleration = _check_shape(np.asarray(acceleration, dtype=float), file)
    names = _check_names(names, acceleration.shape[1], file)
    positions = _check_position_values(positions, names, file)
    sampling_rate = _check_sampling_rate(sampling_rate, file)
    if unit not in UNITS:
        raise InputError(f"unknown unit {unit!r}; use 'm/s^2' or 'g'", field="unit", file=file)
    if start_time is not None:
        _check_start_time(start_time, file)
    _check_finite(acceleration, names, file)
    acceleration = acceleration * UNITS[unit]
    keep, dropped = _screen_channels(acceleration, names, file)
    return Record(
        acceleration=acceleration[:, keep], sampling_rate=sampling_rate,
        channel_names=tuple(names[k] for k in keep), channel_positions=positions[keep],
        start_time=start_time, source=source, dropped=tuple(dropped),
    )


def _check_shape(acceleration: np.ndarray, file: str | None) -> np.ndarray:
    if acceleration.ndim != 2:
        raise InputError(f"must have shape (n_samples, n_channels), got {acceleration.shape}",
                         field="acceleration", file=file)
    if acceleration.shape[0] == 0 or acceleration.shape[1] == 0:
        raise InputError(f"has no samples or no channels: shape {acceleration.shape}", field="acceleration", file=file)
    return acceleration


def _check_names(names: Any, n_channels: int, file: str | None) -> list[str]:
    names = np.asarray(names, dtype=object)
    if names.shape != (n_channels,):
        raise InputError(f"must have shape ({n_channels},), one per channel, got {names.shape}",
                         field="channel_name", file=file)
    seen = set()
    for index, name in enumerate(names):
        if not isinstance(name, str) or not name.strip():
            raise InputError(f"channel {index} needs a non-empty text name, got {name!r}", field="channel_name",
                             file=file)
        if name in seen:
            raise InputError(f"duplicate channel name {name!r}", field="channel_name", file=file)
        seen.add(name)
    return [str(name) for name in names]


def _check_position_values(positions: Any, names: list[str], file: str | None) -> np.ndarray:
    try:
        positions = np.asarray(positions, dtype=float)
    except (TypeError, ValueError):
        raise InputError("positions must be numbers", field="channel_position", file=file) from None
    if positions.shape != (len(names),):
        raise InputError(f"must have shape ({len(names)},), one per channel, got {positions.shape}",
                         field="channel_position", file=file)
    bad = np.flatnonzero(~np.isfinite(positions))
    if bad.size:
        index = int(bad[0])
        raise InputError(f"channel {names[index]!r} has position {positions[index]}: not a finite number",
                         field="channel_position", file=file)
    return positions


def _check_sampling_rate(value: Any, file: str | None) -> float:
    try:
        rate = float(value)
    except (TypeError, ValueError):
        rate = np.nan
    if not rate > 0 or rate == np.inf:
        raise InputError(f"must be a finite number > 0 Hz, got {value!r}", field="sampling_rate", file=file)
    return rate


def _check_start_time(value: Any, file: str | None) -> None:
    try:
        datetime.fromisoformat(value)
    except (TypeError, ValueError):
        raise InputError(f"is not an ISO 8601 time: {value!r}", field="start_time", file=file) from None


def _check_finite(acceleration: np.ndarray, names: list[str], file: str | None) -> None:
    """Refuse NaN or inf samples, naming the first bad channel and sample."""
    bad = ~np.isfinite(acceleration)
    bad_channels = np.flatnonzero(bad.any(axis=0))
    if not bad_channels.size:
        return
    channel = int(bad_channels[0])
    sample = int(np.argmax(bad[:, channel]))
    value = acceleration[sample, channel]
    what = "NaN" if np.isnan(value) else f"{value:g}"
    others = f" ({bad_channels.size - 1} other channel(s) too)" if bad_channels.size > 1 else ""
    raise InputError(f"channel {names[channel]!r} has {what} at sample {sample} (0-based), "
                     f"its first non-finite sample{others}", field="acceleration", file=file)


def _positions_by_name(names: list[str], positions: Positions, file: str | None) -> dict[str, Any]:
    """Positions given as ``{name: position}`` or in channel order, by name."""
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


def _position_list(names: list[str], lookup: Mapping[str, Any], file: str | None) -> list[Any]:
    missing = [name for name in names if name not in lookup]
    if missing:
        raise InputError(f"no position for channel {missing[0]!r}", field="channel_position", file=file)
    return [lookup[name] for name in names]


def _screen_channels(acceleration: np.ndarray, names: list[str], file: str | None) -> tuple[list[int], list]:
    """Indices of the usable channels and ``(name, reason)`` of the others."""
    spread = acceleration.std(axis=0)
    reasons = [_drop_reason(acceleration[:, j], spread[j], spread.max()) for j in range(len(names))]
    dropped = [(name, reason) for name, reason in zip(names, reasons) if reason]
    keep = [j for j, reason in enumerate(reasons) if reason is None]
    if not keep:
        listing = "; ".join(f"{name!r} {reason}" for name, reason in dropped)
        raise InputError(f"no usable channel: {listing}", field="acceleration", file=file)
    for name, reason in dropped:
        warnings.warn(f"{file or 'record'}: channel {name!r} dropped: {reason}", RecordWarning, stacklevel=4)
    return keep, dropped


def _drop_reason(signal: np.ndarray, spread: float, largest_spread: float) -> str | None:
    if np.ptp(signal) == 0 or spread <= DEAD_RELATIVE_STD * largest_spread:
        return "dead: constant signal"
    rails = _clip_rails(signal)
    if not rails:
        return None
    if len(rails) == 2 and np.isclose(abs(rails[0]), abs(rails[1]), rtol=0.01):
        return f"clipped at ±{max(abs(rail) for rail in rails):.4g} m/s²"
    return "clipped at " + " and ".join(f"{rail:+.4g}" for rail in rails) + " m/s²"


def _clip_rails(signal: np.ndarray) -> list[float]:
    """The extreme values a saturated channel holds; empty when it is not clipped."""
    held = {}
    for rail in (float(signal.min()), float(signal.max())):
        runs = _run_lengths(signal == rail)
        held[rail] = runs[runs >= CLIP_MIN_RUN]
    longest = max((int(runs.max()) for runs in held.values() if runs.size), default=0)
    total = sum(int(runs.sum()) for runs in held.values())
    if longest >= CLIP_LONG_RUN or total >= CLIP_FRACTION * signal.size:
        return [rail for rail, runs in held.items() if runs.size]
    return []


def _run_lengths(mask: np.ndarray) -> np.ndarray:
    """Lengths of the runs of consecutive True values in ``mask``."""
    edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)


def _one_line(err: BaseException) -> str:
    return " ".join(str(err).split()) or type(err).__name__
