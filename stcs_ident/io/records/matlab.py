"""Acceleration records in MATLAB ``.mat`` files: v5 (scipy.io) and v7.3 (HDF5, h5py).

The record is one numeric matrix, (n_samples, n_channels) as MATLAB shows it
(a vector is one channel): the variable named by the ``variable`` option, or
the file's only matrix. It may be a field of a struct (``rec.acc``, nested
structs as ``a.b.acc``; a 1x1 struct, v5 and v7.3 alike): then each of the
variables below is looked for in the same struct first (``rec.fs``), then
at the top level of the file. Beside it the file may hold:

- ``fs`` (or ``Fs``, ``FS``, ``sampling_rate``): the sampling rate, Hz, one
  number (MATLAB's 1×1 array); the ``sampling_rate`` option stands in for
  it, and must agree with it to 1e-6 relative unless
  ``override_sampling_rate`` (:mod:`~stcs_ident.io.records.rates`);
- ``channel_names``: a cell array of strings (or a char matrix), one per
  column; without it the campaign's channel table names the columns in order;
- ``unit`` (a string; the ``unit`` option replaces it; default m/s²),
  ``start_time`` (ISO 8601 string) and ``temperature`` (°C, one number);
- ``channel_directions``: a cell array of strings, one per column: ``in``,
  ``out``, ``axial``, an angle in degrees, or an axis of the sensor (``X``,
  ``+Y``) that the reader option ``axes`` places on the cable
  (:mod:`~stcs_ident.io.records.directions`); without it the campaign's
  channel table gives the directions, else every channel is in-plane.

A v7.3 file is HDF5 behind a 512-byte MATLAB header; MATLAB stores its
arrays column-major, so a matrix is read transposed back to MATLAB's shape.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping
from typing import Any

import h5py
import numpy as np
import scipy.io

from ...core.errors import InputError
from ...core.record import Record
from .base import RecordReader, file_head
from .directions import file_directions
from .rates import FileRate, resolved_rate
from .validation import names_from_positions, one_line, overridden, position_list, positions_by_name, validated_record

__all__ = ["READER", "MatlabReader", "record_from_mat"]

#: Names the sampling rate goes by in the files of data loggers, in the order they are looked for.
RATE_NAMES = ("fs", "Fs", "FS", "sampling_rate")
#: Depth of nested structs read (``a.b.c`` is depth 2).
MAX_DEPTH = 8
#: Variables of the file that are not the record's matrix.
_METADATA = (*RATE_NAMES, "channel_names", "channel_directions", "unit", "start_time", "temperature")


class MatlabReader(RecordReader):
    """MATLAB ``.mat`` records, v5 and v7.3 (:func:`record_from_mat`). By content: the MATLAB header text."""

    name = "matlab"
    suffixes = (".mat",)

    def can_open(self, path: str | os.PathLike) -> bool:
        return file_head(path, 128).startswith(b"MATLAB")

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`record_from_mat` with the options ``variable``, ``sampling_rate``, ``unit``, ``axes`` and
        ``override_sampling_rate``."""
        return record_from_mat(path, positions, variable=options.get("variable"),
                               sampling_rate=options.get("sampling_rate"), unit=options.get("unit"),
                               axes=options.get("axes"),
                               override_sampling_rate=bool(options.get("override_sampling_rate", False)))


READER = MatlabReader()


