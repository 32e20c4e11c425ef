"""Spectral overview: per-channel spectra, noise floors and the combined spectrum.

Spectra
    Free decays: per event and channel, the periodogram of the segment
    under a right-half Hann taper (1 at the impulse, 0 at the end: the
    start of a decay is a physical step, only the truncation at the end is
    artificial and would leave sidelobes), zero-padded twice, averaged over
    the events. Ambient: Welch (Hann, 50 % overlap, about 16 segments).
    Both are scaled as one-sided PSD, (m/s²)²/Hz.

Noise floor
    Per channel, a running median over frequency with the peaks left out
    (:mod:`.floor`).

Combined spectrum
    The mean over channels of each channel's spectrum divided by its floor:
    about 1 in noise, and a mode at a node of one sensor still shows in the
    others. Its degrees of freedom are local: C·ν where independent sensor
    noise dominates (C channels, ν per channel), only ν where a random
    response common to all channels does (ambient records: from the
    coherence of the cross-spectral matrix; free decays: from the scatter
    of the log spectrum, which also sees ambient loading continuing
    through a decay, and the smooth deterministic skirts of the decays,
    up to 8·C·ν). The first singular value of the cross-spectral matrix
    (FDD) would weight channels better but has no simple null distribution.

Detection
    Candidates are found in these overviews by :mod:`.detection`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage, signal
from scipy.fft import next_fast_len, rfft

from .events import Event
from .floor import noise_floor, ripple_dof
from .options import FloorOptions, OverviewOptions

__all__ = [
    "Overview",
    "ambient_overview",
    "decay_overview",
    "decay_overviews",
    "noise_floor",
    "smoothed_overview",
]

# The tuning values (padding, Welch segments, decay-matched windows, smoothing) are
# :class:`.options.OverviewOptions`; the floors' are :class:`.options.FloorOptions`.


@dataclass(frozen=True)
class Overview:
    """Per-channel spectra with their noise floors and the combined spectrum.

    Parameters
    ----------
    frequency : ndarray (n_freq,), Hz
    channel_spectra : ndarray (n_freq, n_channels), one-sided PSD (m/s²)²/Hz
    channel_floor : ndarray (n_freq, n_channels), noise floor of each channel
    combined : ndarray (n_freq,), mean of spectrum / floor over channels (1 in noise)
    combined_floor : ndarray (n_freq,), floor of ``combined`` (about 1)
    dof : float, chi-squared degrees of freedom of one channel's spectrum value
    combined_dof : ndarray (n_freq,), effective degrees of freedom of ``combined``
    channel_dof : ndarray (n_freq,), the same for the largest channel's spectrum / floor
    cell : int, frequency bins per independent resolution cell
    random_ripple : bool
        True when the spectrum's scatter is random wherever the signal is
        (ambient): then a peak must also rise above its neighbouring
        valley by more than the ratio of two independent spectrum values
        ever does (F distribution), or ripple on a resonance's skirt would
        pass. Free decays are deterministic; only sensor noise scatters.
    floor_dof : float, optional
        Degrees of freedom of the spectrum the floor was estimated from
        (its scatter; default ``dof``): a smoothed overview keeps the floor
        of the original one.
    """

    frequency: np.ndarray
    channel_spectra: np.ndarray
    channel_floor: np.ndarray
    combined: np.ndarray
    combined_floor: np.ndarray
    dof: float
    combined_dof: np.ndarray
    channel_dof: np.ndarray
    cell: int
    random_ripple: bool = False
    floor_dof: float | None = None


def decay_overview(
    x: np.ndarray, sampling_rate: float, events: list[Event], window_length: int | None = None, *,
    options: OverviewOptions | None = None, floor_options: FloorOptions | None = None,
) -> Overview:
    """Overview of free decays: tapered, zero-padded periodograms averaged over events.

    By default each whole event under a right-half Hann taper. With
    `window_length`, a decay-matched overview instead: a full Hann window
    over the first `window_length` samples of each event (see
    :func:`decay_overviews`). `options`, `floor_options`: padding and
    floors (default: the calibrated values).
    """
    options = OverviewOptions() if options is None else options
    longest = max(e.n_samples for e in events) if window_length is None else int(window_length)
    n_fft = next_fast_len(options.decay_padding * longest, real=True)
    total = np.zeros((n_fft // 2 + 1, x.shape[1]))
    weight = 0.0
    for event in events:
        n = event.n_samples if window_length is None else min(event.n_samples, longest)
        if window_length is None:
            taper = 0.5 * (1.0 + np.cos(np.pi * np.arange(n) / n))
        else:
            taper = signal.windows.hann(n, sym=False)
        spectrum = rfft(x[event.start : event.start + n] * taper[:, None], n=n_fft, axis=0, workers=-1)
        total += np.abs(spectrum) ** 2
        weight += np.sum(taper**2)
    psd = _one_sided(total / (weight * sampling_rate))
    frequency = np.arange(psd.shape[0]) * sampling_rate / n_fft
    cell = max(1, round(n_fft / longest))
    dof = 2.0 * len(events)
    floor = noise_floor(psd, dof, cell, options=floor_options)
    ratio = psd / floor
    high = options.ripple_dof_cap * dof * psd.shape[1]
    combined_dof = ripple_dof(ratio.mean(axis=1), cell, dof, high, floor_options)
    channel_dof = ripple_dof(ratio.max(axis=1), cell, dof, high, floor_options)
    return _overview(frequency, psd, floor, dof, combined_dof, channel_dof, cell, random_ripple=False)


def decay_window_lengths(events: list[Event], options: OverviewOptions | None = None) -> list[int]:
    """Lengths of the decay-matched windows: the longest event over 4, 16, … while at least 64 samples
    (``options.decay_window_ratio``, ``options.min_decay_window``)."""
    options = OverviewOptions() if options is None else options
    longest = max(e.n_samples for e in events)
    lengths = []
    length = longest // options.decay_window_ratio
    while length >= options.min_decay_window:
        lengths.append(int(length))
        length //= options.decay_window_ratio
    return lengths


def decay_overviews(x: np.ndarray, sampling_rate: float, events: list[Event], *,
                    options: OverviewOptions | None = None,
                    floor_options: FloorOptions | None = None) -> list[Overview]:
    """The whole-event overview, the same smoothed over frequency, then decay-matched ones.

    A mode that decays in a small part of the event is drowned, in the
    whole-event periodogram, by the noise of the long tail; and the
    abrupt start of the decays (kept by the right-half taper, which is what
    makes that overview sensitive) gives the strong modes skirts falling
    only as 1/f², on which a weak mode shows as a dip beside a bump, not a
    peak. A full Hann window over the first L samples of each event (L a
    few decay times; :func:`decay_window_lengths`) catches both. A weak,
    heavily damped mode spreads over many cells of the whole-event
    periodogram: averaged over ``options.smoothing`` cells
    (:func:`smoothed_overview`), its peak keeps its height while the
    scatter falls.
    """
    options = OverviewOptions() if options is None else options
    main = decay_overview(x, sampling_rate, events, options=options, floor_options=floor_options)
    overviews = [main, smoothed_overview(main, options.smoothing, options=options, floor_options=floor_options)]
    overviews += [decay_overview(x, sampling_rate, events, n, options=options, floor_options=floor_options)
                  for n in decay_window_lengths(events, options)]
    return overviews


def smoothed_overview(overview: Overview, factor: int, *, options: OverviewOptions | None = None,
                      floor_options: FloorOptions | None = None) -> Overview:
    """The overview's spectra averaged over `factor` resolution cells (a Daniell estimate), on a coarser grid.

    Running means over factor · cell bins, taken every half of that (two
    bins per new cell, the grid still starting at 0 Hz); the degrees of
    freedom grow `factor` times (neighbouring cells are nearly
    independent). The floor is the original one, averaged alike (the
    noise does not change; a floor estimated afresh on the coarse grid
    would span many resonances), and keeps its own scatter (``floor_dof``).
    """
    options = OverviewOptions() if options is None else options
    width = factor * overview.cell
    step = max(1, width // 2)
    kernel = np.ones(width) / width
    centres = np.arange(0, overview.frequency.size, step)

    def smooth(values):
        return ndimage.convolve1d(values, kernel, axis=0, mode="nearest")[centres]

    psd = smooth(overview.channel_spectra)
    floor = smooth(overview.channel_floor)
    dof = overview.dof * factor
    cell = max(1, width // step)
    if overview.random_ripple:
        combined_dof = smooth(overview.combined_dof) * factor
        channel_dof = np.full(centres.shape, dof)
    else:
        ratio = psd / floor
        high = options.ripple_dof_cap * dof * psd.shape[1]
        combined_dof = ripple_dof(ratio.mean(axis=1), cell, dof, high, floor_options)
        channel_dof = ripple_dof(ratio.max(axis=1), cell, dof, high, floor_options)
    combined = (psd / floor).mean(axis=1)
    return Overview(
        overview.frequency[centres], psd, floor, combined, np.ones_like(combined), float(dof), combined_dof,
        channel_dof, int(cell), overview.random_ripple, floor_dof=overview.floor_dof or overview.dof,
    )


def _one_sided(psd: np.ndarray) -> np.ndarray:
    psd = psd.copy()
    psd[1:-1] *= 2.0
    return psd


def welch_length(n_samples: int, options: OverviewOptions | None = None) -> int:
    """Segment length for the ambient Welch spectrum: a power of two near 2N/17 (about 16 segments,
    ``options.welch_segments``)."""
    options = OverviewOptions() if options is None else options
    target = max(256, n_samples * 2 // (options.welch_segments + 1))
    return int(min(n_samples, 2 ** int(np.round(np.log2(target)))))


#: Largest block of segment DFTs (all channels, a band of frequencies) held at once, bytes: with the
#: record itself, what bounds the memory of the ambient overview (:func:`ambient_overview`).
BLOCK_BYTES = 64 * 2**20
#: Rows of a segment transposed at a time into the channels-first buffer of :func:`_segment_dfts` (bytes of
#: the buffer they fill: the rows read stay in cache while their columns are written).
TRANSPOSE_BYTES = 2**18


def _segment_dfts(x: np.ndarray, nperseg: int, window: np.ndarray, budget: int, halves: np.ndarray | None = None):
    """``(segment k, first channel, DFTs (g, n_freq))`` of the Hann-windowed, mean-removed segments (50 %
    overlap), a segment and a group of g channels at a time, channels first: rows read in order from the
    row-major record, each step's arrays within ``budget`` bytes. ``halves``: :func:`_half_sums` of ``x``
    (computed here if not given).

    Each group is transposed into a channels-first buffer, a few rows at a time, so that every DFT runs on
    contiguous samples: an rfft along the rows of a (g, nperseg) array took half the time of one down the
    columns of the (nperseg, g) segment (measured, 2**18 samples × 15 channels: 18 against 33 ms), and
    the strided subtraction of the mean as long again.
    """
    step = nperseg // 2
    n_segments = _n_segments(x.shape[0], nperseg)
    g = int(np.clip(budget // max(1, 24 * nperseg), 1, x.shape[1]))
    if halves is None and 2 * step == nperseg:
        halves = _half_sums(x, step, n_segments)
    buffer = np.empty((g, nperseg))
    rows = max(1, TRANSPOSE_BYTES // (8 * g))
    for k in range(n_segments):
        segment = x[k * step:k * step + nperseg]
        mean = (halves[k] + halves[k + 1]) / nperseg if 2 * step == nperseg else None
        for c0 in range(0, x.shape[1], g):
            columns = segment[:, c0:c0 + g]
            out = buffer[:columns.shape[1]]
            centre = (columns.mean(axis=0) if mean is None else mean[c0:c0 + g])[:, None]
            for r in range(0, nperseg, rows):
                np.subtract(columns[r:r + rows].T, centre, out=out[:, r:r + rows])
            out *= window
            yield k, c0, rfft(out, axis=1, workers=-1)


def _half_sums(x: np.ndarray, step: int, n_segments: int) -> np.ndarray:
    """Column sums of each half-segment (``step`` rows), once: a segment's mean is that of its two halves."""
    return np.array([x[j * step:(j + 1) * step].sum(axis=0) for j in range(n_segments + 1)])


