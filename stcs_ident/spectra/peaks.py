"""Modal frequencies of a multi-channel acceleration record: detection, sub-bin refinement, uncertainty.

:func:`find_peaks` turns a :class:`~stcs_ident.core.record.Record` into a
:class:`PeakResult`: the peaks, each with a frequency, an honest 1σ, the
damping ratio, the channels that saw it and its amplitude per channel.

Steps
    1. Kind. Blows are looked for (:mod:`.events`); a record with at least
       one is a hand-excitation record, one with none is ambient.
    2. Overview (:mod:`.overview`): per-channel spectra (per-event tapered
       periodograms for free decays, Welch for ambient), each divided by
       its noise floor and averaged over channels; peaks are detected
       against a chi-squared threshold at a nominal false-alarm probability
       of 1e-4 per record, so a mode at a node of one sensor is found
       through the others and pure noise gives nothing. Free decays are
       also looked at smoothed over frequency and through decay-matched
       (shorter) windows; what those add only their fits can confirm.
    3. Refinement (:mod:`.refine`), one peak at a time, on the DFT bins of
       a band around it: free decays by a variable-projection least-squares
       fit of a common pole to all channels and events (:mod:`.decay_fit`);
       ambient records by the debiased Whittle likelihood of the modal
       coordinate (:mod:`.ambient_fit`). Where the decay-fit residual (or its
       forced ratio) shows a random response under the peak (ambient loading
       continuing through the decay), the decay fit's 1σ allows for it (the band noise is the
       sensor floor plus the mode's own forced response, coloured and
       common to all channels: :mod:`.decay_fit`), and the Whittle fit of
       the whole record is taken instead when its 1σ is smaller or the
       forced response outweighs the decay in the band (the blows are then
       too weak for the decay model), or where the decay fit does not decay
       while the record's peak is ten times broader (a fit to one noise bin
       of the random response). With several blows, their disagreement
       beyond their noise widens the 1σ, mode by mode and pooled over all
       modes (a tension wander moves them together: :mod:`.wander`), since
       the frequency sought is the record's mean. Both are maximum likelihood on the
       band; the 1σ comes from the information of the fit under its noise
       model. Detections whose fit is not a significant, lightly
       damped mode are dropped (the overview may propose a few: on the
       smooth skirts of free decays it is deliberately liberal).
       Ambient records then get a residual pass (:mod:`.residual`): the
       Welch spectrum is tested against the expected spectra of the
       fitted modes plus the noise, and what they leave unexplained is
       proposed and fitted with the others (a weak mode between broad
       resonances, too little prominent to be detected, whose neighbour's
       fit would otherwise absorb it).
    4. Mains hum: a fitted line with ζ < 5e-4 within 0.2 % of a harmonic
       of 50 or 60 Hz is not reported (:func:`.peak_filters.is_mains_hum`).
    5. Channels: those where the peak stands at least 6 dB above the
       channel's own noise floor (free decay: the fitted mode's peak power
       per bin over the noise per bin, plus one; ambient: the Welch
       spectrum over its floor at the fitted frequency).

Why a parametric fit (measured; seeded simulations, /tmp benchmarks)
    Free decays, 3 channels at 5, 10 and 13.3 m of 20 m, modes 3.1 / 6.25 /
    9.4 Hz, ζ = 0.5 %, 30 s at 256 Hz, 40 records per SNR (A²/2s² of a
    unit mode); median |error| / Cramér–Rao σ (:mod:`.crb`; an efficient
    estimator gives 0.67):

    ==================================================  ======  ======  ======
    estimator                                           20 dB   30 dB   40 dB
    ==================================================  ======  ======  ======
    variable-projection fit (kept)                      0.77    0.75    0.81
    parabola on the 8× zero-padded periodogram          1.5     2.1     6.6
    parabola on the tapered overview spectrum           7.8     27      92
    ==================================================  ======  ======  ======

    The interpolated DFTs are biased (by the decay's line shape and the
    taper), so their error grows relative to the bound as the SNR rises;
    the fit stays at it (the 10–20 % above 0.67 is the price of the
    background terms). Its reported 1σ is honest: std(error / 1σ) = 1.07,
    0.99, 0.95. The short stiff hanger of the tests (8 modes, 7.5–141 Hz,
    ζ = 0.3 %, 2 % noise) gives relative errors near 1e-6, with one blow or
    five overlapping ones.

    Ambient, the same 3 channels, 4 modes 2–8.2 Hz, noise rms 30 % of the
    signal, 30 records per case (ζ = 1 % 600 s; 0.5 % 300 s; 2 % 600 s;
    0.3 % 120 s): std(error / 1σ) of the frequency 1.00, 1.13, 0.99, 1.03
    and of ζ 0.98, 0.97, 0.97, 0.97; median |error| of ζ 6, 11, 5, 22 %.
    Interpolating the Welch peak gives median errors of 1.8, 1.1, 2.3, 0.7
    Whittle σ, against 0.65, 0.84, 0.66, 0.75 for the Whittle fit (and no
    1σ, no damping). A blow on the hanger with random loading underneath
    (white force of 0.003–0.03 of the blow's per sample; at the top the blow
    is no longer found and the record is ambient): std(error / 1σ)
    0.8–1.1, no missed or extra mode in 36 records.

    On the 105 records of tests/test_spectra_acceptance.py (the project's
    simulator; three cables, 1–5 sensors, ζ 0.1–2 %, 0–40 dB): median
    |error| / CRB 1.21 over 277 free-decay modes; none of 722 visible
    modes missed (was 9 with the whole-event overview alone and the
    0.45-gap bands, 2 without the residual pass: in an ambient record of
    the stay with ζ ≈ 1.8 %, a mode whose peak rises too little above the
    valley beside it in a band filled with broad resonances, and its
    neighbour, whose fit then absorbed it). The counts are of the simulator's
    records since its wind is the same on every machine (before: 725 visible
    modes on this machine's BLAS).

    Time (this 2-core machine): 16 channels × 600 s × 256 Hz with 20 modes,
    ambient 0.6–0.8 s, ten blows 0.8–0.9 s.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
from scipy import fft

from ..core.errors import InputError
from ..core.record import Record, check_finite
from .ambient_fit import AmbientFit, fit_ambient, widen_to_spread
from .decay_fit import DecayFit, event_spectra, fit_decay
from .detection import Candidate, detect_multiresolution, expected_proposals
from .events import Event, detect_events, whole_record_event
from .options import DecayCheckOptions, PickingOptions
from .overview import Overview, ambient_overview, decay_overviews
from .peak_filters import at_mains_harmonic, deduplicate, is_mains_hum
from .peak_result import Peak, PeakResult
from .refine import refine
from .residual import residual_candidates
from .two_poles import second_resonance
from .wander import common_wander, with_common_wander

__all__ = ["Peak", "PeakResult", "PickingOptions", "find_peaks", "is_mains_hum"]

# Every value that changes what is reported is in :class:`.options.PickingOptions`, recorded in the result.
KINDS = ("auto", "impulse", "ambient")


def find_peaks(
    record: Record,
    f_min: float | None = None,
    f_max: float | None = None,
    *,
    kind: str = "auto",
    max_peaks: int | None = None,
    min_snr_db: float | None = None,
    overwrite: bool = False,
    options: PickingOptions | None = None,
    expected=None,
) -> PeakResult:
    """Modal frequencies present in a record, with 1σ uncertainty, damping and the channels that saw them.

    Parameters
    ----------
    record : Record
        Acceleration, (n_samples, n_channels), m/s².
    f_min, f_max : float, optional
        Band searched for peaks, Hz (default 0 … 0.45 · sampling rate).
    kind : {"auto", "impulse", "ambient"}
        "auto" looks for impulses and treats the record as ambient if there
        are none; "impulse" with none found uses the decay from the most
        energetic instant to the end.
    max_peaks : int, optional
        Keep only the strongest peaks (by height above the floor).
    min_snr_db : float, optional
        Raise the detection threshold to this height above the floor, dB
        (it is never lowered below the false-alarm threshold).
    overwrite : bool
        Remove each channel's mean from ``record.acceleration`` in place
        instead of from a copy (as scipy's ``overwrite_x``): for a caller
        that read the record itself and needs no second copy of it in
        memory. The record then holds the mean-removed acceleration.
    options : PickingOptions, optional
        The tuning of every step (default: the calibrated values); recorded
        in the result.
    expected : sequence of float, optional
        Frequencies (Hz) where a model expects modes (the cable's nominal
        family). On an ambient record, an expected mode with no detected peak
        near it is proposed where the overview is highest around it, and
        reported only if its fit confirms a mode
        (:func:`.detection.expected_proposals`): on a short record most modes
        are below the detection threshold, and a detected mode's fit band
        would otherwise hold them unmodelled.

    Returns
    -------
    PeakResult

    Raises
    ------
    InputError
        For a bad argument (the message names it) or a non-finite record.
    """
    fs = record.sampling_rate
    if options is None:
        options = PickingOptions()
    elif not isinstance(options, PickingOptions):
        raise InputError(f"must be a PickingOptions, got {options!r}", field="options")
    f_lo, f_hi = _check_arguments(record, f_min, f_max, kind, max_peaks, min_snr_db)
    expected = None if expected is None else _expected(expected)
    x = record.acceleration
    if overwrite and x.flags.writeable:
        x -= x.mean(axis=0)
    else:
        x = x - x.mean(axis=0)
    events: list[Event] = [] if kind == "ambient" else detect_events(x, fs, options.events)
    if kind == "impulse" and not events:
        events = [whole_record_event(x, fs, options.events)]
    spectral = {"options": options.overview, "floor_options": options.floor}
    overviews = decay_overviews(x, fs, events, **spectral) if events else [ambient_overview(x, fs, **spectral)]
    overview = overviews[0]
    candidates, threshold = detect_multiresolution(overviews, f_lo, f_hi, min_snr_db, options=options.detection,
                                                   floor_options=options.floor)
    if expected is not None and not events:
        candidates = sorted(candidates + expected_proposals(overview, threshold, expected, candidates, f_lo, f_hi),
                            key=lambda c: c.frequency)
    refine = _refine_decays if events else _refine_ambient
    peaks = refine(x, fs, events, overview, candidates, record.channel_names, (f_lo, f_hi), options)
    peaks = deduplicate(peaks, options.filters)
    peaks = [p for p in peaks if not is_mains_hum(p, options.filters)]
    if max_peaks is not None and len(peaks) > max_peaks:
        # After the fits: the overview's strongest candidates may include some that are not modes.
        strongest = sorted(peaks, key=lambda p: p.snr_db, reverse=True)[:max_peaks]
        peaks = sorted(strongest, key=lambda p: p.frequency)
    return PeakResult(
        peaks=peaks,
        kind="impulse" if events else "ambient",
        events=[(e.start / fs, e.stop / fs) for e in events],
        frequency_axis=overview.frequency,
        combined_spectrum=overview.combined,
        combined_floor=overview.combined_floor,
        channel_spectra=overview.channel_spectra,
        channel_floor=overview.channel_floor,
        channel_names=record.channel_names,
        threshold=threshold,
        options=options,
    )


def _check_arguments(record, f_min, f_max, kind, max_peaks, min_snr_db) -> tuple[float, float]:
    fs = record.sampling_rate
    if kind not in KINDS:
        raise InputError(f"must be one of {', '.join(KINDS)}, got {kind!r}", field="kind")
    check_finite(record.acceleration, record.channel_names, record.source)  # a Record built in code: not read
    if record.n_samples < 256:
        raise InputError(f"needs at least 256 samples, has {record.n_samples}", field="acceleration")
    f_lo = 0.0 if f_min is None else float(f_min)
    f_hi = 0.45 * fs if f_max is None else float(f_max)
    if not (np.isfinite(f_lo) and f_lo >= 0):
        raise InputError(f"must be >= 0, got {f_min!r}", field="f_min")
    if not (np.isfinite(f_hi) and f_hi <= 0.5 * fs):
        raise InputError(f"must be <= the Nyquist frequency {0.5 * fs:g} Hz, got {f_max!r}", field="f_max")
    if f_hi <= f_lo:
        raise InputError(f"must be > f_min = {f_lo:g} Hz, got {f_hi:g}", field="f_max")
    if max_peaks is not None and (int(max_peaks) != max_peaks or max_peaks < 1):
        raise InputError(f"must be a positive integer, got {max_peaks!r}", field="max_peaks")
    if min_snr_db is not None and not np.isfinite(min_snr_db):
        raise InputError(f"must be finite, got {min_snr_db!r}", field="min_snr_db")
    return f_lo, f_hi


def _expected(expected) -> np.ndarray:
    e = np.asarray(expected, dtype=float).ravel()
    if not np.all(np.isfinite(e) & (e > 0)):
        raise InputError(f"must be positive finite frequencies, got {expected!r}", field="expected")
    return e


def _refine_decays(x, fs, events, overview: Overview, candidates, names, band, options: PickingOptions) -> list[Peak]:
    spectra = event_spectra(x, [(e.start, e.stop) for e in events])
    resolution = 1.0 / (max(e.n_samples for e in events) / fs)
    whittle = _whittle_band(x, fs, overview, options)
    check = options.decay_check
    max_damping = 2 * options.refine.max_damping

    def fit_band(f0, half_width, poles, peak_width):
        fit = fit_decay(spectra, fs, f0, half_width, poles, max_damping=max_damping, options=options.fit)
        if fit is not None and (fit.residual_excess > check.max_residual_excess or fit.damping < check.narrow_damping
                                or fit.forced_ratio > check.max_forced_ratio):
            # A random response under the decay: the decay fit's 1σ allows for it (decay_fit's noise model);
            # a forced ratio beyond max_forced_ratio alone calls for the comparison too (a weak blow under
            # wind, calibrate_damping hum stay seed 1 #4, mode 4: a decay fit of ζ 0.0012 ± 0.0004 with
            # forced ratio 0.5 and residual excess 1.5 stood for a mode of ζ 0.0145, z = −30);
            # the stationary model of the whole record is kept where it pins the mode down better, and where
            # the decay fit is far narrower than the record's peak: a pole that does not decay, fitted to
            # one noise bin of a random response (a blow at the mode's node leaves nothing else to fit;
            # calibrate_spectra hum60 stay seed 7 #10, mode 3: ζ 5e-5 for 0.0085, z = 76).
            other = whittle(f0, half_width, poles, peak_width)
            if _sound(other, half_width, check) and (
                other.frequency_std < fit.frequency_std
                or fit.forced_ratio > check.max_forced_ratio
                or fit.damping * check.broader_peak < other.damping
            ):
                return other
        return fit

    calls: dict[int, tuple] = {}

    def fit_band_noted(f0, half_width, poles, peak_width):
        fit = fit_band(f0, half_width, poles, peak_width)
        calls[id(fit)] = (f0, half_width, poles)
        return fit

    cell_width = overview.cell * (overview.frequency[1] - overview.frequency[0])
    fitted = refine(candidates, fit_band_noted, resolution, options.refine.band_min_bins * resolution, 0.5 * fs,
                    cell_width, options=options.refine)
    fitted, widened = _without_lines(fitted, calls, lambda f0, hw, poles, zeta: fit_decay(
        spectra, fs, f0, hw, poles, max_damping=max_damping, min_damping=zeta, options=options.fit), options)
    # The events' common offset, pooled over modes (a tension wander moves them all; wander.common_wander).
    decays = [fit for _, fit in fitted if isinstance(fit, DecayFit)]
    tau2 = common_wander([(f.frequency, f.event_frequencies, f.event_variances) for f in decays],
                         options.fit.heterogeneity_level)
    snr_db = options.filters.channel_snr_db
    peaks = []
    for c, fit in fitted:
        if fit is None:
            peaks.append(_overview_peak(c, overview, names, snr_db))
        elif isinstance(fit, AmbientFit):
            peaks.append(_ambient_peak(c, widen_to_spread(fit), overview, names, snr_db))
        else:
            std = with_common_wander(fit.frequency_std, fit.frequency, fit.event_variances, tau2)
            peak = _decay_peak(c, replace(fit, frequency_std=std), names, snr_db)
            peaks.append(replace(peak, damping=None, damping_uncertainty=None) if id(fit) in widened else peak)
    return peaks


def _without_lines(fitted: list, calls: dict, refit: Callable,
                   options: PickingOptions | None = None) -> tuple[list, set]:
    """Decay fits that do not decay, among modes that do: refitted, or kept with the 1σ of the mode's own width.

    A pole ten times (``decay_check.broader_peak``) narrower than the
    record's other modes and below ``decay_check.narrow_damping``, which
    the record's Whittle fit could not replace, is a
    fit to one noise bin of the mode's random response (a blow at the
    mode's node under wind: calibrate_spectra seed 11, four stay modes with
    ζ 1e-5–2e-4 among modes of 0.5–1 %, z = 5–64). A cable's damping
    changes gradually from mode to mode; hum, the one undamped line a
    record holds, is left to be recognised and removed afterwards. The
    mode is refitted with ζ at least a third of the modes' median; where
    that fails (no decay to fit), it is kept where the fit put it with a
    1σ of ζ_median · f: the random response's maximum lies anywhere
    within about half the mode's half-power band. Returns the pairs and
    the ids of the fits so widened (their damping is not known).
    `options`: default the calibrated values.
    """
    options = PickingOptions() if options is None else options
    check = options.decay_check
    zetas = [fit.damping for _, fit in fitted if isinstance(fit, DecayFit)]
    if len(zetas) < 3:
        return fitted, set()
    median = float(np.median(zetas))
    out, widened = [], set()
    for c, fit in fitted:
        narrow = isinstance(fit, DecayFit) and fit.damping < min(check.narrow_damping, median / check.broader_peak)
        if narrow and id(fit) in calls and not at_mains_harmonic(fit.frequency, options.filters):
            other = refit(*calls[id(fit)], 3.0 * median / check.broader_peak)
            if other is not None and other.converged:
                fit = other
            else:
                fit = replace(fit, frequency_std=max(fit.frequency_std, median * fit.frequency))
                widened.add(id(fit))
        out.append((c, fit))
    return out, widened


def _sound(fit: AmbientFit | None, half_width: float, options: DecayCheckOptions | None = None) -> bool:
    """A converged Whittle fit that locates its mode: 1σ within a quarter (``options.whittle_max_std``) of the
    band's half-width.

    A pole narrower than the record resolves (ζ at its lower bound, its
    damping ratio NaN: :data:`.ambient_fit.UNRESOLVED_BINS`) is no estimate
    of a mode that a decay fit describes: the Whittle likelihood is flat in
    frequency there (its information degenerate; its 1σ is the resolution
    cell's).
    """
    options = DecayCheckOptions() if options is None else options
    return fit is not None and fit.converged and bool(np.isfinite(fit.frequency_std) and np.isfinite(fit.damping)) and (
        fit.frequency_std <= options.whittle_max_std * half_width
    )


def _decay_peak(c: Candidate, fit: DecayFit, names, channel_snr_db: float) -> Peak:
    strongest = int(np.argmax((np.abs(fit.amplitude) ** 2).sum(axis=1)))
    return Peak(
        frequency=fit.frequency,
        uncertainty=fit.frequency_std,
        damping=fit.damping,
        damping_uncertainty=fit.damping_std,
        channels=_channels(fit.channel_snr_db, names, channel_snr_db),
        amplitude=_signed(fit.amplitude[strongest]),
        snr_db=c.snr_db,
        channel_snr_db=fit.channel_snr_db,
    )


def _ambient_peak(c: Candidate, fit: AmbientFit, overview: Overview, names, channel_snr_db: float) -> Peak:
    snr = _channel_ratio_db(overview, fit.frequency)
    return Peak(
        frequency=fit.frequency,
        uncertainty=fit.frequency_std,
        damping=fit.damping if np.isfinite(fit.damping) else None,  # NaN: narrower than the record resolves
        damping_uncertainty=fit.damping_std if np.isfinite(fit.damping) else None,
        channels=_channels(snr, names, channel_snr_db),
        amplitude=fit.amplitude,
        snr_db=c.snr_db,
        channel_snr_db=snr,
        misfit=fit.misfit,
    )


def _record_dft(x: np.ndarray) -> np.ndarray:
    """The whole record's DFT / √n, (n // 2 + 1, n_channels), a channel at a time, kept in complex64: half
    the record's float64 size (its rounding, 6e-8 relative, is far below the noise of any bin)."""
    n = x.shape[0]
    out = np.empty((n // 2 + 1, x.shape[1]), dtype=np.complex64)
    for c in range(x.shape[1]):
        out[:, c] = fft.rfft(x[:, c], workers=-1) / np.sqrt(n)
    return out


def _whittle_band(x: np.ndarray, fs: float, overview: Overview, options: PickingOptions) -> Callable:
    """A band fitter using the debiased Whittle likelihood of the whole record (DFT computed once, on demand)."""
    n = x.shape[0]
    cache: dict = {}
    max_damping = 2 * options.refine.max_damping

    def fit_band(f0, half_width, poles, peak_width):
        if "dft" not in cache:
            cache["dft"] = _record_dft(x)
        # Noise variance per DFT bin = one-sided PSD · fs / 2 (only the ratios between channels matter).
        floor = np.array([np.interp(f0, overview.frequency, col) for col in overview.channel_floor.T])
        noise_scale = np.sqrt(floor * fs / 2.0)
        return fit_ambient(cache["dft"], n, fs, f0, half_width, noise_scale, poles, peak_width=peak_width,
                           max_damping=max_damping, options=options.fit, spread=False)

    return fit_band


def _refine_ambient(x, fs, events, overview: Overview, candidates, names, band, options: PickingOptions) -> list[Peak]:
    """Whittle fits of the candidates, then of what the fitted modes leave unexplained (:mod:`.residual`)."""
    resolution = overview.frequency[1] - overview.frequency[0]
    fit_band = _whittle_band(x, fs, overview, options)
    cache: dict = {}
    min_half_width = options.refine.band_min_welch_bins * resolution

    def fitted(candidates):
        return refine(
            candidates, fit_band, 1.5 * resolution, min_half_width, 0.5 * fs, resolution, cache, options.refine
        )

    pairs = fitted(candidates)
    modes = [(fit.frequency, fit.decay_rate, fit.amplitude) for _, fit in pairs if fit is not None]
    extra = residual_candidates(overview, fs, modes, candidates, *band, options=options.residual,
                                detection_options=options.detection, floor_options=options.floor)
    if extra:
        pairs = fitted(sorted([c for c, _ in pairs] + extra, key=lambda c: c.frequency))
    # The kept fits' 1σ widened to the profile likelihood's spread (.profile): only theirs, since the profile
    # costs several fits' time and refine's decisions need the pole alone.
    snr_db = options.filters.channel_snr_db
    peaks = []
    for c, fit in pairs:
        if fit is None:
            peaks.append(_overview_peak(c, overview, names, snr_db))
        else:  # a kept fit that misfits its band is tested for a second resonance in it (.two_poles)
            peaks.append(replace(_ambient_peak(c, widen_to_spread(fit), overview, names, snr_db),
                                 second_pole=second_resonance(fit)))
    return peaks


def _channel_ratio_db(overview: Overview, frequency: float) -> np.ndarray:
    ratio = overview.channel_spectra / overview.channel_floor
    return 10 * np.log10(np.array([np.interp(frequency, overview.frequency, col) for col in ratio.T]))


def _channels(snr_db: np.ndarray, names: tuple[str, ...], channel_snr_db: float) -> tuple[str, ...]:
    """Channels at or above `channel_snr_db`; if none, the best one (the peak was seen in the combination)."""
    seen = np.flatnonzero(snr_db >= channel_snr_db)
    if seen.size == 0:
        seen = [int(np.argmax(snr_db))]
    return tuple(names[k] for k in seen)


def _signed(amplitude: np.ndarray) -> np.ndarray:
    """|a| signed by the phase relative to the largest entry (a real mode shape from complex amplitudes)."""
    ref = amplitude[int(np.argmax(np.abs(amplitude)))]
    return np.abs(amplitude) * np.sign(np.cos(np.angle(amplitude) - np.angle(ref)))


def _overview_peak(c: Candidate, overview: Overview, names, channel_snr_db: float) -> Peak:
    """Fallback when the fit fails: the interpolated overview peak.

    Its 1σ is a quarter of the -3 dB width, and at least the uniform 1σ
    of a resolution cell: where the fit failed, the peak's maximum is
    trusted no better than that.
    """
    df = overview.frequency[1] - overview.frequency[0]
    snr = _channel_ratio_db(overview, c.frequency)
    k = c.index
    amplitude = np.sqrt(np.maximum(overview.channel_spectra[k] - overview.channel_floor[k], 0.0) * df)
    return Peak(
        frequency=c.frequency,
        uncertainty=float(max(overview.cell * df / np.sqrt(12.0), 0.25 * c.half_power_width)),
        damping=None,
        damping_uncertainty=None,
        channels=_channels(snr, names, channel_snr_db),
        amplitude=amplitude,
        snr_db=c.snr_db,
        channel_snr_db=snr,
    )
