"""Peak detection in the spectral overviews (:mod:`.overview`).

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
    (:func:`.overview.decay_overviews`, :func:`detect_multiresolution`): the
    whole-event periodogram, the same averaged over a few cells (weak,
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

from .floor import floor_log_variance
from .options import DetectionOptions, FloorOptions
from .overview import Overview

__all__ = ["Candidate", "detect_multiresolution", "detect_peaks", "detection_threshold", "peak_candidate"]

# The probabilities (false alarm, ripple, separation) are :class:`.options.DetectionOptions`.


def detection_threshold(
    overview: Overview, n_cells: int, false_alarm: float, per_channel: bool = False, *,
    floor_options: FloorOptions | None = None,
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
    interpolated. `floor_options`: how the floor was estimated (default:
    the calibrated values).
    """
    n_channels = overview.channel_spectra.shape[1]
    per_cell = 0.5 * false_alarm / max(n_cells, 1) / (n_channels if per_channel else 1)
    dof = overview.channel_dof if per_channel else overview.combined_dof
    grid = np.geomspace(dof.min(), dof.max(), 24) if dof.max() > dof.min() else dof[:1]
    floor_dof = overview.dof if overview.floor_dof is None else overview.floor_dof
    table = _threshold_with_floor_error(grid, overview.dof, per_cell, floor_dof, floor_options)
    return np.interp(dof, grid, table) if grid.size > 1 else np.full(dof.shape, table[0])


