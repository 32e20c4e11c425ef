"""Acceleration records in universal files (UFF/UNV), dataset 58, read with pyuff.

Each dataset 58 of the file that is a time response (function type 1) is one
channel, named by its response entity name (``rsp_ent_name``) or, where that
is blank, its response node number; the positions come from the campaign's
channel table. The abscissa increment (``abscissa_inc``, s) gives the
sampling rate and the ordinate's units label the unit; the option ``unit``
replaces or stands in for the unit, ``sampling_rate`` stands in for a missing
increment. The format prints the increment to six significant digits: where
that is not the exact step (1/2048 s, say), give ``sampling_rate``, which
must agree with it within that rounding (:data:`PRINTED_RTOL`) unless
``override_sampling_rate`` (:mod:`~.rates`). The file holds no start time:
give ``start_time`` where one is needed.

Each dataset's response direction (``rsp_dir``: 1, 2, 3 for +X, +Y, +Z,
negative for -X, -Y, -Z; 0 for a scalar) is an axis of the sensor's frame:
the reader option ``axes`` places it on the cable
(:mod:`~stcs_ident.io.records.directions`; the sign does not change the
plane). Without ``axes`` the channels are read as in-plane, with a warning;
a scalar or rotational direction (0, ±4 … ±6) says nothing of the channel's.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import numpy as np
import pyuff

from ...core.errors import InputError
from ...core.record import Record
from .base import RecordReader
from .directions import AXES, file_directions
from .rates import STORED_RTOL, FileRate, resolved_rate
from .validation import one_line, overridden, position_list, positions_by_name, validated_record

__all__ = ["READER", "UffReader", "record_from_uff"]

#: Function type of a time response in dataset 58.
TIME_RESPONSE = 1
#: Relative agreement of a given rate with the abscissa increment's: the format prints it to six significant
#: digits (half a unit of the sixth is at most 5e-6 of it), plus the stored-number agreement of :mod:`.rates`.
PRINTED_RTOL = 5e-6 + STORED_RTOL
#: Relative difference of two datasets' abscissa increments still taken as one rate.
RATE_AGREEMENT = 1e-9
_BLANK = ("", "NONE")


class UffReader(RecordReader):
    """UFF dataset 58 records (:func:`record_from_uff`); the suffix tells the format."""

    name = "uff"
    suffixes = (".uff", ".unv")

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """:func:`record_from_uff` with the options ``sampling_rate``, ``unit``, ``axes`` and
        ``override_sampling_rate``."""
        return record_from_uff(path, positions, sampling_rate=options.get("sampling_rate"), unit=options.get("unit"),
                               axes=options.get("axes"),
                               override_sampling_rate=bool(options.get("override_sampling_rate", False)))


READER = UffReader()


def record_from_uff(path: str | os.PathLike, positions: Mapping[str, float] | None = None, *,
                    sampling_rate: float | None = None, unit: str | None = None, axes: Any = None,
                    override_sampling_rate: bool = False) -> Record:
    """Read a record from the datasets 58 of a universal file (see the module docstring).

    Raises
    ------
    InputError
        Naming the file: not a universal file, no time-response dataset 58, datasets that disagree on the
        rate, the unit or the length, and the checks of every record.
    """
    file = os.fspath(path)
    if not os.path.exists(file):
        raise InputError("file not found", file=file)
    try:
        found = pyuff.UFF(file).read_sets()
    except Exception as err:  # noqa: BLE001 (pyuff raises bare Exception on a file it cannot parse)
        raise InputError(f"not a universal file this toolkit reads: {one_line(err)}", file=file) from None
    found = [found] if isinstance(found, dict) else list(found)
    sets = [s for s in found if s.get("type") == 58 and s.get("func_type") == TIME_RESPONSE]
    if not sets:
        types = sorted({f"{s.get('type')}" + (f" (function type {s.get('func_type')})" if s.get("type") == 58
                                               else "") for s in found})
        raise InputError(f"holds no dataset 58 of a time response (function type 1); found: {', '.join(types) or 'none'}",
                         field="acceleration", file=file)
    names = [_name(s) for s in sets]
    lengths = {len(s["data"]) for s in sets}
    if len(lengths) != 1:
        raise InputError(f"the datasets have different lengths ({sorted(lengths)})", field="acceleration", file=file)
    replaced: list = []
    rate = resolved_rate(sampling_rate, _file_rate(sets, file), override=override_sampling_rate, file=file,
                         replaced=replaced)
    if rate is None:
        raise InputError("a dataset has no abscissa increment (an uneven abscissa?); give sampling_rate in "
                         "record_format", field="sampling_rate", file=file)
    units = {str(s.get("ordinate_axis_units_lab", "")).strip() for s in sets} - set(_BLANK)
    if len(units) > 1:
        raise InputError(f"the datasets disagree on the unit ({', '.join(sorted(units))})", field="unit", file=file)
    unit = overridden("unit", next(iter(units), None), {"unit": unit}, replaced) or "m/s^2"
    data = [np.asarray(s["data"]) for s in sets]
    if any(np.iscomplexobj(d) for d in data):
        raise InputError("the datasets hold complex values, not a time response", field="acceleration", file=file)
    channel_positions = position_list(names, positions_by_name(names, positions or {}, file), file)
    directions = file_directions([_axis(s, file) for s in sets], names, axes=axes, file=file, field="rsp_dir")
    return validated_record(np.column_stack(data), rate, names, channel_positions, unit=unit, start_time=None,
                            source=file, replaced=replaced, directions=directions)


def _axis(dataset: Mapping[str, Any], file: str) -> str | None:
    """The dataset's response direction as an axis (``"+X"``, ``"-Z"``); None for a scalar or a rotation."""
    value = dataset.get("rsp_dir")
    if value is None:
        return None
    try:
        code = int(value)
    except (TypeError, ValueError):
        raise InputError(f"must be an integer from -6 to 6, got {value!r}", field="rsp_dir", file=file) from None
    if not 1 <= abs(code) <= 3:
        return None
    return ("-" if code < 0 else "+") + AXES[abs(code) - 1]


def _name(dataset: Mapping[str, Any]) -> str:
    name = str(dataset.get("rsp_ent_name", "")).strip()
    return str(dataset.get("rsp_node")) if name in _BLANK else name


def _file_rate(sets: list[Mapping[str, Any]], file: str) -> FileRate | None:
    steps = np.asarray([float(s.get("abscissa_inc") or 0.0) for s in sets])
    if not np.all(steps > 0):
        return None
    if np.ptp(steps) > RATE_AGREEMENT * steps[0]:
        raise InputError(f"the datasets are sampled at different rates (abscissa_inc {sorted(set(steps))} s)",
                         field="sampling_rate", file=file)
    return FileRate(float(1.0 / steps[0]), "abscissa increment", rtol=PRINTED_RTOL, detail=f"{steps[0]:.6g} s")
