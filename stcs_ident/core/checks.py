"""The checks of one number of the model: finite, positive, in its band, a frequency, a mode number (and a
pair of bounds).

Each returns the value as a float (an int for a mode number) or raises
:class:`~stcs_ident.core.errors.ModelError` naming the field; the model
objects (:mod:`.model`) and every reader of numbers use them.
"""

from __future__ import annotations

import math

from .errors import ModelError

#: Highest mode number computed or measured. The solver brackets every mode up to the highest (10000
#: modes of a hanger: 0.04 s); a record resolves tens, so a larger number is a mistake, not a need.
MAX_MODE = 10000


#: Measured frequencies lie in this band (Hz): below, a period of hours; above, beyond what any
#: accelerometer records. A value outside is a typing or unit mistake (and 1e300 would overflow χ²).
FREQUENCY_BAND = (1e-4, 1e6)


def frequency(value, name: str) -> float:
    """``value`` as a measured frequency in :data:`FREQUENCY_BAND`; ModelError naming ``name`` otherwise."""
    f = positive_number(value, name)
    low, high = FREQUENCY_BAND
    if not low <= f <= high:
        raise ModelError(f"must lie between {low:g} and {high:g} Hz (a period of hours to beyond any "
                         f"accelerometer), got {value!r}", field=name)
    return f


def mode_number(value, name: str) -> int:
    """``value`` as a mode number 1 … :data:`MAX_MODE`; ModelError naming ``name`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ModelError(f"mode numbers must be integers >= 1, got {value!r}", field=name)
    if value > MAX_MODE:
        shown = value if value < 10**12 else f"an integer of {len(str(value))} digits"
        raise ModelError(f"mode numbers are at most {MAX_MODE} (a record resolves tens of modes; the solver "
                         f"computes every mode up to the highest), got {shown}", field=name)
    return value


def finite_number(value, name: str) -> float:
    """``value`` as a finite float (a bool is not a number); ModelError naming ``name`` otherwise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"must be a number, got {value!r}", field=name) from None
    except OverflowError:  # an integer too large for a float
        raise ModelError(f"must be a finite number, got an integer of {len(str(value))} digits", field=name) from None
    if isinstance(value, bool) or not math.isfinite(v):
        raise ModelError(f"must be a finite number, got {value!r}", field=name)
    return v


#: Bands of the model's quantities (SI units), each far wider than any cable built (spans of 2 km, tensions
#: of 1 GN, tonnes per metre): a value outside is a unit or typing mistake, and the solver, which squares
#: and multiplies these, cannot carry it in floating point (a tension of 1e-320 N or an EI of 1e-300 N m^2
#: left every root search without convergence). Zero stays allowed where it means "none" (EI of a string,
#: an attachment without mass or spring, no gravity).
BANDS = {
    "length": (1e-3, 1e5, "m"),
    "mass_per_length": (1e-6, 1e6, "kg/m"),
    "EI": (1e-9, 1e15, "N m^2"),
    "EA": (1e-3, 1e15, "N"),
    "gravity": (1e-3, 1e3, "m/s^2"),
    "tension": (1e-3, 1e12, "N"),
    "mass": (1e-9, 1e9, "kg"),
    "stiffness": (1e-9, 1e15, "N/m"),
    "coefficient": (1e-6, 1e12, "N s/m"),
}


def in_band(value, name: str, quantity: str, zero: bool = False) -> float:
    """``value`` as a number within ``BANDS[quantity]`` (or 0 when ``zero``); ModelError naming ``name``."""
    v = non_negative_number(value, name) if zero else positive_number(value, name)
    low, high, unit = BANDS[quantity]
    if v != 0 and not low <= v <= high:
        allowed = f"0 or between {low:g} and {high:g}" if zero else f"between {low:g} and {high:g}"
        raise ModelError(f"must be {allowed} {unit} (far beyond any cable: a unit or typing mistake), "
                         f"got {value!r}", field=name)
    return v


def real_number(value, name: str, *, positive: bool = False, nonnegative: bool = False) -> float:
    """``value``, a real number (int or float, numpy's too; not a bool or a string), as a finite float
    (> 0 with ``positive``, >= 0 with ``nonnegative``); ModelError naming ``name`` otherwise. The one check
    of a number given through the library's API (the simulator's options and conditions)."""
    import numpy as np

    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise ModelError(f"must be a number, got {value!r}", field=name)
    v = finite_number(value, name)
    if (positive and v <= 0) or (nonnegative and v < 0):
        raise ModelError(f"must be a finite number {'> 0' if positive else '>= 0'}, got {value!r}", field=name)
    return v


def positive_number(value, name: str) -> float:
    """``value`` as a finite float > 0; ModelError naming ``name`` otherwise."""
    v = finite_number(value, name)
    if v <= 0:
        raise ModelError(f"must be > 0, got {value!r}", field=name)
    return v


def non_negative_number(value, name: str) -> float:
    """``value`` as a finite float >= 0; ModelError naming ``name`` otherwise."""
    v = finite_number(value, name)
    if v < 0:
        raise ModelError(f"must be >= 0, got {value!r}", field=name)
    return v


def checked_bounds(bounds) -> tuple[tuple[str, tuple[float, float]], ...]:
    """``Campaign.bounds`` as sorted (kind, (lower, upper)) pairs of finite increasing numbers."""
    pairs = list(bounds.items()) if isinstance(bounds, dict) else list(bounds)
    out: dict[str, tuple[float, float]] = {}
    for key, given in pairs:
        field = f"bounds.{key}"
        if key in out:
            raise ModelError("a key is given twice", field="bounds")
        if isinstance(given, (str, bytes)) or not hasattr(given, "__len__") or len(given) != 2:
            raise ModelError(f"must be two numbers [lower, upper], got {given!r}", field=field)
        lo, hi = (finite_number(v, field) for v in given)
        if not lo < hi:
            raise ModelError(f"must satisfy lower < upper, got [{lo:g}, {hi:g}]", field=field)
        if lo < 0:
            raise ModelError(f"the lower bound must be >= 0, got {lo:g}", field=field)
        out[key] = (lo, hi)
    return tuple(sorted(out.items()))