def _threshold_with_floor_error(
    dof: np.ndarray, channel_dof: float, probability: float, floor_dof: float | None = None,
    floor_options: FloorOptions | None = None,
) -> np.ndarray:
    """t with E_F[P(χ²_d / d > t F)] = probability for each d in `dof`, log F normal (see detection_threshold)."""
    floor_dof = channel_dof if floor_dof is None else floor_dof
    log_floor_var = floor_log_variance(floor_dof, floor_options) / np.maximum(dof / channel_dof, 1.0)
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
        -3 dB width above the floor, Hz (on a side where a stronger
        resonance rises first, to the valley before it).
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
    overview: Overview, f_min: float, f_max: float, min_snr_db: float | None = None, share: float = 1.0, *,
    options: DetectionOptions | None = None, floor_options: FloorOptions | None = None,
) -> tuple[list[Candidate], np.ndarray]:
    """Peaks within [f_min, f_max] (see the module docstring).

    Two statistics share the false-alarm probability: the mean over
    channels of spectrum / floor (sensitive when all channels see a mode)
    and the largest single channel's (sensitive when only one does, where
    the mean would dilute it C times). `share` is the fraction of the
    record's false-alarm budgets (``options.false_alarm``,
    ``options.ripple_false_alarm``) given to this overview
    (:func:`detect_multiresolution` splits them). `options`,
    `floor_options`: default the calibrated values.

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
    options = DetectionOptions() if options is None else options
    false_alarm = share * options.false_alarm
    statistics = [
        (
            overview.combined / overview.combined_floor,
            detection_threshold(overview, n_cells, false_alarm, floor_options=floor_options),
            overview.combined_dof,
        )
    ]
    if overview.channel_spectra.shape[1] > 1:
        largest = np.max(overview.channel_spectra / overview.channel_floor, axis=1)
        per_channel = detection_threshold(overview, n_cells, false_alarm, per_channel=True,
                                          floor_options=floor_options)
        statistics.append((largest, per_channel, overview.channel_dof))
    if min_snr_db is not None:
        statistics = [(r, np.maximum(t, 10 ** (min_snr_db / 10)), d) for r, t, d in statistics]
    if hi <= lo:
        return [], statistics[0][1]
    candidates = []
    for ratio, t, dof in statistics:
        index = _exceedances(overview, ratio, t, dof, lo, hi, n_cells / share, options.ripple_false_alarm)
        candidates += [peak_candidate(overview, ratio, int(k), t[k], dof[k]) for k in index]
    return _suppress_shoulders(overview, candidates, options.separation_probability), statistics[0][1]


def detect_multiresolution(
    overviews: list[Overview], f_min: float, f_max: float, min_snr_db: float | None = None, *,
    options: DetectionOptions | None = None, floor_options: FloorOptions | None = None,
) -> tuple[list[Candidate], np.ndarray]:
    """Peaks of several overviews of one record (finest first), on the first one's frequency grid.

    Each overview gets an equal share of the false-alarm budgets
    (Bonferroni). A candidate of a coarser overview is added only where
    no candidate already kept lies within the half-power width of either
    (it is a resonance the finer overviews did not see), carried over to
    the first overview's nearest bin with its own frequency, height and
    width (its ``spectrum`` becomes the first overview's combined one).
    `options`, `floor_options`: as :func:`detect_peaks`.

    Returns
    -------
    candidates : list of Candidate
        In frequency order.
    threshold : ndarray (n_freq,)
        The first overview's threshold on the combined spectrum.
    """
    share = 1.0 / len(overviews)
    candidates, threshold = detect_peaks(overviews[0], f_min, f_max, min_snr_db, share, options=options,
                                         floor_options=floor_options)
    frequency = overviews[0].frequency
    combined = overviews[0].combined / overviews[0].combined_floor
    for overview in overviews[1:]:
        extra, _ = detect_peaks(overview, f_min, f_max, min_snr_db, share, options=options,
                                floor_options=floor_options)
        for c in extra:
            if all(abs(c.frequency - k.frequency) > max(c.half_power_width, k.half_power_width) for k in candidates):
                index = int(np.argmin(np.abs(frequency - c.frequency)))
                candidates.append(replace(c, index=index, spectrum=combined, proposal=True))
    return sorted(candidates, key=lambda c: c.frequency), threshold


def _exceedances(overview: Overview, ratio, t, dof, lo: int, hi: int, n_cells: float,
                 ripple_false_alarm: float) -> np.ndarray:
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
        needed = np.maximum(needed, _f_isf(ripple_false_alarm / max(n_cells, 1), dof[index]))
    return index[prominence >= np.log10(needed)]


def _f_isf(probability: float, dof):
    """Upper `probability` quantile of F(dof, dof), the ratio of two independent spectrum values.

    (special.fdtri directly: scipy.stats' distribution layer costs more than
    the quantile itself, and this is called for every pair of candidates.)
    """
    return special.fdtri(dof, dof, 1.0 - probability)


def _suppress_shoulders(overview: Overview, candidates: list[Candidate],
                        separation_probability: float) -> list[Candidate]:
    """Keep one candidate per resonance (see :func:`_separated`), the one that exceeds its threshold most."""
    kept: list[Candidate] = []
    for c in sorted(candidates, key=lambda c: c.exceedance, reverse=True):
        if all(_separated(overview, c, k, separation_probability) for k in kept):
            kept.append(c)
    return sorted(kept, key=lambda c: c.frequency)


def _separated(overview: Overview, weak: Candidate, strong: Candidate, separation_probability: float) -> bool:
    """Two candidates are two resonances if, between them, the smoothed spectrum falls to the floor, or
    below the weaker peak by the detection threshold (ambient: or by more than its ripple does, upper F
    quantile at `separation_probability`).

    The smoothing (a running mean over half the stronger peak's -3 dB
    width, at least 5 cells) keeps the random ripple on one resonance (its
    nulls, when ambient loading continues through a decay) from splitting it.
    """
    df = overview.frequency[1] - overview.frequency[0]
    lo, hi = sorted((weak.index, strong.index))
    # An ambient overview averaged over many segments (a short record's coarse one) barely ripples: where its own
    # valley between the two falls to the floor, they are two resonances, whatever the width taken on a running
    # mean over 5 cells (a Hz or more there, which merged modes a Hz apart into one and suppressed all but the
    # strongest as its shoulders: 1 of 3 equal modes 1.16 Hz apart found on 60-s records).
    if (overview.random_ripple and weak.dof >= SMOOTH_DOF and hi - lo >= 3 * overview.cell
            and np.min(weak.spectrum[lo : hi + 1]) <= max(1.0, weak.spectrum[weak.index] / weak.threshold)):
        return True
    if abs(weak.frequency - strong.frequency) <= 0.5 * strong.half_power_width:
        return False
    n = max(5 * overview.cell, round(0.5 * strong.half_power_width / df))
    a, b = max(0, lo - n), min(overview.combined.size, hi + n + 1)
    smooth = ndimage.uniform_filter1d(weak.spectrum[a:b], n, mode="nearest")
    valley = np.min(smooth[lo - a : hi - a + 1])
    depth = weak.threshold
    if overview.random_ripple:
        # Welch spectrum, degrees of freedom known: two values of its running mean differ by this factor with
        # probability separation_probability. (For free decays the ripple of a random response under the decay
        # is not known inside a resonance: the threshold itself is the depth asked for.)
        dof = weak.dof * n / overview.cell
        depth = min(depth, float(_f_isf(separation_probability, dof)))
    return bool(valley <= max(1.0, smooth[weak.index - a] / depth))


def peak_candidate(overview: Overview, ratio: np.ndarray, k: int, threshold: float, dof: float) -> Candidate:
    """The :class:`Candidate` at index ``k`` of ``ratio`` (spectrum over floor): interpolated frequency
    (parabola through the log) and -3 dB width (above the floor, 1); shared with the residual pass
    (:mod:`.residual`), which finds peaks the same way.

    Each side of the width ends where the running mean falls to half power,
    or, where it climbs first above the peak's own height (into a stronger
    resonance beside it), at the valley between the two: that side's extent
    is all this resonance shows. Without that stop, a peak on the skirt of a
    stronger one took the width of the whole run of resonances (the mode 7
    of seed 100 of tests/test_spectra_acceptance.py, seen best by one
    channel whose spectrum stays above the half-power level down to mode 1:
    7.32 Hz for 0.78, which then hid mode 8 from detection, refinement and
    the residual pass)."""
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
    height = max(ratio[k], smooth[centre])  # the running mean can top a narrow maximum on a broad one
    left = _half_power_edge(smooth[centre::-1], half, height)
    right = _half_power_edge(smooth[centre:], half, height)
    left, right = centre - left, centre + right
    snr = 10 * np.log10(ratio[k])
    frequency = float(f[k] + np.clip(shift, -0.5, 0.5) * df)
    return Candidate(k, frequency, float(snr), float((right - left) * df), float(threshold), float(dof), ratio)


def _half_power_edge(side: np.ndarray, half: float, height: float) -> int:
    """Bins from the peak (``side[0]``) to the first at or below `half`, or to the lowest before `side` first
    exceeds `height` (a stronger resonance beside the peak); at least one bin, as a crossing is; the side's
    last bin if neither."""
    above = np.flatnonzero(side > height)
    stop = above[0] if above.size else side.size
    below = np.flatnonzero(side[1:stop] <= half)
    if below.size:
        return int(below[0]) + 1
    if above.size:
        return int(np.argmin(side[1:stop])) + 1 if stop > 1 else 1
    return side.size - 1


#: Degrees of freedom of the overview at a weaker peak from which the raw valley between it and a stronger one
#: tells them apart (:func:`_separated`): the relative ripple of a spectrum averaged over dof/2 segments is
#: about √(2/dof), 30 % at 20.
SMOOTH_DOF = 20.0

#: A detected peak within this share of the local spacing of the expected modes stands for the expected mode.
EXPECTED_MATCH = 0.3
#: An expected mode with no detected peak is proposed at the overview's highest bin within this share of the
#: local spacing of it.
EXPECTED_REACH = 0.25


def expected_proposals(overview: Overview, threshold: np.ndarray, expected: np.ndarray, detected: list[Candidate],
                       f_min: float, f_max: float) -> list[Candidate]:
    """Proposals where a model expects a mode and no peak was detected (``find_peaks(expected=...)``).

    On a short record the overview is coarse and noisy, and most of a long cable's modes stay below the
    detection threshold (a 60-s record of a 120 m stay: 4 of its 19 modes). A detected mode's fit band (eight
    half-power widths, ±1.7 Hz for ζ 1 % at 10 Hz) then holds the undetected modes beside it, and the one pole
    fitted there lands between them with a 1σ that knows nothing of them (10.411 ± 0.035 Hz for modes at 9.600
    and 10.566 Hz). A proposal at each expected mode gives every fit its neighbours as poles and the band its
    limit between them; like the coarser overviews' proposals, each is reported only if its own fit confirms a
    mode. Without a detected peak nothing is proposed: the record shows no cable to fit.
    """
    e = np.sort(np.asarray(expected, dtype=float))
    if not detected or e.size == 0:
        return []
    f = overview.frequency
    ratio = overview.combined / overview.combined_floor
    gaps = np.diff(e)
    spacing = np.minimum(np.append(gaps, np.inf), np.insert(gaps, 0, np.inf)) if e.size > 1 else e.copy()
    out: list[Candidate] = []
    for fe, gap in zip(e, spacing):
        if not (f_min <= fe <= f_max) or any(abs(c.frequency - fe) < EXPECTED_MATCH * gap for c in detected):
            continue
        near = np.flatnonzero(np.abs(f - fe) <= EXPECTED_REACH * gap)
        near = near[(near >= 1) & (near <= f.size - 2)]
        if near.size == 0:
            continue
        k = int(near[np.argmax(ratio[near])])
        out.append(replace(peak_candidate(overview, ratio, k, float(threshold[k]), float(overview.combined_dof[k])),
                           proposal=True))
    return out
