"""Acceleration records in HDF5: the record file of a campaign.

The layout is the one of the interface contract: root attributes
``format = "stcs-record"``, ``version = 1``, ``sampling_rate`` (Hz),
``unit`` (``"m/s^2"`` or ``"g"``) and optional ``start_time`` (ISO 8601);
datasets ``/acceleration`` (n_samples, n_channels), ``/channel_name``,
``/channel_position`` (m from end A) and optional ``/channel_direction``
(``in``, ``out``, ``axial`` or an angle in degrees, as text; without it
every channel is in-plane).

The channel directions may also be given as an attribute ``channel_direction``
(an array of strings, one per channel), on the root or on ``/acceleration``,
as some writers keep per-channel metadata in attributes. Where several are
given, the dataset wins, then the root attribute, then the one on
``/acceleration``: the first found is read and the others are not (the writer
writes the dataset only). A direction may also be an axis of the sensor
(``X``, ``Y``, ``Z``), placed on the cable by the reader option ``axes``
(:mod:`~stcs_ident.io.records.directions`). A wrong count or an unknown text
is refused naming the file and ``channel_direction``.

The checks every record source shares
(and their errors) are in :mod:`~stcs_ident.io.records.validation`; dead and
clipped channels are dropped as :mod:`~stcs_ident.io.records.screening` says.
A file that is missing, unreadable or not HDF5 raises an
:class:`~stcs_ident.core.errors.InputError` with no field.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import h5py
import numpy as np

from ...core.errors import InputError
from ...core.files import atomic_path
from ...core.planes import direction_text
from ...core.record import Record
from .base import RecordReader, file_head
from .directions import file_directions
from .rates import FileRate, resolved_rate
from .validation import one_line, overridden, validated_record

__all__ = ["FORMAT", "READER", "VERSION", "Hdf5Reader", "read_record", "write_record"]

FORMAT = "stcs-record"
VERSION = 1
#: Most values of one dataset read into memory (4 GiB as float64).
MAX_VALUES = 2**29
#: The HDF5 signature, at offset 0 or after a user block of 512, 1024, 2048, ... bytes.
SIGNATURE = b"\x89HDF\r\n\x1a\n"


class Hdf5Reader(RecordReader):
    """The contract's HDF5 record (:func:`read_record`); every channel's position is in the file."""

    name = "hdf5"
    suffixes = (".h5", ".hdf5")

    def can_open(self, path: str | os.PathLike) -> bool:
        head = file_head(path)
        return any(head[offset:offset + len(SIGNATURE)] == SIGNATURE for offset in (0, 512, 1024))

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`read_record`; ``positions`` is not used (the file gives every channel's); of the options,
        ``unit`` replaces the file's, ``sampling_rate`` stands in for it or must agree with it (unless
        ``override_sampling_rate``), ``axes`` places axis labels of its directions (the others do not apply)."""
        return read_record(path, unit=options.get("unit"), sampling_rate=options.get("sampling_rate"),
                           axes=options.get("axes"),
                           override_sampling_rate=bool(options.get("override_sampling_rate", False)))


READER = Hdf5Reader()


