"""Spectral overview: per-channel spectra, noise floors, the combined spectrum and peak detection.

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
    Two statistics share a nominal false-alarm probability of 1e-4 per
    record (Bonferroni over the independent cells): the combined spectrum,
    and the largest single channel's spectrum over its floor (a mode seen
    by one channel of many is diluted C times in the mean). A candidate is
    a local maximum above floor × t, t the chi-squared quantile for the
    local degrees of freedom widened by the scatter of the floor estimate,
    with a prominence (height over the higher neighbouring valley) of t
    too. In ambient spectra, where the response itself scatters, the
    prominence must also beat the F quantile of the ratio of two spectrum
    values at 0.5 false bumps per record: ripple on skirts is kept down,
    and what passes is rejected by the fit (:mod:`.refine`). Of candidates
    not separated by a valley (in a running mean over half a peak width)
    down to the floor, or by the threshold below the weaker peak (ambient:
    or deeper than the ripple of that mean goes, F quantile at 1 %), only
    the one exceeding its threshold most is kept: one per resonance, even
    when ambient loading puts random ripple on it.

    Free decays are looked at in several resolutions
    (:func:`decay_overviews`, :func:`detect_multiresolution`): the
    whole-event periodogram, the same averaged over SMOOTHING cells (weak,
    heavily damped modes), and full-Hann windows over the first L samples
    of each event, L = N/4, N/16, … (modes decaying in a small part of the
    event; weak modes on the 1/f² skirts of strong ones). The false-alarm
    probability is shared equally among them, and a coarser overview adds
    a candidate only where the finer ones have none; the fit confirms it
    or it is dropped.

    Measured, 60 s at 256 Hz: a candidate in 0 of 400 white-noise and 0 of
    400 low-pass-noise records with one channel, 0 and 2 of 200 with
    three; no peak reported in 180 noise records (1, 3 and 16 channels,
    white and low-pass) once the fit has judged the candidates.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy import ndimage, signal, special
from scipy.fft import next_fast_len, rfft

from .events import Event
from .floor import floor_log_variance, noise_floor, ripple_dof

__all__ = [
    "Overview",
    "ambient_overview",
    "decay_overview",
    "decay_overviews",
    "detect_multiresolution",
    "detect_peaks",
    "noise_floor",
    "smoothed_overview",
]

FALSE_ALARM = 1e-4  # nominal, per record (measured rates in the module docstring)
DECAY_PADDING = 2
RIPPLE_DOF_CAP = 8  # free decays: local degrees of freedom at most 8 C ν
RIPPLE_FALSE_ALARM = 0.5  # per record: ripple bumps that pass the prominence test (the fit rejects them)
SEPARATION_PROBABILITY = 0.01  # a valley deeper than ripple makes with this probability separates two resonances
WELCH_SEGMENTS = 16
DECAY_WINDOW_RATIO = 4  # successive decay-matched windows are this much shorter
MIN_DECAY_WINDOW = 64  # samples, shortest decay-matched window
SMOOTHING = 4  # cells averaged in the smoothed overview


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
    x: np.ndarray, sampling_rate: float, events: list[Event], window_length: int | None = None
) -> Overview:
    """Overview of free decays: tapered, zero-padded periodograms averaged over events.

    By default each whole event under a right-half Hann taper. With
    `window_length`, a decay-matched overview instead: a full Hann window
    over the first `window_length` samples of each event (see
    :func:`decay_overviews`).
    """
    longest = max(e.n_samples for e in events) if window_length is None else int(window_length)
    n_fft = next_fast_len(DECAY_PADDING * longest, real=True)
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
    floor = noise_floor(psd, dof, cell)
    ratio = psd / floor
    high = RIPPLE_DOF_CAP * dof * psd.shape[1]
    combined_dof = ripple_dof(ratio.mean(axis=1), cell, dof, high)
    channel_dof = ripple_dof(ratio.max(axis=1), cell, dof, high)
    return _overview(frequency, psd, floor, dof, combined_dof, channel_dof, cell, random_ripple=False)


def decay_window_lengths(events: list[Event]) -> list[int]:
    """Lengths of the decay-matched windows: the longest event over 4, 16, … while at least MIN_DECAY_WINDOW samples."""
    longest = max(e.n_samples for e in events)
    lengths = []
    length = longest // DECAY_WINDOW_RATIO
    while length >= MIN_DECAY_WINDOW:
        lengths.append(int(length))
        length //= DECAY_WINDOW_RATIO
    return lengths


def decay_overviews(x: np.ndarray, sampling_rate: float, events: list[Event]) -> list[Overview]:
    """The whole-event overview, the same smoothed over frequency, then decay-matched ones.

    A mode that decays in a small part of the event is drowned, in the
    whole-event periodogram, by the noise of the long tail; and the
    abrupt start of the decays (kept by the right-half taper, which is what
    makes that overview sensitive) gives the strong modes skirts falling
    only as 1/f², on which a weak mode shows as a dip beside a bump, not a
    peak. A full Hann window over the first L samples of each event (L a
    few decay times; :func:`decay_window_lengths`) catches both. A weak,
    heavily damped mode spreads over many cells of the whole-event
    periodogram: averaged over SMOOTHING cells (:func:`smoothed_overview`),
    its peak keeps its height while the scatter falls.
    """
    main = decay_overview(x, sampling_rate, events)
    overviews = [main, smoothed_overview(main, SMOOTHING)]
    overviews += [decay_overview(x, sampling_rate, events, n) for n in decay_window_lengths(events)]
    return overviews


def smoothed_overview(overview: Overview, factor: int) -> Overview:
    """The overview's spectra averaged over `factor` resolution cells (a Daniell estimate), on a coarser grid.

    Running means over factor · cell bins, taken every half of that (two
    bins per new cell, the grid still starting at 0 Hz); the degrees of
    freedom grow `factor` times (neighbouring cells are nearly
    independent). The floor is the original one, averaged alike (the
    noise does not change; a floor estimated afresh on the coarse grid
    would span many resonances), and keeps its own scatter (``floor_dof``).
    """
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
        high = RIPPLE_DOF_CAP * dof * psd.shape[1]
        combined_dof = ripple_dof(ratio.mean(axis=1), cell, dof, high)
        channel_dof = ripple_dof(ratio.max(axis=1), cell, dof, high)
    combined = (psd / floor).mean(axis=1)
    return Overview(
        overview.frequency[centres], psd, floor, combined, np.ones_like(combined), float(dof), combined_dof,
        channel_dof, int(cell), overview.random_ripple, floor_dof=overview.floor_dof or overview.dof,
    )


def _one_sided(psd: np.ndarray) -> np.ndarray:
    psd = psd.copy()
    psd[1:-1] *= 2.0
    return psd


def welch_length(n_samples: int) -> int:
    """Segment length for the ambient Welch spectrum: a power of two near 2N/17 (about 16 segments)."""
    target = max(256, n_samples * 2 // (WELCH_SEGMENTS + 1))
    return int(min(n_samples, 2 ** int(np.round(np.log2(target)))))


def _welch_segments(x: np.ndarray, nperseg: int) -> tuple[np.ndarray, float]:
    """Hann-windowed, mean-removed segment DFTs (n_segments, n_freq, n_channels), 50 % overlap, and Σ window²."""
    step = nperseg // 2
    n_segments = max(1, (x.shape[0] - nperseg) // step + 1)
    window = signal.windows.hann(nperseg, sym=False)
    segments = np.lib.stride_tricks.sliding_window_view(x, nperseg, axis=0)[::step][:n_segments]  # (K, C, nperseg)
    segments = segments - segments.mean(axis=-1, keepdims=True)
    return rfft(segments * window, axis=-1, workers=-1).transpose(0, 2, 1), float(np.sum(window**2))


def ambient_overview(x: np.ndarray, sampling_rate: float) -> Overview:
    """Overview of an ambient record: Welch PSD per channel (Hann, 50 % overlap).

    The combined spectrum's degrees of freedom are local: where a mode's
    response dominates, all channels carry the same random realisation and
    averaging them does not reduce the scatter. With S the floor-whitened
    cross-spectral matrix, the Satterthwaite count ν (tr S)² / tr(S²) (tr S²
    corrected for its Wishart bias) runs from ν (coherent) to C ν
    (independent noise).
    """
    nperseg = welch_length(x.shape[0])
    spectra, window_power = _welch_segments(x, nperseg)
    n_segments = spectra.shape[0]
    psd = _one_sided((np.abs(spectra) ** 2).mean(axis=0) / (window_power * sampling_rate))
    frequency = np.arange(psd.shape[0]) * sampling_rate / nperseg
    # Equivalent degrees of freedom of Welch's average (Hann, 50 % overlap: correlation 0.167 between segments).
    rho2 = 0.167**2 if n_segments > 1 else 0.0
    dof = 2.0 * n_segments / (1.0 + 2.0 * rho2 * (1.0 - 1.0 / n_segments))
    floor = noise_floor(psd, dof, cell=2)
    combined_dof = _coherent_dof(spectra, floor, dof, window_power, sampling_rate)
    channel_dof = np.full(frequency.shape, dof)
    return _overview(frequency, psd, floor, dof, combined_dof, channel_dof, cell=2, random_ripple=True)


def _coherent_dof(spectra: np.ndarray, floor: np.ndarray, dof: float, window_power: float, fs: float) -> np.ndarray:
    """ν (tr S)² / tr(S²) per bin, S the floor-whitened cross-spectral matrix (see :func:`ambient_overview`)."""
    n_segments, _, n_channels = spectra.shape
    scale = 1.0 / np.sqrt(floor * window_power * fs / 2.0)  # E|X|² of noise in a segment DFT
    white = spectra * scale[None]
    stacked = white.transpose(1, 2, 0)  # (f, C, K)
    csd = stacked @ stacked.conj().transpose(0, 2, 1) / n_segments
    trace = np.real(np.trace(csd, axis1=1, axis2=2))
    frobenius = np.sum(np.abs(csd) ** 2, axis=(1, 2))
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


def detection_threshold(
    overview: Overview, n_cells: int, per_channel: bool = False, false_alarm: float = FALSE_ALARM
) -> np.ndarray:
    """Height over the floor (per bin) that pure noise exceeds somewhere with probability `false_alarm` / 2.

    For the mean over channels (``combined``), or with ``per_channel`` for
    the largest single channel (the probability shared among the channels).
    The statistic is Y / F: Y a chi-squared variable over its degrees of
    freedom d (``combined_dof``, or one channel's), F the estimated floor
    over the true one. log F is taken as normal with the variance of
    :func:`.floor.floor_log_variance`, divided by the number of channels
    whose floors average (d / dof), and the quantile is solved for over
    that spread (Gauss–Hermite quadrature). Tabulated on a grid of d and
    interpolated.
    """
    n_channels = overview.channel_spectra.shape[1]
    per_cell = 0.5 * false_alarm / max(n_cells, 1) / (n_channels if per_channel else 1)
    dof = overview.channel_dof if per_channel else overview.combined_dof
    grid = np.geomspace(dof.min(), dof.max(), 24) if dof.max() > dof.min() else dof[:1]
    floor_dof = overview.dof if overview.floor_dof is None else overview.floor_dof
    table = _threshold_with_floor_error(grid, overview.dof, per_cell, floor_dof)
    return np.interp(dof, grid, table) if grid.size > 1 else np.full(dof.shape, table[0])


def _threshold_with_floor_error(
    dof: np.ndarray, channel_dof: float, probability: float, floor_dof: float | None = None
) -> np.ndarray:
    """t with E_F[P(χ²_d / d > t F)] = probability for each d in `dof`, log F normal (see detection_threshold)."""
    floor_dof = channel_dof if floor_dof is None else floor_dof
    log_floor_var = floor_log_variance(floor_dof) / np.maximum(dof / channel_dof, 1.0)
    nodes, weights = np.polynomial.hermite_e.hermegauss(16)
    weights = weights / weights.sum()
    shifts = np.exp(np.sqrt(log_floor_var)[:, None] * nodes[None, :])  # (grid, nodes)

    def exceed(t):
        return np.sum(weights * special.chdtrc(dof[:, None], (t[:, None] * dof[:, None]) / shifts), axis=1)

    lo, hi = np.ones(dof.shape), np.ones(dof.shape)
    while np.any(low := exceed(hi) > probability):
        hi = np.where(low, 2.0 * hi, hi)
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        above = exceed(mid) > probability
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
    return hi


@dataclass(frozen=True, eq=False)
class Candidate:
    """A detected peak.

    Parameters
    ----------
    index : int
        Bin of the maximum.
    frequency : float
        Interpolated frequency, Hz.
    snr_db : float
        Height above the floor in the statistic that found it, dB.
    half_power_width : float
        -3 dB width above the floor, Hz.
    threshold : float
        That statistic's detection threshold at the peak (linear).
    dof : float
        That statistic's degrees of freedom at the peak.
    spectrum : ndarray (n_freq,)
        That statistic (spectrum / floor), shared, not copied.
    proposal : bool
        True for a candidate carried over from a coarser overview
        (:func:`detect_multiresolution`): those overviews are liberal, so
        it is reported only if its fit confirms a mode, never from the
        overview.
    """

    index: int
    frequency: float
    snr_db: float
    half_power_width: float
    threshold: float
    dof: float
    spectrum: np.ndarray = field(repr=False)
    proposal: bool = False

    @property
    def exceedance(self) -> float:
        """Height over the threshold, dB."""
        return self.snr_db - 10 * np.log10(self.threshold)


def detect_peaks(
    overview: Overview, f_min: float, f_max: float, min_snr_db: float | None = None, share: float = 1.0
) -> tuple[list[Candidate], np.ndarray]:
    """Peaks within [f_min, f_max] (see the module docstring).

    Two statistics share the false-alarm probability: the mean over
    channels of spectrum / floor (sensitive when all channels see a mode)
    and the largest single channel's (sensitive when only one does, where
    the mean would dilute it C times). `share` is the fraction of the
    record's false-alarm budgets (FALSE_ALARM, RIPPLE_FALSE_ALARM) given to
    this overview (:func:`detect_multiresolution` splits them).

    Returns
    -------
    candidates : list of Candidate
        In frequency order.
    threshold : ndarray (n_freq,)
        The height over the combined floor a peak of the mean had to reach.
    """
    f = overview.frequency
    df = f[1] - f[0]
    lo = max(int(np.ceil(f_min / df)), 3 * overview.cell)
    hi = min(int(np.floor(f_max / df)), f.size - 2)
    n_cells = max(hi - lo, 1) // overview.cell
    false_alarm = share * FALSE_ALARM
    statistics = [
        (
            overview.combined / overview.combined_floor,
            detection_threshold(overview, n_cells, false_alarm=false_alarm),
            overview.combined_dof,
        )
    ]
    if overview.channel_spectra.shape[1] > 1:
        largest = np.max(overview.channel_spectra / overview.channel_floor, axis=1)
        per_channel = detection_threshold(overview, n_cells, per_channel=True, false_alarm=false_alarm)
        statistics.append((largest, per_channel, overview.channel_dof))
    if min_snr_db is not None:
        statistics = [(r, np.maximum(t, 10 ** (min_snr_db / 10)), d) for r, t, d in statistics]
    if hi <= lo:
        return [], statistics[0][1]
    candidates = []
    for ratio, t, dof in statistics:
        index = _exceedances(overview, ratio, t, dof, lo, hi, n_cells / share)
        candidates += [_candidate(overview, ratio, int(k), t[k], dof[k]) for k in index]
    return _suppress_shoulders(overview, candidates), statistics[0][1]


def detect_multiresolution(
    overviews: list[Overview], f_min: float, f_max: float, min_snr_db: float | None = None
) -> tuple[list[Candidate], np.ndarray]:
    """Peaks of several overviews of one record (finest first), on the first one's frequency grid.

    Each overview gets an equal share of the false-alarm budgets
    (Bonferroni). A candidate of a coarser overview is added only where
    no candidate already kept lies within the half-power width of either
    (it is a resonance the finer overviews did not see), carried over to
    the first overview's nearest bin with its own frequency, height and
    width (its ``spectrum`` becomes the first overview's combined one).

    Returns
    -------
    candidates : list of Candidate
        In frequency order.
    threshold : ndarray (n_freq,)
        The first overview's threshold on the combined spectrum.
    """
    share = 1.0 / len(overviews)
    candidates, threshold = detect_peaks(overviews[0], f_min, f_max, min_snr_db, share)
    frequency = overviews[0].frequency
    combined = overviews[0].combined / overviews[0].combined_floor
    for overview in overviews[1:]:
        extra, _ = detect_peaks(overview, f_min, f_max, min_snr_db, share)
        for c in extra:
            if all(abs(c.frequency - k.frequency) > max(c.half_power_width, k.half_power_width) for k in candidates):
                index = int(np.argmin(np.abs(frequency - c.frequency)))
                candidates.append(replace(c, index=index, spectrum=combined, proposal=True))
    return sorted(candidates, key=lambda c: c.frequency), threshold


def _exceedances(overview: Overview, ratio, t, dof, lo: int, hi: int, n_cells: float) -> np.ndarray:
    """Local maxima of `ratio` in [lo, hi] above `t`, with a prominence of `t` (and the F quantile if random)."""
    log_ratio = np.log10(np.maximum(ratio, np.finfo(float).tiny))
    index, _ = signal.find_peaks(log_ratio, distance=max(1, overview.cell))
    index = index[(index >= lo) & (index <= hi)]
    index = index[ratio[index] >= t[index]]
    if index.size == 0:
        return index
    prominence = signal.peak_prominences(log_ratio, index)[0]
    needed = t[index]
    if overview.random_ripple:
        needed = np.maximum(needed, _f_isf(RIPPLE_FALSE_ALARM / max(n_cells, 1), dof[index]))
    return index[prominence >= np.log10(needed)]


def _f_isf(probability: float, dof):
    """Upper `probability` quantile of F(dof, dof), the ratio of two independent spectrum values.

    (special.fdtri directly: scipy.stats' distribution layer costs more than
    the quantile itself, and this is called for every pair of candidates.)
    """
    return special.fdtri(dof, dof, 1.0 - probability)


def _suppress_shoulders(overview: Overview, candidates: list[Candidate]) -> list[Candidate]:
    """Keep one candidate per resonance (see :func:`_separated`), the one that exceeds its threshold most."""
    kept: list[Candidate] = []
    for c in sorted(candidates, key=lambda c: c.exceedance, reverse=True):
        if all(_separated(overview, c, k) for k in kept):
            kept.append(c)
    return sorted(kept, key=lambda c: c.frequency)


def _separated(overview: Overview, weak: Candidate, strong: Candidate) -> bool:
    """Two candidates are two resonances if, between them, the smoothed spectrum falls to the floor, or
    below the weaker peak by the detection threshold (ambient: or by more than its ripple does, F quantile 1 %).

    The smoothing (a running mean over half the stronger peak's -3 dB
    width, at least 5 cells) keeps the random ripple on one resonance (its
    nulls, when ambient loading continues through a decay) from splitting it.
    """
    df = overview.frequency[1] - overview.frequency[0]
    if abs(weak.frequency - strong.frequency) <= 0.5 * strong.half_power_width:
        return False
    n = max(5 * overview.cell, round(0.5 * strong.half_power_width / df))
    lo, hi = sorted((weak.index, strong.index))
    a, b = max(0, lo - n), min(overview.combined.size, hi + n + 1)
    smooth = ndimage.uniform_filter1d(weak.spectrum[a:b], n, mode="nearest")
    valley = np.min(smooth[lo - a : hi - a + 1])
    depth = weak.threshold
    if overview.random_ripple:
        # Welch spectrum, degrees of freedom known: two values of its running mean differ by this factor with
        # probability SEPARATION_PROBABILITY. (For free decays the ripple of a random response under the decay
        # is not known inside a resonance: the threshold itself is the depth asked for.)
        dof = weak.dof * n / overview.cell
        depth = min(depth, float(_f_isf(SEPARATION_PROBABILITY, dof)))
    return bool(valley <= max(1.0, smooth[weak.index - a] / depth))


def _candidate(overview: Overview, ratio: np.ndarray, k: int, threshold: float, dof: float) -> Candidate:
    """Interpolated frequency (parabola through the log) and -3 dB width (above the floor, 1) of a peak of `ratio`."""
    f = overview.frequency
    df = f[1] - f[0]
    y = np.log(np.maximum(ratio[k - 1 : k + 2], np.finfo(float).tiny))
    denom = y[0] - 2 * y[1] + y[2]
    shift = 0.5 * (y[0] - y[2]) / denom if denom < 0 else 0.0
    # Width on a 5-cell running mean, so that ripple does not end it early.
    n = 5 * overview.cell
    lo, hi = max(0, k - 50 * n), min(f.size, k + 50 * n + 1)
    smooth = ndimage.uniform_filter1d(ratio[lo:hi], n, mode="nearest")
    centre = k - lo
    half = 1.0 + 0.5 * (smooth[centre] - 1.0)
    below = np.flatnonzero(smooth <= half)
    left = below[below < centre]
    right = below[below > centre]
    left = left[-1] if left.size else 0
    right = right[0] if right.size else smooth.size - 1
    snr = 10 * np.log10(ratio[k])
    frequency = float(f[k] + np.clip(shift, -0.5, 0.5) * df)
    return Candidate(k, frequency, float(snr), float((right - left) * df), float(threshold), float(dof), ratio)
