"""Channel directions as record files give them, and the ``axes`` option that places a file's axes on the cable.

A file may say each channel's direction in the cable's terms (``"in"``, ``"out"``, ``"axial"`` or an angle in
degrees from in-plane towards out-of-plane, :func:`~stcs_ident.core.planes.check_direction`) or as an axis of
the sensor's own frame: ``X``, ``Y`` or ``Z``, with an optional sign (a UFF response direction, a TDMS or SEP005
``direction`` of ``"+Y"``). Which of the cable's directions an axis is depends on how the sensor was mounted;
only the campaign can say, with the reader option ``axes`` (``axes = { X = "axial", Y = "in", Z = "out" }``).
The sign of an axis does not change the plane a channel sees (its samples are only inverted; spectra do not
change), so ``-Y`` takes the direction of ``Y``.

A file with axis labels and no ``axes`` is read as before: its channels have no direction (every channel
in-plane, and :func:`~stcs_ident.core.planes.directions_note` says so); a direction is never guessed. Where its
channels lie along different axes (a triaxial sensor), a :class:`~stcs_ident.core.errors.RecordWarning` says
too that ``axes`` would read them: some of them are surely not in-plane. (Channels all along one axis, as a
logger of one-axis sensors writes them, are what the in-plane default assumes, and get no warning.) A label that ``axes``
does not name, or a text that is neither a direction nor an axis, is refused with one line naming the file and
the field.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ...core.errors import InputError, ModelError, RecordWarning
from ...core.planes import check_direction, direction_text

__all__ = ["AXES", "axes_problem", "axes_value", "axis_label", "file_directions"]

#: The axes of a sensor's frame a file may name.
AXES = ("X", "Y", "Z")
_AXIS = re.compile(r"^\s*([+-]?)\s*([xyzXYZ])\s*$")


def axis_label(value: Any) -> str | None:
    """``"X"``, ``"Y"`` or ``"Z"`` when ``value`` names an axis (``"x"``, ``"+Y"``, ``"-z"``), else None."""
    if not isinstance(value, str):
        return None
    match = _AXIS.match(value)
    return match.group(2).upper() if match else None


def axes_problem(value: Any) -> str | None:
    """What is wrong with ``value`` as the option ``axes`` (None: nothing): a table of axis = direction, or
    the (axis, direction) pairs :func:`axes_value` gives."""
    try:
        pairs = _pairs(value)
    except (TypeError, ValueError):
        return f"must be a table of axis = direction ({{ X = \"axial\", Y = \"in\", Z = \"out\" }}), got {value!r}"
    if not pairs:
        return "must name at least one axis (X, Y or Z)"
    seen = set()
    for axis, direction in pairs:
        label = axis.strip().upper() if isinstance(axis, str) else None
        if label not in AXES:
            return f"unknown axis {axis!r}; the axes are X, Y and Z"
        if label in seen:
            return f"axis {label} is given twice"
        seen.add(label)
        try:
            check_direction(direction, f"axes.{label}")
        except ModelError as err:
            return f"axis {label}: {err.message}"
    return None


def axes_value(value: Any) -> tuple[tuple[str, str | float], ...]:
    """``value`` (checked by :func:`axes_problem`) as (axis, direction) pairs in the order X, Y, Z."""
    found = {axis_label(axis): check_direction(direction) for axis, direction in _pairs(value)}
    return tuple((axis, found[axis]) for axis in AXES if axis in found)


def _pairs(value: Any) -> list[tuple[Any, Any]]:
    if isinstance(value, Mapping):
        return list(value.items())
    if isinstance(value, str | bytes) or not isinstance(value, Sequence):
        raise TypeError
    pairs = [tuple(item) for item in value]
    if any(len(item) != 2 for item in pairs):
        raise ValueError
    return pairs


def file_directions(values: Sequence[Any], names: Sequence[str], *, axes: Any = None, file: str | None,
                    field: str) -> tuple[str | float, ...] | None:
    """Each channel's direction from what the file says of it (``values``, one per channel: None where it
    says nothing, a direction, or an axis label that ``axes`` places on the cable).

    Returns None when no channel's direction is known (nothing said, or axis labels and no ``axes``: a
    :class:`~stcs_ident.core.errors.RecordWarning` says so where they name different axes); otherwise one
    direction per channel, in-plane for a channel the file says nothing of (or an axis label without ``axes``).

    Raises
    ------
    InputError
        Naming ``file`` and ``field`` (the file's own name of the direction: ``channel_direction``,
        ``direction``, ``rsp_dir``), or ``axes`` for an axis the option does not name.
    """
    placed = dict(axes_value(axes)) if axes else None
    out: list[str | float | None] = []
    unplaced = []
    for name, value in zip(names, values):
        if isinstance(value, bytes):
            value = value.decode("utf-8", "replace")
        if isinstance(value, np.generic):  # an HDF5 or TDMS number: an angle
            value = value.item()
        if value is None or (isinstance(value, str) and not value.strip()):
            out.append(None)
            continue
        label = axis_label(value)
        if label is None:
            try:
                out.append(check_direction(value, field))
            except ModelError as err:
                raise InputError(f"channel {name!r}: {err.message}, or an axis X, Y, Z placed by the option axes",
                                 field=field, file=file) from None
        elif placed is None:
            unplaced.append((name, value.strip(), label))
            out.append(None)
        elif label not in placed:
            raise InputError(f"channel {name!r} is along {label}, an axis the option does not place on the cable "
                             f"(it gives {', '.join(f'{a} = {direction_text(d)}' for a, d in placed.items())})",
                             field="axes", file=file)
        else:
            out.append(placed[label])
    if len({label for _, _, label in unplaced}) > 1:
        listed = ", ".join(f"{name} ({text})" for name, text, _ in unplaced)
        warnings.warn(f"{file or 'record'}: the file gives the channels' directions as axes of the sensor "
                      f"({listed}) and record_format gives no axes to place them on the cable "
                      "(axes = { X = \"axial\", Y = \"in\", Z = \"out\" }, say): every channel read as in-plane",
                      RecordWarning, stacklevel=3)
    if all(d is None for d in out):
        return None
    return tuple("in" if d is None else d for d in out)