def read_record(path: str | os.PathLike, *, unit: str | None = None, sampling_rate: float | None = None,
                axes: Any = None, override_sampling_rate: bool = False) -> Record:
    """Read an acceleration record from its HDF5 file (the contract's layout).

    ``unit``, where given, replaces the file's (the record's ``replaced`` says so); ``sampling_rate`` stands
    in for a missing attribute, and must agree with the file's within 1e-6 relative unless
    ``override_sampling_rate`` (:mod:`~stcs_ident.io.records.rates`); ``axes`` places channel directions
    given as axes X, Y, Z on the cable (the reader option).

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
    try:
        return _read(file, {"unit": unit, "sampling_rate": sampling_rate}, axes, override_sampling_rate)
    except InputError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError, TypeError) as err:  # h5py on a corrupt file
        raise InputError(f"cannot read the record (a corrupt HDF5 file?): {one_line(err)}", file=file) from None


def _read(file: str, options: dict[str, Any], axes: Any = None, override: bool = False) -> Record:
    with _open_hdf5(file) as h5:
        if (fmt := _attr(h5.attrs, "format", str, file)) != FORMAT:
            raise InputError(f"is {fmt!r}, expected {FORMAT!r}", field="format", file=file)
        if (version := _attr(h5.attrs, "version", float, file)) != VERSION:
            raise InputError(f"unsupported version {version:g}; this toolkit reads {VERSION}", field="version",
                             file=file)
        replaced: list = []
        found = {key: _attr(h5.attrs, key, kind, file)  # required unless the options give it
                 for key, kind in (("sampling_rate", float), ("unit", str))
                 if options[key] is None or key in h5.attrs}
        own = found.get("sampling_rate")
        sampling_rate = resolved_rate(options["sampling_rate"],
                                      None if own is None else FileRate(own, "attribute sampling_rate"),
                                      override=override, file=file, replaced=replaced)
        unit = overridden("unit", found.get("unit"), options, replaced)
        start_time = _attr(h5.attrs, "start_time", str, file) if "start_time" in h5.attrs else None
        temperature = _attr(h5.attrs, "temperature", float, file) if "temperature" in h5.attrs else None
        acceleration = _read_dataset(h5, "acceleration", file)
        names = _read_dataset(h5, "channel_name", file)
        positions = _read_dataset(h5, "channel_position", file)
        directions = _directions(h5, file)
    if acceleration.dtype.kind != "f":
        raise InputError(f"must be float32 or float64, got {acceleration.dtype}", field="acceleration", file=file)
    if positions.dtype.kind not in "fiu":
        raise InputError(f"must be real numbers (m from end A, float64), got {positions.dtype}",
                         field="channel_position", file=file)
    if directions is not None and acceleration.ndim == 2:  # (another shape is refused as every record's)
        if directions.size != acceleration.shape[1]:
            raise InputError(f"must have {acceleration.shape[1]} entries, one per channel, got {directions.size}",
                             field="channel_direction", file=file)
        directions = file_directions(list(directions), [str(n) for n in np.ravel(names)], axes=axes, file=file,
                                     field="channel_direction")
    return validated_record(acceleration, sampling_rate, names, positions, unit=unit, start_time=start_time,
                            source=file, temperature=temperature, replaced=replaced, directions=directions)


def write_record(record: Record, path: str | os.PathLike, *, float32: bool = False) -> None:
    """Write ``record`` to an HDF5 file, whole or not at all.

    The layout is the contract's, in float64 (float32 if ``float32``, as
    some data loggers write) and m/s², version 1. The file is written
    beside the target under a temporary name, then renamed, so a failure
    never leaves half a record. Dropped channels are not written.
    """
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        h5.attrs.update(format=FORMAT, version=VERSION, sampling_rate=record.sampling_rate, unit="m/s^2")
        if record.start_time is not None:
            h5.attrs["start_time"] = record.start_time
        if record.temperature is not None:
            h5.attrs["temperature"] = record.temperature
        h5["acceleration"] = np.asarray(record.acceleration, dtype=np.float32 if float32 else np.float64)
        h5.create_dataset("channel_name", data=list(record.channel_names), dtype=h5py.string_dtype())
        h5["channel_position"] = np.asarray(record.channel_positions, dtype=np.float64)
        if record.channel_directions is not None:
            h5.create_dataset("channel_direction", data=[direction_text(d) for d in record.channel_directions],
                              dtype=h5py.string_dtype())


def _directions(h5: h5py.File, file: str) -> np.ndarray | None:
    """The channel directions as given (text or numbers): the dataset, else the attribute ``channel_direction``
    of the root, else that of ``/acceleration``; None if none is given."""
    if "channel_direction" in h5:
        return np.asarray(_read_dataset(h5, "channel_direction", file), dtype=object).reshape(-1)
    for node in (h5, h5.get("acceleration")):
        attrs = getattr(node, "attrs", None)
        if attrs is not None and "channel_direction" in attrs:
            try:
                value = np.asarray(attrs["channel_direction"], dtype=object).reshape(-1)
            except (OSError, RuntimeError, KeyError, ValueError, TypeError) as err:
                raise InputError(f"cannot read the attribute: {one_line(err)}", field="channel_direction",
                                 file=file) from None
            return np.asarray([v.decode("utf-8", "replace") if isinstance(v, bytes) else v for v in value],
                              dtype=object)
    return None


def _open_hdf5(file: str) -> h5py.File:
    """Open ``file`` for reading; any failure is an InputError naming it."""
    if not os.path.exists(file):
        raise InputError("file not found", file=file)
    try:
        if not h5py.is_hdf5(file):
            raise InputError("not an HDF5 file", file=file)
        return h5py.File(file, "r")
    except OSError as err:
        raise InputError(f"cannot read the file: {one_line(err)}", file=file) from err


def _attr(attrs: h5py.AttributeManager, key: str, kind: type, file: str) -> Any:
    """Root attribute ``key`` as a Python ``str`` or ``float`` (``kind``)."""
    try:
        if key not in attrs:
            raise InputError("missing root attribute", field=key, file=file)
        value = attrs[key]
    except InputError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError, TypeError) as err:
        raise InputError(f"cannot read the attribute: {one_line(err)}", field=key, file=file) from None
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
    """Dataset ``name`` as an array; strings are decoded from UTF-8.

    A soft or external link in its place is refused: a record is read from the datasets stored in its own
    file (an external link can name any file of the machine, a soft link can dangle or point to itself).
    """
    try:
        link = h5.get(name, getlink=True)
        if link is None:
            raise InputError("missing dataset", field=name, file=file)
        if isinstance(link, h5py.ExternalLink):
            raise InputError(f"must be a dataset stored in the record, found an external link to "
                             f"{link.filename}:{link.path}", field=name, file=file)
        if isinstance(link, h5py.SoftLink):
            raise InputError(f"must be a dataset stored in the record, found a link to {link.path}", field=name,
                             file=file)
        node = h5[name]
        if not isinstance(node, h5py.Dataset):
            raise InputError("must be a dataset, found a group", field=name, file=file)
        if node.size > MAX_VALUES:
            raise InputError(f"holds {node.size} values; at most {MAX_VALUES} ({MAX_VALUES * 8 // 2**30} GiB as "
                             "float64) are read", field=name, file=file)
        if h5py.check_string_dtype(node.dtype) is not None:
            return np.asarray(node.asstr("utf-8")[()], dtype=object)
        if node.dtype.kind == "f" and node.ndim > 0:  # into float64: no second copy of a large record
            out = np.empty(node.shape, dtype=np.float64)
            if node.size:
                _read_float64(node, out)
            return out
        return np.asarray(node[()])
    except InputError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError, TypeError) as err:  # UnicodeDecodeError is a ValueError
        raise InputError(f"cannot read the dataset: {one_line(err)}", field=name, file=file) from None


#: Bytes of a block of rows of a float32 dataset read before conversion (:func:`_read_float64`).
READ_BLOCK_BYTES = 16 * 2**20


def _read_float64(node: h5py.Dataset, out: np.ndarray) -> None:
    """The float dataset ``node`` into the float64 array ``out`` of its shape.

    A float64 dataset is read straight in; another (float32, as loggers write) a block of rows at a time in
    its own type, converted by numpy: HDF5's own conversion took 1.7 s for a record of 50 channels ×
    2,000,000 float32 samples (400 MB) that the blocks read and convert in 0.13 s (from the page cache; the
    same values, float32 to float64 being exact).
    """
    if node.dtype == out.dtype or node.ndim != 2:
        node.read_direct(out)
        return
    rows = max(1, READ_BLOCK_BYTES // max(1, node.dtype.itemsize * node.shape[1]))
    buffer = np.empty((min(rows, node.shape[0]), node.shape[1]), dtype=node.dtype)
    for lo in range(0, node.shape[0], rows):
        hi = min(node.shape[0], lo + rows)
        block = buffer[:hi - lo]
        node.read_direct(block, np.s_[lo:hi], np.s_[0:hi - lo])
        out[lo:hi] = block
