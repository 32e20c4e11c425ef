"""The sampling rate of a record when the campaign gives one and the file has its own.

A ``sampling_rate`` in ``record_format`` stands in for a file that has no rate, and is the rate of a file whose
own agrees with it within the file's rounding (a time column printed to a few digits: that is why the option
exists). A given rate that disagrees with the file's beyond that would scale every frequency, and so the
tension, by their ratio: it is refused (field ``sampling_rate``, naming both values and where each came from),
unless the option ``override_sampling_rate = true`` says the given rate is meant to replace the file's; the
record's ``replaced`` then lists it.

How far a file's rate may be off its true value depends on how it is stored (:class:`FileRate`'s ``rtol``):

- a time column (text): its printed resolution over the record's span (the first and last times are each off
  by up to half a unit of their last digit), plus :data:`~.validation.TIME_TOLERANCE`;
- a number stored in binary (an HDF5 attribute, a MATLAB ``fs``, a TDMS ``wf_increment``):
  :data:`STORED_RTOL`;
- a number printed in a header (LVM ``Delta_X``, UFF's abscissa increment): half a unit of its last printed
  digit, relative, plus :data:`STORED_RTOL`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from ...core.errors import InputError

__all__ = ["STORED_RTOL", "FileRate", "printed_resolution", "resolved_rate"]

#: Relative agreement of a given rate with one the file stores as a binary number. A float32 holds a rate to
#: 6e-8, a rate written to 7 significant digits (256.0001) is within 5e-7; 1e-6 covers both, and a rate off
#: by 1e-6 shifts every frequency by 1e-6 and the tension by 2e-6, far below what a spectrum resolves.
STORED_RTOL = 1e-6

_NUMBER = re.compile(r"^\s*[-+]?(\d*)(?:[.,](\d*))?(?:[eE]([-+]?\d+))?\s*$")


@dataclass(frozen=True)
class FileRate:
    """A file's own sampling rate and where it came from.

    Parameters
    ----------
    value : float
        Hz.
    source : str
        Where in the file, for messages: ``"time column 'time'"``, ``"attribute sampling_rate"``.
    rtol : float
        Relative difference from a given rate still taken as agreement (the file's rounding).
    detail : str
        What the file says, in its own terms (``"steps of 0.01 s"``); may be empty.
    """

    value: float
    source: str
    rtol: float = STORED_RTOL
    detail: str = ""


def printed_resolution(text: Any) -> float | None:
    """A unit of the last digit of a number printed as ``text`` (``"0.0039"``: 1e-4; ``"3.9e-3"``: 1e-4;
    ``"20"``: 1); None when ``text`` is not a plainly printed number."""
    match = _NUMBER.match(text) if isinstance(text, str) else None
    if match is None or not (match.group(1) or match.group(2)):
        return None
    decimals = len(match.group(2) or "")
    exponent = int(match.group(3) or 0)
    if abs(exponent) > 400:
        return None
    return 10.0 ** (exponent - decimals)


def _ratio(value: float) -> str:
    """``value`` with digits enough to show how far from 1 it is (1.000002, not 1)."""
    off = abs(value - 1.0)
    digits = 6 if off == 0 or off >= 1e-3 else min(17, 3 + int(-math.log10(off)))
    return f"{value:.{digits}g}"


def resolved_rate(given: float | None, found: FileRate | None, *, override: bool = False, file: str | None,
                  replaced: list) -> float | None:
    """The record's sampling rate, Hz, from the option ``given`` and the file's ``found`` (either may be None).

    Agreeing within ``found.rtol``, the given rate is used (it is the more precise) and nothing is said; a
    disagreement is refused unless ``override``, and then the given rate is used and ``("sampling_rate",
    given, file's)`` appended to ``replaced``.

    Raises
    ------
    InputError
        Field ``sampling_rate``: both values, where each came from, the ratio every frequency would be scaled
        by, and the two ways out.
    """
    if given is None:
        return None if found is None else found.value
    if found is None:
        return given
    if abs(given - found.value) <= found.rtol * found.value:
        return given
    if override:
        replaced.append(("sampling_rate", given, found.value))
        return given
    detail = f" ({found.detail})" if found.detail else ""
    raise InputError(
        f"record_format gives sampling_rate {given:.10g} Hz, the file's {found.source} says {found.value:.10g} Hz"
        f"{detail}: every frequency would be scaled by {_ratio(given / found.value)}; remove sampling_rate, or give "
        f"override_sampling_rate = true to use {given:.10g} Hz", field="sampling_rate", file=file)
