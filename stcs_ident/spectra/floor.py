"""Noise floors of spectra, and the local degrees of freedom of their scatter.

Noise floor
    Per channel: medians over frequency blocks (at least 8 resolution
    cells, growing to 3 % of the frequency), a running median over 7
    blocks (a window of 56 cells or ±10 % of the frequency, five times the
    half-power width of a mode with ζ = 2 %), interpolated in log, divided
    by the median of the spectrum's chi-squared distribution so that in
    pure noise it is the mean. A running median follows a monotone skirt
    exactly; three passes leave out the peak regions found in the previous
    one (bins above the 1 % chi-squared quantile, or an 8-cell running
    mean above twice the floor, grown until they fall to the floor or to
    the valley next to them), so a resonance does not lift its own floor,
    and where resonances fill the band the floor follows their valleys.

Local degrees of freedom (free decays)
    See :func:`ripple_dof`: from the scatter of the log spectrum outside
    the peaks.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage, special, stats

from .options import FloorOptions

__all__ = ["floor_log_variance", "noise_floor", "ripple_dof"]

# The tuning values (blocks, passes, mask) are :class:`.options.FloorOptions`.
CHUNK_VALUES = 2**20  # noise_floor: values of the spectra treated at once


def _blocks(n: int, cell: int, options: FloorOptions) -> list[tuple[int, int]]:
    """Frequency blocks [lo, hi): at least ``block_cells`` cells, growing to ``block_relative`` of their frequency."""
    blocks = []
    lo = 1
    min_width = options.block_cells * cell
    while lo < n:
        hi = min(n, lo + max(min_width, int(options.block_relative * lo)))
        blocks.append((lo, hi))
        lo = hi
    return blocks


def _quantile_to_mean(dof, quantile: float):
    """The `quantile` of a chi-squared variable with `dof` degrees of freedom over its mean."""
    dof = np.asarray(dof, dtype=float)
    return special.gammaincinv(dof / 2.0, quantile) / (dof / 2.0)


def _block_floor(spectra: np.ndarray, cell: int, options: FloorOptions) -> np.ndarray:
    """Running median (over ``floor_blocks`` blocks) of block medians, interpolated in log; nan bins are left out."""
    n = spectra.shape[0]
    blocks = _blocks(n, cell, options)
    centres = np.array([0.5 * (lo + hi - 1) for lo, hi in blocks])
    medians = np.full((len(blocks), spectra.shape[1]), np.nan)
    for i, (lo, hi) in enumerate(blocks):
        medians[i] = _nan_median(spectra[lo:hi], axis=0, min_count=max(2, (hi - lo) // 4))
    log_med = np.log(np.maximum(medians, np.finfo(float).tiny))
    half = options.floor_blocks // 2
    padded = np.pad(log_med, ((half, half), (0, 0)), constant_values=np.nan)
    windows = np.lib.stride_tricks.sliding_window_view(padded, options.floor_blocks, axis=0)
    smooth = _nan_median(windows, axis=-1, min_count=1)
    index = np.arange(n)
    columns = []
    for col in smooth.T:
        ok = np.isfinite(col)
        columns.append(np.interp(index, centres[ok], col[ok]) if ok.any() else np.zeros(n))
    return np.exp(np.column_stack(columns))


def _nan_median(values: np.ndarray, axis: int, min_count: int) -> np.ndarray:
    """Median ignoring nan (nan where fewer than `min_count` values); faster than np.nanmedian."""
    ordered = np.sort(values, axis=axis)  # nan sort last
    count = np.sum(np.isfinite(values), axis=axis, keepdims=True)
    lo = np.maximum((count - 1) // 2, 0)
    hi = np.maximum(count // 2, 0)
    median = 0.5 * (np.take_along_axis(ordered, lo, axis=axis) + np.take_along_axis(ordered, hi, axis=axis))
    median = np.where(count >= min_count, median, np.nan)
    return np.squeeze(median, axis=axis)


def noise_floor(spectra: np.ndarray, dof, cell: int, passes: int | None = None,
                options: FloorOptions | None = None) -> np.ndarray:
    """Local noise floor of each column of `spectra` (mean level of the noise; see the module docstring).

    `dof` is a number or one per bin (degrees of freedom of the spectrum).
    `passes` = 1 takes the running median without leaving peaks out (for
    a spectrum whose peaks have been taken out already); by default
    ``options.passes``. `options`: blocks, passes and mask (default: the
    calibrated values).

    Columns are independent; a large array is done a group of columns at
    a time (its temporaries, some ten times its size, stay bounded).
    """
    options = FloorOptions() if options is None else options
    passes = options.passes if passes is None else passes
    group = max(1, CHUNK_VALUES // max(1, spectra.shape[0]))
    if spectra.shape[1] > group:
        return np.concatenate([noise_floor(spectra[:, c:c + group], dof, cell, passes, options)
                               for c in range(0, spectra.shape[1], group)], axis=1)
    dof = np.broadcast_to(np.asarray(dof, dtype=float), spectra.shape[:1])
    # The quantiles once per distinct value (often one for all bins), then spread over the bins.
    dof, bins = np.unique(dof, return_inverse=True)
    correction = _quantile_to_mean(dof, 0.5)[bins][:, None]
    threshold = (stats.chi2.isf(options.mask_probability, dof) / dof)[bins][:, None]
    # A broad peak may stand only a few times above a first floor that it lifts itself: it is found in the
    # spectrum averaged over mask_smoothing cells, whose scatter is that many times smaller.
    smoothing = options.mask_smoothing * cell
    smooth_dof = dof * options.mask_smoothing
    # At least twice the floor: a smooth spectrum a little off its floor (curvature) is no peak.
    smooth_threshold = np.maximum(stats.chi2.isf(options.mask_probability, smooth_dof) / smooth_dof,
                                  2.0)[bins][:, None]
    masked = spectra
    floor = None
    for k in range(passes):
        floor = _block_floor(masked, cell, options) / correction
        if k == passes - 1:
            break
        ratio = spectra / floor
        smooth = ndimage.uniform_filter1d(ratio, smoothing, axis=0, mode="nearest")
        peaks = _peak_regions(ratio, threshold, smooth) | _peak_regions(smooth, smooth_threshold)
        masked = np.where(peaks, np.nan, spectra)
    return floor


def _peak_regions(ratio: np.ndarray, threshold: np.ndarray, smooth: np.ndarray | None = None) -> np.ndarray:
    """Bins above `threshold`, grown on each side until the ratio falls below 1 or `smooth` reaches a valley.

    Stopping at the valleys (local minima of `smooth`, the ratio's running
    mean) keeps each region to its own resonance: where resonances fill
    the band, the floor then follows the valleys between them instead of
    sinking, pass after pass, to the lowest bins. Columns are independent.
    """
    smooth = ratio if smooth is None else smooth
    above = ratio > threshold
    low = ratio < 1.0
    valley = np.zeros(ratio.shape, dtype=bool)
    valley[1:-1] = (smooth[1:-1] <= smooth[:-2]) & (smooth[1:-1] <= smooth[2:])
    n = ratio.shape[0]
    idx = np.arange(n)[:, None]
    left = np.maximum.accumulate(np.where(low | valley, idx, -1), axis=0)
    right = np.minimum.accumulate(np.where(low | valley, idx, n)[::-1], axis=0)[::-1]
    mask = np.zeros((n + 1, ratio.shape[1]), dtype=int)
    rows, cols = np.nonzero(above)
    np.add.at(mask, (left[rows, cols] + 1, cols), 1)
    np.add.at(mask, (right[rows, cols], cols), -1)
    return np.cumsum(mask, axis=0)[:n] > 0


def ripple_dof(ratio: np.ndarray, cell: int, low: float, high: float, options: FloorOptions | None = None) -> np.ndarray:
    """Local degrees of freedom of a spectrum from the scatter of its logarithm.

    A mean of C channels' periodograms has 2C degrees of freedom where the
    sensors' independent noise dominates, but only 2 where a random
    response common to all channels does (ambient loading continuing
    through a decay), and many where the smooth deterministic skirts of
    the decaying modes stand far above the noise. var(log χ²_d) = ψ'(d/2)
    is independent of the level, so its local value, over every `cell`-th
    bin outside peak regions, gives d; clipped to [low, high]. `options`: the
    floor's blocks and mask (default: the calibrated values).
    """
    options = FloorOptions() if options is None else options
    log_ratio = np.log(np.maximum(ratio, np.finfo(float).tiny))
    threshold = np.full((ratio.size, 1), stats.chi2.isf(options.mask_probability, low) / low)
    peaks = _peak_regions(ratio[:, None], threshold)[:, 0]
    sample = np.zeros(ratio.size, dtype=bool)
    sample[::cell] = True
    blocks = _blocks(ratio.size, cell, options)
    centres, variances = [], []
    for lo, hi in blocks:
        values = log_ratio[lo:hi][sample[lo:hi] & ~peaks[lo:hi]]
        if values.size >= 8:
            centres.append(0.5 * (lo + hi - 1))
            variances.append(np.var(values, ddof=1))
    if not variances:
        return np.full(ratio.size, low)
    variances = ndimage.median_filter(np.array(variances), size=options.floor_blocks, mode="nearest")
    dof = 2.0 * _inverse_trigamma(np.maximum(variances, 1e-12))
    return np.clip(np.interp(np.arange(ratio.size), centres, dof), low, high)


def _inverse_trigamma(value: np.ndarray) -> np.ndarray:
    """x with ψ'(x) = value, by bisection in log x (ψ' decreases from ∞ to 0)."""
    value = np.asarray(value, dtype=float)
    lo, hi = np.full(value.shape, 1e-3), np.full(value.shape, 1e6)
    for _ in range(60):
        mid = np.sqrt(lo * hi)
        above = special.polygamma(1, mid) > value
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
    return np.sqrt(lo * hi)


def floor_log_variance(dof: float, options: FloorOptions | None = None) -> float:
    """Variance of log(floor estimate / true floor) in pure noise of `dof` degrees of freedom.

    The floor is a median of about n = block_cells · floor_blocks
    independent values (of `options`, default the calibrated ones):
    1 / (4 n p(m)² m²), p the density of the spectrum (mean 1) and m its median.
    """
    options = FloorOptions() if options is None else options
    half = dof / 2.0
    median = special.gammaincinv(half, 0.5) / half
    density = stats.gamma.pdf(median, half, scale=1.0 / half)
    return float(1.0 / (4.0 * options.block_cells * options.floor_blocks * density**2 * median**2))
