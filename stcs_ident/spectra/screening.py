"""Dead and clipped channels, dropped from a record rather than refused.

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

import warnings

import numpy as np

from ..errors import InputError, RecordWarning

__all__ = ["CLIP_FRACTION", "CLIP_LONG_RUN", "CLIP_MIN_RUN", "DEAD_RELATIVE_STD", "screen_channels"]

DEAD_RELATIVE_STD = 1e-12
CLIP_MIN_RUN = 3
CLIP_LONG_RUN = 20
CLIP_FRACTION = 0.005


def screen_channels(acceleration: np.ndarray, names: list[str], file: str | None) -> tuple[list[int], list]:
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
