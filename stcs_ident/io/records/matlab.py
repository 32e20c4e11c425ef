"""Acceleration records in MATLAB ``.mat`` files: v5 (scipy.io) and v7.3 (HDF5, h5py).

The record is one numeric matrix, (n_samples, n_channels) as MATLAB shows it
(a vector is one channel): the variable named by the ``variable`` option, or
the file's only matrix. Beside it the file may hold:

- ``fs`` (or ``Fs``, ``sampling_rate``): the sampling rate, Hz, one number
  (MATLAB's 1×1 array); the ``sampling_rate`` option replaces it or stands in;
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
from .validation import names_from_positions, one_line, overridden, position_list, positions_by_name, validated_record

__all__ = ["READER", "MatlabReader", "record_from_mat"]

#: Names the sampling rate goes by in the files of data loggers, in the order they are looked for.
RATE_NAMES = ("fs", "Fs", "FS", "sampling_rate")
#: Variables of the file that are not the record's matrix.
_METADATA = (*RATE_NAMES, "channel_names", "channel_directions", "unit", "start_time", "temperature")


class MatlabReader(RecordReader):
    """MATLAB ``.mat`` records, v5 and v7.3 (:func:`record_from_mat`). By content: the MATLAB header text."""

    name = "matlab"
    suffixes = (".mat",)

    def can_open(self, path: str | os.PathLike) -> bool:
        return file_head(path, 128).startswith(b"MATLAB")

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`record_from_mat` with the options ``variable``, ``sampling_rate``, ``unit`` and ``axes``."""
        return record_from_mat(path, positions, variable=options.get("variable"),
                               sampling_rate=options.get("sampling_rate"), unit=options.get("unit"),
                               axes=options.get("axes"))


READER = MatlabReader()


def record_from_mat(path: str | os.PathLike, positions: Mapping[str, float] | None = None, *,
                    variable: str | None = None, sampling_rate: float | None = None,
                    unit: str | None = None, axes: Any = None) -> Record:
    """Read a record from a MATLAB file (see the module docstring).

    Raises
    ------
    InputError
        Naming the file: not a MATLAB file, no such variable (field ``variable``), several matrices and no
        ``variable`` option, no sampling rate (field ``sampling_rate``), a transposed matrix, and the checks
        of every record.
    """
    file = os.fspath(path)
    variables = _load(file)
    matrices = [k for k, v in variables.items() if k not in _METADATA and isinstance(v, np.ndarray) and v.size > 1]
    if variable is None:
        if len(matrices) != 1:
            found = ", ".join(matrices) or "none"
            raise InputError(f"cannot tell the record's matrix (numeric variables: {found}): give variable = "
                             "\"<name>\" in record_format", field="variable", file=file)
        variable = matrices[0]
    if variable not in variables:
        raise InputError(f"no variable {variable!r} in the file (variables: {', '.join(variables) or 'none'}); "
                         "give the right one as variable in record_format", field="variable", file=file)
    acceleration = _matrix(variables[variable], variable, file)
    replaced: list = []
    rate = overridden("sampling_rate", _rate(variables, file), {"sampling_rate": sampling_rate}, replaced)
    if rate is None:
        raise InputError(f"no sampling rate: the file holds none of {', '.join(RATE_NAMES)}; give sampling_rate "
                         "in record_format", field="sampling_rate", file=file)
    unit = overridden("unit", _text(variables, "unit", file), {"unit": unit}, replaced) or "m/s^2"
    names = variables.get("channel_names")
    if names is None:
        names = names_from_positions(acceleration.shape[1], positions, file)
    elif isinstance(names, str):
        names = [names]
    channel_positions = position_list(list(names), positions_by_name(list(names), positions or {}, file), file)
    temperature = variables.get("temperature")
    if temperature is not None:
        temperature = _one_number(temperature, "temperature", file)
    directions = variables.get("channel_directions")
    if directions is not None:
        directions = [directions] if isinstance(directions, str) else directions
        if not isinstance(directions, list) or len(directions) != acceleration.shape[1]:
            count = len(directions) if isinstance(directions, list) else "not a cell array of strings"
            raise InputError(f"must be a cell array of {acceleration.shape[1]} strings, one per column, got {count}",
                             field="channel_directions", file=file)
        directions = file_directions(directions, list(names), axes=axes, file=file, field="channel_directions")
    return validated_record(acceleration, rate, names, channel_positions, unit=unit,
                            start_time=_text(variables, "start_time", file), source=file,
                            temperature=temperature, replaced=replaced, directions=directions)


def _load(file: str) -> dict[str, Any]:
    """The file's variables: numeric arrays in MATLAB's shape, strings, lists of strings."""
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
    except (OSError, ValueError, TypeError, KeyError, IndexError, RuntimeError) as err:
        raise InputError(f"not a MATLAB file this toolkit reads (v5 or v7.3): {one_line(err)}", file=file) from None
    return {key: _v5_value(value) for key, value in raw.items() if not key.startswith("__")}


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
        for key, node in h5.items():
            if key.startswith("#") or not isinstance(node, h5py.Dataset) or node.attrs.get("MATLAB_empty", 0):
                continue
            kind = node.attrs.get("MATLAB_class", b"double")
            kind = kind.decode() if isinstance(kind, bytes) else str(kind)
            if kind == "char":
                out[key] = _v73_chars(node[()])
            elif kind == "cell":
                out[key] = [_v73_chars(h5[ref][()]) for ref in node[()].T.ravel()]
            else:
                out[key] = np.asarray(node[()]).T  # column-major: back to MATLAB's (rows, columns)
    return out


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


def _rate(variables: dict[str, Any], file: str) -> float | None:
    for name in RATE_NAMES:
        if name in variables:
            return _one_number(variables[name], name, file)
    return None


def _one_number(value: Any, name: str, file: str) -> float:
    if not isinstance(value, np.ndarray) or value.dtype.kind not in "fiu" or value.size != 1:
        shape = f"shape {value.shape}" if isinstance(value, np.ndarray) else repr(value)
        raise InputError(f"variable {name!r} must be one number (a 1x1 array), got {shape}", field=name, file=file)
    return float(value.reshape(()))


def _text(variables: dict[str, Any], name: str, file: str) -> str | None:
    value = variables.get(name)
    if value is not None and not isinstance(value, str):
        raise InputError(f"variable {name!r} must be a string", field=name, file=file)
    return value