def record_from_mat(path: str | os.PathLike, positions: Mapping[str, float] | None = None, *,
                    variable: str | None = None, sampling_rate: float | None = None,
                    unit: str | None = None, axes: Any = None, override_sampling_rate: bool = False) -> Record:
    """Read a record from a MATLAB file (see the module docstring).

    Raises
    ------
    InputError
        Naming the file: not a MATLAB file, no such variable (field ``variable``), several matrices and no
        ``variable`` option, no sampling rate (field ``sampling_rate``), a given sampling rate that disagrees
        with the file's (:mod:`~stcs_ident.io.records.rates`), a transposed matrix, and the checks of every
        record.
    """
    file = os.fspath(path)
    variables = _load(file)
    matrices = [k for k, v in variables.items() if _leaf(k) not in _METADATA and isinstance(v, np.ndarray)
                and v.dtype.names is None and v.size > 1]
    if variable is None:
        if len(matrices) != 1:
            found = ", ".join(matrices) or "none"
            raise InputError(f"cannot tell the record's matrix (numeric variables: {found}): give variable = "
                             "\"<name>\" in record_format (a field of a struct as \"rec.acc\")", field="variable",
                             file=file)
        variable = matrices[0]
    if variable not in variables:
        raise InputError(f"no variable {variable!r} in the file (variables: {', '.join(variables) or 'none'}); "
                         "give the right one as variable in record_format", field="variable", file=file)
    acceleration = _matrix(variables[variable], variable, file)
    prefix = variable.rpartition(".")[0]
    meta = {name: _beside(variables, prefix, name) for name in _METADATA}  # the struct's field, else the file's
    replaced: list = []
    rate = resolved_rate(sampling_rate, _rate(meta, file), override=override_sampling_rate, file=file,
                         replaced=replaced)
    if rate is None:
        where = f"struct {prefix!r} nor the file hold" if prefix else "file holds"
        raise InputError(f"no sampling rate: the {where} none of {', '.join(RATE_NAMES)}; give sampling_rate "
                         "in record_format", field="sampling_rate", file=file)
    unit = overridden("unit", _text(meta, "unit", file), {"unit": unit}, replaced) or "m/s^2"
    names = _value(meta, "channel_names")
    if names is None:
        names = names_from_positions(acceleration.shape[1], positions, file)
    elif isinstance(names, str):
        names = [names]
    channel_positions = position_list(list(names), positions_by_name(list(names), positions or {}, file), file)
    temperature = _value(meta, "temperature")
    if temperature is not None:
        temperature = _one_number(temperature, meta["temperature"][0], file)
    directions = _value(meta, "channel_directions")
    if directions is not None:
        directions = [directions] if isinstance(directions, str) else directions
        if not isinstance(directions, list) or len(directions) != acceleration.shape[1]:
            count = len(directions) if isinstance(directions, list) else "not a cell array of strings"
            raise InputError(f"must be a cell array of {acceleration.shape[1]} strings, one per column, got {count}",
                             field="channel_directions", file=file)
        directions = file_directions(directions, list(names), axes=axes, file=file, field="channel_directions")
    return validated_record(acceleration, rate, names, channel_positions, unit=unit,
                            start_time=_text(meta, "start_time", file), source=file,
                            temperature=temperature, replaced=replaced, directions=directions)


def _leaf(key: str) -> str:
    """The last part of a dotted name (``"rec.fs"``: ``"fs"``)."""
    return key.rpartition(".")[2]


def _beside(variables: dict[str, Any], prefix: str, name: str) -> tuple[str, Any] | None:
    """(its full name, value) of variable ``name`` in the struct ``prefix`` (a field of it), else at the top
    level of the file; None if neither holds it."""
    for key in (f"{prefix}.{name}" if prefix else None, name):
        if key is not None and key in variables:
            return key, variables[key]
    return None


def _value(meta: dict[str, tuple[str, Any] | None], name: str) -> Any:
    found = meta.get(name)
    return None if found is None else found[1]


def _load(file: str) -> dict[str, Any]:
    """The file's variables: numeric arrays in MATLAB's shape, strings, lists of strings; the fields of a 1x1
    struct as ``struct.field`` (nested structs as ``a.b.c``)."""
    if not os.path.exists(file):
        raise InputError("file not found", file=file)
    head = file_head(file, 1024)
    try:
        if head.startswith(b"MATLAB 7.3") or h5py.is_hdf5(file):
            return _load_v73(file)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # scipy warns on odd headers; a file it cannot read raises
            raw = scipy.io.loadmat(file, chars_as_strings=True)
    except InputError:
        raise
    except NotImplementedError as err:
        raise InputError(f"a MATLAB format this toolkit does not read: {one_line(err)}", file=file) from None
    except (OSError, ValueError, TypeError, KeyError, IndexError, RuntimeError, AttributeError,
            RecursionError) as err:
        raise InputError(f"not a MATLAB file this toolkit reads (v5 or v7.3): {one_line(err)}", file=file) from None
    out: dict[str, Any] = {}
    for key, value in raw.items():
        if not key.startswith("__"):
            _flatten_v5(key, value, out, 0)
    return out


