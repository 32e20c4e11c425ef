"""Dead and clipped channels, dropped from a record rather than refused.

A sensor that died or saturated would spoil the spectra of a record that is
otherwise good, so its channel is dropped: a
:class:`~stcs_ident.core.errors.RecordWarning` names the channel and the file,
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
channel"), raised without warnings; so is a channel of samples so large
(beyond about 1e154 m/s²) that their spread overflows: a corrupt file.
"""

from __future__ import annotations

import warnings

import numpy as np

from ...core.errors import InputError, RecordWarning

__all__ = ["CLIP_FRACTION", "CLIP_LONG_RUN", "CLIP_MIN_RUN", "DEAD_RELATIVE_STD", "screen_channels"]

DEAD_RELATIVE_STD = 1e-12
CLIP_MIN_RUN = 3
CLIP_LONG_RUN = 20
CLIP_FRACTION = 0.005


#: Rows scanned at a time (a record of gigabytes is read in row order, with bounded temporaries).
BLOCK_ROWS = 65536


def screen_channels(acceleration: np.ndarray, names: list[str], file: str | None) -> tuple[list[int], list]:
    """Indices of the usable channels and ``(name, reason)`` of the others; a channel whose samples are so
    large that their spread overflows (a corrupt file's 1e200) is refused, not dropped."""
    with np.errstate(over="ignore", invalid="ignore"):
        low, high, spread, at_rails = _column_statistics(acceleration)
    if not np.all(np.isfinite(spread)):
        j = int(np.argmin(np.isfinite(spread)))
        raise InputError(f"channel {names[j]!r} has samples up to {max(abs(low[j]), abs(high[j])):.3g} m/s², too "
                         "large for their spread to be computed: not an acceleration (a corrupt file?)",
                         field="acceleration", file=file)
    reasons = []
    for j in range(len(names)):
        if high[j] == low[j] or spread[j] <= DEAD_RELATIVE_STD * spread.max():
            reasons.append("dead: constant signal")
        elif at_rails[j] >= CLIP_MIN_RUN:  # only then can a run be held: look at the channel itself
            reasons.append(_clip_reason(acceleration[:, j], low[j], high[j]))
        else:
            reasons.append(None)
    dropped = [(name, reason) for name, reason in zip(names, reasons) if reason]
    keep = [j for j, reason in enumerate(reasons) if reason is None]
    if not keep:
        listing = "; ".join(f"{name!r} {reason}" for name, reason in dropped)
        raise InputError(f"no usable channel: {listing}", field="acceleration", file=file)
    for name, reason in dropped:
        warnings.warn(f"{file or 'record'}: channel {name!r} dropped: {reason}", RecordWarning, stacklevel=4)
    return keep, dropped


def _column_statistics(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per column: minimum, maximum, standard deviation, and the larger count of samples at either extreme;
    in two passes over blocks of rows."""
    n = x.shape[0]
    low, high = x[0].copy(), x[0].copy()
    total = np.zeros(x.shape[1])
    for lo in range(0, n, BLOCK_ROWS):
        block = x[lo:lo + BLOCK_ROWS]
        low = np.minimum(low, _column_reduce(np.minimum, block))
        high = np.maximum(high, _column_reduce(np.maximum, block))
        total += block.sum(axis=0)
    mean = total / n
    squares = np.zeros(x.shape[1])
    at_low = np.zeros(x.shape[1], dtype=int)
    at_high = np.zeros(x.shape[1], dtype=int)
    for lo in range(0, n, BLOCK_ROWS):
        block = x[lo:lo + BLOCK_ROWS]
        squares += ((block - mean) ** 2).sum(axis=0)
        at_low += (block == low).sum(axis=0)
        at_high += (block == high).sum(axis=0)
    return low, high, np.sqrt(squares / n), np.maximum(at_low, at_high)


def _column_reduce(ufunc: np.ufunc, block: np.ndarray) -> np.ndarray:
    """``ufunc.reduce(block, axis=0)`` for a minimum or maximum (exact in any order): of a row-major block, its
    rows folded in 16s into rows 16 times as long first (np.min along the rows of a 65536 × 50 block took
    10.7 ms, 3.0 ms so: numpy's loop along short rows is slow)."""
    fold = next((k for k in (16, 8, 4, 2) if block.shape[0] % k == 0), 1)
    if fold == 1 or not block.flags.c_contiguous:
        return ufunc.reduce(block, axis=0)
    wide = ufunc.reduce(block.reshape(-1, fold * block.shape[1]), axis=0)
    return ufunc.reduce(wide.reshape(fold, block.shape[1]), axis=0)


def _clip_reason(signal: np.ndarray, low: float, high: float) -> str | None:
    rails = _clip_rails(signal, low, high)
    if not rails:
        return None
    if len(rails) == 2 and np.isclose(abs(rails[0]), abs(rails[1]), rtol=0.01):
        return f"clipped at ±{max(abs(rail) for rail in rails):.4g} m/s²"
    return "clipped at " + " and ".join(f"{rail:+.4g}" for rail in rails) + " m/s²"


def _clip_rails(signal: np.ndarray, low: float, high: float) -> list[float]:
    """The extreme values (``low``, ``high``) a saturated channel holds; empty when it is not clipped."""
    held = {}
    for rail in (float(low), float(high)):
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