def _n_segments(n_samples: int, nperseg: int) -> int:
    return max(1, (n_samples - nperseg) // (nperseg // 2) + 1)


def ambient_overview(x: np.ndarray, sampling_rate: float, *, options: OverviewOptions | None = None,
                     floor_options: FloorOptions | None = None) -> Overview:
    """Overview of an ambient record: Welch PSD per channel (Hann, 50 % overlap).

    The combined spectrum's degrees of freedom are local: where a mode's
    response dominates, all channels carry the same random realisation and
    averaging them does not reduce the scatter. With S the floor-whitened
    cross-spectral matrix, the Satterthwaite count ν (tr S)² / tr(S²) (tr S²
    corrected for its Wishart bias) runs from ν (coherent) to C ν
    (independent noise).

    Memory: the spectra a Welch segment at a time, and the cross-spectral
    sums band by band of frequency (each band's DFTs recomputed: a few
    passes over a large record; the first band's are kept from the pass of
    the spectra), so that beside the record about half its size is held at
    most (or BLOCK_BYTES).

    `options`, `floor_options`: Welch segments and floors (default: the
    calibrated values).
    """
    nperseg = welch_length(x.shape[0], options)
    n_segments = _n_segments(x.shape[0], nperseg)
    window = signal.windows.hann(nperseg, sym=False)
    window_power = float(np.sum(window**2))
    budget = max(BLOCK_BYTES, x.nbytes // 8)
    halves = _half_sums(x, nperseg // 2, n_segments) if nperseg % 2 == 0 else None
    n_freq = nperseg // 2 + 1
    power = np.zeros((x.shape[1], n_freq))  # channels first, as the DFTs come
    first = np.empty((min(n_freq, _band_width(budget, n_segments, x.shape[1])), n_segments, x.shape[1]),
                     dtype=np.complex64)  # the first band of the cross-spectral sums, not yet whitened
    for k, c0, dft in _segment_dfts(x, nperseg, window, budget, halves):
        power[c0:c0 + dft.shape[0]] += np.abs(dft) ** 2
        first[:, k, c0:c0 + dft.shape[0]] = dft[:, :first.shape[0]].T
    psd = _one_sided(np.ascontiguousarray(power.T) / (n_segments * window_power * sampling_rate))
    del power
    frequency = np.arange(psd.shape[0]) * sampling_rate / nperseg
    # Equivalent degrees of freedom of Welch's average (Hann, 50 % overlap: correlation 0.167 between segments).
    rho2 = 0.167**2 if n_segments > 1 else 0.0
    dof = 2.0 * n_segments / (1.0 + 2.0 * rho2 * (1.0 - 1.0 / n_segments))
    floor = noise_floor(psd, dof, cell=2, options=floor_options)
    scale = 1.0 / np.sqrt(floor * (window_power * sampling_rate / 2.0))  # E|X|² of noise in a segment DFT
    trace, frobenius = np.empty(n_freq), np.empty(n_freq)
    first *= scale[:first.shape[0], None, :]
    _band_sums(first, 0, trace, frobenius)
    start = first.shape[0]
    del first
    _whitened_sums(x, nperseg, window, scale, budget, halves, trace, frobenius, start)
    combined_dof = _coherent_dof(trace, frobenius, dof, n_channels=x.shape[1])
    channel_dof = np.full(frequency.shape, dof)
    return _overview(frequency, psd, floor, dof, combined_dof, channel_dof, cell=2, random_ripple=True)


def _band_width(budget: int, n_segments: int, n_channels: int) -> int:
    """Bins per band of :func:`_whitened_sums`: the segment DFTs of all channels (complex64) in twice ``budget``."""
    return max(1, 2 * budget // (8 * n_segments * n_channels))


def _whitened_sums(x: np.ndarray, nperseg: int, window: np.ndarray, scale: np.ndarray, budget: int,
                   halves: np.ndarray | None, trace: np.ndarray, frobenius: np.ndarray, start: int = 0) -> None:
    """tr S and ‖S‖²_F of the bins from ``start`` on, into ``trace`` and ``frobenius``; S the floor-whitened
    cross-spectral matrix Σ_k w_k w_kᴴ / K, ``scale`` (n_freq, C) the whitening of each bin and channel.

    Over bands of frequency whose segment DFTs of all channels (complex64) fit in twice ``budget`` bytes:
    per band, the DFTs are recomputed and the band kept (:func:`ambient_overview` keeps the first band's
    from the pass of the spectra).
    """
    n_freq, n_channels = scale.shape
    n_segments = _n_segments(x.shape[0], nperseg)
    scale_t = np.ascontiguousarray(scale.T)  # channels first, as the DFTs come
    width = _band_width(budget, n_segments, n_channels)
    for lo in range(start, n_freq, width):
        hi = min(n_freq, lo + width)
        band = np.empty((hi - lo, n_segments, n_channels), dtype=np.complex64)  # (f, K, C)
        for k, c0, dft in _segment_dfts(x, nperseg, window, budget, halves):
            c1 = c0 + dft.shape[0]
            band[:, k, c0:c1] = (dft[:, lo:hi] * scale_t[c0:c1, lo:hi]).T
        _band_sums(band, lo, trace, frobenius)
        del band


def _band_sums(band: np.ndarray, lo: int, trace: np.ndarray, frobenius: np.ndarray) -> None:
    """tr S and ‖S‖²_F of the whitened segment DFTs ``band`` (f, K, C) of the bins from ``lo`` on: ‖S‖²_F from
    the C × C matrix or, when the segments are fewer than the channels, from the K × K Gram matrix of the
    segments (the same norm)."""
    _, n_segments, n_channels = band.shape
    for a in range(0, band.shape[0], 4096):  # the products in sub-bands: bounded temporaries
        w = band[a:a + 4096]
        if n_channels <= n_segments:
            product = w.conj().transpose(0, 2, 1) @ w  # (f, C, C) = K S
        else:
            product = w @ w.conj().transpose(0, 2, 1)  # (f, K, K): the same Frobenius norm
        rows = slice(lo + a, lo + a + w.shape[0])
        trace[rows] = np.sum(w.real.astype(float) ** 2 + w.imag.astype(float) ** 2, axis=(1, 2)) / n_segments
        frobenius[rows] = np.sum(product.real.astype(float) ** 2 + product.imag.astype(float) ** 2,
                                 axis=(1, 2)) / n_segments**2


def _coherent_dof(trace: np.ndarray, frobenius: np.ndarray, dof: float, n_channels: int) -> np.ndarray:
    """ν (tr S)² / tr(S²) per bin (see :func:`ambient_overview`), tr(S²) corrected for its Wishart bias."""
    effective = dof / 2.0
    square = np.maximum(frobenius - trace**2 / effective, trace**2 / n_channels)
    ratio = np.clip(trace**2 / square, 1.0, n_channels)
    return dof * ratio


def _overview(frequency, psd, floor, dof, combined_dof, channel_dof, cell, random_ripple) -> Overview:
    # Each channel is already divided by its own floor: the combined floor is 1 (a second floor estimate
    # would only add its scatter to the detection statistic).
    combined = (psd / floor).mean(axis=1)
    combined_floor = np.ones_like(combined)
    return Overview(
        frequency, psd, floor, combined, combined_floor, float(dof), combined_dof, channel_dof, int(cell), random_ripple
    )