def _flatten_v5(key: str, value: Any, out: dict[str, Any], depth: int) -> None:
    if isinstance(value, np.ndarray) and value.dtype.names and value.size == 1 and depth < MAX_DEPTH:
        item = value.reshape(-1)[0]
        for field in value.dtype.names:
            _flatten_v5(f"{key}.{field}", item[field], out, depth + 1)
        return
    out[key] = _v5_value(value)


def _v5_value(value: Any) -> Any:
    if isinstance(value, np.ndarray) and value.dtype.kind == "U":
        texts = [str(x).rstrip() for x in value.ravel()]
        return texts[0] if len(texts) == 1 else texts
    if isinstance(value, np.ndarray) and value.dtype == object:  # a cell array: of strings, for channel_names
        return [str(_v5_value(cell)) for cell in value.ravel(order="F")]
    return value


def _load_v73(file: str) -> dict[str, Any]:
    out: dict[str, Any] = {}
    with h5py.File(file, "r") as h5:
        _flatten_v73(h5, h5, "", out, 0)
    return out


def _flatten_v73(h5: h5py.File, group: h5py.Group, prefix: str, out: dict[str, Any], depth: int) -> None:
    """The datasets of ``group`` into ``out`` by dotted name, a struct (a group) field by field."""
    for key, node in group.items():
        if key.startswith("#"):
            continue
        name = f"{prefix}{key}"
        if isinstance(node, h5py.Group):
            if depth < MAX_DEPTH:
                _flatten_v73(h5, node, f"{name}.", out, depth + 1)
            continue
        if not isinstance(node, h5py.Dataset) or node.attrs.get("MATLAB_empty", 0):
            continue
        kind = node.attrs.get("MATLAB_class", b"double")
        kind = kind.decode() if isinstance(kind, bytes) else str(kind)
        if kind == "char":
            out[name] = _v73_chars(node[()])
        elif kind == "cell":
            out[name] = [_v73_chars(h5[ref][()]) for ref in node[()].T.ravel()]
        else:
            out[name] = np.asarray(node[()]).T  # column-major: back to MATLAB's (rows, columns)


def _v73_chars(codes: np.ndarray) -> str:
    return "".join(chr(int(c)) for c in np.asarray(codes).T.ravel()).rstrip()


def _matrix(value: Any, name: str, file: str) -> np.ndarray:
    if not isinstance(value, np.ndarray) or value.dtype.kind not in "fiu" or value.ndim > 2:
        what = f"a {value.dtype} array of shape {value.shape}" if isinstance(value, np.ndarray) else "text"
        raise InputError(f"variable {name!r} must be a real numeric matrix (n_samples, n_channels), got {what}",
                         field="variable", file=file)
    if value.ndim < 2 or min(value.shape) == 1:
        return value.reshape(-1, 1)
    if value.shape[0] < value.shape[1]:
        raise InputError(f"variable {name!r} has {value.shape[0]} rows and {value.shape[1]} columns: expected one "
                         "row per sample and one column per channel; transpose it", field="variable", file=file)
    return value


def _rate(meta: dict[str, tuple[str, Any] | None], file: str) -> FileRate | None:
    """The file's rate: the first of :data:`RATE_NAMES` in the record's struct, else at the top level."""
    for name in RATE_NAMES:
        if meta.get(name) is not None:
            key, value = meta[name]
            return FileRate(_one_number(value, key, file), f"variable {key!r}")
    return None


def _one_number(value: Any, name: str, file: str) -> float:
    if not isinstance(value, np.ndarray) or value.dtype.kind not in "fiu" or value.size != 1:
        shape = f"shape {value.shape}" if isinstance(value, np.ndarray) else repr(value)
        raise InputError(f"variable {name!r} must be one number (a 1x1 array), got {shape}", field=name, file=file)
    return float(value.reshape(()))


def _text(meta: dict[str, tuple[str, Any] | None], name: str, file: str) -> str | None:
    found = meta.get(name)
    if found is not None and not isinstance(found[1], str):
        raise InputError(f"variable {found[0]!r} must be a string", field=name, file=file)
    return None if found is None else found[1]
