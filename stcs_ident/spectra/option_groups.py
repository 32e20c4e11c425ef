"""The groups of picking options, one per step of :func:`.peaks.find_peaks` (and the numbering), each a
frozen dataclass whose fields are checked when built; :class:`.options.PickingOptions` holds one of each.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..core.errors import InputError
from .option_checks import (
    OptionGroup,
    at_least,
    count,
    fraction,
    integer_at_least,
    non_negative,
    positive,
    probability,
    ratio_range,
    tuple_of,
)

__all__ = [
    "DecayCheckOptions", "DetectionOptions", "EventOptions", "FilterOptions", "FitOptions", "FloorOptions",
    "NumberingOptions", "OnsetScale", "OverviewOptions", "RefineOptions", "ResidualOptions",
]


# ----------------------------------------------------------------------------------------------------------------
# The groups, in the order of the steps of find_peaks.


@dataclass(frozen=True)
class OnsetScale:
    """One scale of the onset search (:mod:`.events`): frames, the history they are compared with, the jump.

    Attributes
    ----------
    frame : float
        Frame length, s (the onset's timing resolution).
    history : float
        Frames compared with, s before the candidate.
    min_samples : int
        Shortest frame, samples (at a low sampling rate a frame of
        ``frame`` seconds would hold too few samples to average).
    jump_db : float
        Rise of the energy over every level within the history that makes
        an onset, dB (three frames of broadband noise never jump by 10 dB).
    """

    frame: float
    history: float
    min_samples: int
    jump_db: float

    def __post_init__(self):
        for name, check in (("frame", positive), ("history", positive), ("min_samples", count),
                            ("jump_db", positive)):
            problem = check(getattr(self, name))
            if problem is not None:
                raise InputError(problem, field=f"onset_scale.{name}")
        if self.history <= self.frame:
            raise InputError(f"must be longer than the frame ({self.frame:g} s), got {self.history!r}",
                             field="onset_scale.history")


def _onset_scale(value) -> str | None:
    return None if isinstance(value, OnsetScale) else f"must be an OnsetScale, got {value!r}"


@dataclass(frozen=True)
class EventOptions(OptionGroup):
    """Blows and free-decay segments (:mod:`.events`).

    Attributes
    ----------
    fine : OnsetScale
        The first difference of the acceleration: 10 ms frames, 1 s
        history, at least 4 samples, 10 dB. It weights the broadband
        content of a blow and times the onset to a frame.
    coarse : OnsetScale
        The acceleration itself: 0.1 s frames, 2 s history, at least 8
        samples, 10 dB (blows that excite only modes far below the
        sampling rate, which the first difference misses).
    persist : int
        Frames averaged after a candidate onset (3: gives even a 4-sample
        frame enough degrees of freedom).
    min_gap : float
        Onsets closer than this belong to one blow, s (0.5).
    force_search : float
        Time after an onset within which the blow is over, s (0.25): the
        decay is taken from the end of its most energetic frame.
    confirm_after, confirm_before : float
        An onset must raise the mean square acceleration of the next
        ``confirm_after`` seconds (0.5) over the previous ``confirm_before``
        seconds (1.0) ...
    confirm_db : float
        ... by this much, dB (3: rejects isolated spikes in one sensor).
    min_event : float
        Shorter free-decay segments are not used, s (0.5).
    """

    fine: OnsetScale = OnsetScale(frame=0.01, history=1.0, min_samples=4, jump_db=10.0)
    coarse: OnsetScale = OnsetScale(frame=0.1, history=2.0, min_samples=8, jump_db=10.0)
    persist: int = 3
    min_gap: float = 0.5
    force_search: float = 0.25
    confirm_after: float = 0.5
    confirm_before: float = 1.0
    confirm_db: float = 3.0
    min_event: float = 0.5

    _name: ClassVar[str] = "events"
    _checks: ClassVar[dict[str, Callable]] = {
        "fine": _onset_scale, "coarse": _onset_scale, "persist": count, "min_gap": positive,
        "force_search": positive, "confirm_after": positive, "confirm_before": positive,
        "confirm_db": non_negative, "min_event": positive,
    }


@dataclass(frozen=True)
class OverviewOptions(OptionGroup):
    """Spectral overviews (:mod:`.overview`).

    Attributes
    ----------
    decay_padding : int
        Zero-padding factor of the free-decay periodograms (2).
    ripple_dof_cap : float
        Free decays: the local degrees of freedom of the combined spectrum
        are at most this times C ν (8: the smooth deterministic skirts of
        strong decays scatter far less than noise).
    welch_segments : int
        Ambient records: about this many Welch segments (16).
    decay_window_ratio : int
        Successive decay-matched windows are this many times shorter (4).
    min_decay_window : int
        Shortest decay-matched window, samples (64).
    smoothing : int
        Resolution cells averaged in the smoothed free-decay overview (4:
        weak, heavily damped modes keep their height while the scatter falls).
    """

    decay_padding: int = 2
    ripple_dof_cap: float = 8
    welch_segments: int = 16
    decay_window_ratio: int = 4
    min_decay_window: int = 64
    smoothing: int = 4

    _name: ClassVar[str] = "overview"
    _checks: ClassVar[dict[str, Callable]] = {
        "decay_padding": count, "ripple_dof_cap": at_least(1.0), "welch_segments": count,
        "decay_window_ratio": integer_at_least(2), "min_decay_window": integer_at_least(8),
        "smoothing": count,
    }


@dataclass(frozen=True)
class FloorOptions(OptionGroup):
    """Noise floors of the spectra (:mod:`.floor`).

    Attributes
    ----------
    block_cells : int
        Smallest floor block, resolution cells (8).
    block_relative : float
        Floor blocks grow to this fraction of their frequency (0.03).
    floor_blocks : int
        Running median over this many blocks (7: a window of 56 cells or
        ±10 % of the frequency, five times the half-power width of a mode
        with ζ = 2 %).
    passes : int
        Passes of the floor, each leaving out the peak regions the
        previous one found (3: a resonance does not lift its own floor).
    mask_probability : float
        A bin above this upper chi-squared quantile starts a masked peak
        region (0.01).
    mask_smoothing : int
        Cells averaged to find broad peaks for the mask (8).
    """

    block_cells: int = 8
    block_relative: float = 0.03
    floor_blocks: int = 7
    passes: int = 3
    mask_probability: float = 0.01
    mask_smoothing: int = 8

    _name: ClassVar[str] = "floor"
    _checks: ClassVar[dict[str, Callable]] = {
        "block_cells": count, "block_relative": positive, "floor_blocks": count, "passes": count,
        "mask_probability": probability, "mask_smoothing": count,
    }


@dataclass(frozen=True)
class DetectionOptions(OptionGroup):
    """Peak detection in the overviews (:mod:`.detection`).

    Attributes
    ----------
    false_alarm : float
        Nominal probability, per record, that pure noise gives a candidate
        (1e-4; measured: no candidate in 800 one-channel noise records).
    ripple_false_alarm : float
        Ambient: expected ripple bumps per record that pass the prominence
        test (0.5; the fit rejects them).
    separation_probability : float
        Ambient: a valley deeper than the ripple of the running mean makes
        with this probability separates two resonances (0.01).
    """

    false_alarm: float = 1e-4
    ripple_false_alarm: float = 0.5
    separation_probability: float = 0.01

    _name: ClassVar[str] = "detection"
    _checks: ClassVar[dict[str, Callable]] = {
        "false_alarm": probability, "ripple_false_alarm": fraction, "separation_probability": probability,
    }


@dataclass(frozen=True)
class RefineOptions(OptionGroup):
    """The band each detection is fitted in, and which fits are modes (:mod:`.refine`).

    Attributes
    ----------
    min_significance : float
        A fitted mode below this z-like score is a detection on a skirt or
        on noise (6).
    fallback_snr_db : float
        A peak whose fit failed is still reported (overview estimate) if
        this strong above the floor, dB (10).
    max_damping : float
        A fitted ζ at or above this describes a broad spectral shape, not
        a cable mode (0.1); the fits search ζ up to twice this.
    band_half_power_widths : float
        Band half-width, in half-power widths of the peak (8).
    band_neighbour_fraction : float
        The band reaches at most this fraction of the way to the next
        candidate (0.45).
    band_neighbour_fraction_wide : float
        Last try for a doubtful fit: the band reaches this fraction of the
        way over to the neighbours' peaks (0.9: a heavily damped mode between
        close neighbours).
    band_max_relative : float
        The band's half-width is at most this fraction of the frequency (0.25).
    band_min_bins : int
        Free decays: narrowest band half-width, DFT bins of the longest event (24).
    band_min_welch_bins : int
        Ambient: narrowest band half-width, Welch resolution cells (12).
    """

    min_significance: float = 6.0
    fallback_snr_db: float = 10.0
    max_damping: float = 0.1
    band_half_power_widths: float = 8.0
    band_neighbour_fraction: float = 0.45
    band_neighbour_fraction_wide: float = 0.9
    band_max_relative: float = 0.25
    band_min_bins: int = 24
    band_min_welch_bins: int = 12

    _name: ClassVar[str] = "refine"
    _checks: ClassVar[dict[str, Callable]] = {
        "min_significance": non_negative, "fallback_snr_db": non_negative, "max_damping": probability,
        "band_half_power_widths": positive, "band_neighbour_fraction": fraction,
        "band_neighbour_fraction_wide": fraction, "band_max_relative": fraction, "band_min_bins": count,
        "band_min_welch_bins": count,
    }


@dataclass(frozen=True)
class DecayCheckOptions(OptionGroup):
    """When a free-decay fit is checked against, and replaced by, the record's Whittle fit (:mod:`.peaks`).

    Attributes
    ----------
    max_residual_excess : float
        Decay-fit residual under the peak over that away from it beyond
        which the Whittle fit is tried (2: a random response under the decay).
    max_forced_ratio : float
        Random response over free decay in the band beyond which the
        record's Whittle fit is used (0.3: a weak blow under wind; a decay
        fit of forced ratio 0.5 stood for a mode of ζ 0.0145 with 0.0012, z = −30).
    narrow_damping : float
        A decay fit below this ζ is checked against Whittle (1e-3: cables
        have ζ ≥ 1e-3, rarely below 5e-4) ...
    broader_peak : float
        ... and replaced by it when the record's peak is this many times
        broader in ζ (10: a pole that does not decay, fitted to one noise
        bin of a random response).
    whittle_max_std : float
        A Whittle fit whose 1σ exceeds this fraction of its band's
        half-width locates nothing (0.25).
    """

    max_residual_excess: float = 2.0
    max_forced_ratio: float = 0.3
    narrow_damping: float = 1e-3
    broader_peak: float = 10.0
    whittle_max_std: float = 0.25

    _name: ClassVar[str] = "decay_check"
    _checks: ClassVar[dict[str, Callable]] = {
        "max_residual_excess": at_least(1.0), "max_forced_ratio": positive, "narrow_damping": probability,
        "broader_peak": at_least(1.0), "whittle_max_std": positive,
    }


_DECAY_START_DAMPING = tuple(float(z) for z in np.concatenate([[0.0], np.logspace(-4.5, -1.0, 15)]))
_AMBIENT_START_DAMPING = tuple(float(z) for z in np.logspace(-4.0, -1.0, 7))


@dataclass(frozen=True)
class FitOptions(OptionGroup):
    """The fits of one mode (:mod:`.decay_fit`, :mod:`.ambient_fit`) and the events' disagreement (:mod:`.wander`).

    Attributes
    ----------
    decay_max_iterations : int
        Levenberg–Marquardt iterations of a free-decay fit (40).
    decay_start_damping : tuple of float
        ζ grid of the free-decay fit's start (0 and 15 values from
        10^-4.5 to 0.1, logarithmic): the best of them starts the search.
    ambient_max_iterations : int
        Fisher-scoring iterations of a Whittle fit (60).
    ambient_start_damping : tuple of float
        ζ grid of the Whittle fit's start (7 values from 1e-4 to 0.1,
        logarithmic), crossed with a few starting frequencies.
    heterogeneity_level : float
        Level of Cochran's Q test of the events' agreement before a
        between-event variance is added to a frequency's 1σ (0.05: without
        the test, chance scatter of two or three clean events made the 1σ
        too large).
    """

    decay_max_iterations: int = 40
    decay_start_damping: tuple[float, ...] = _DECAY_START_DAMPING
    ambient_max_iterations: int = 60
    ambient_start_damping: tuple[float, ...] = _AMBIENT_START_DAMPING
    heterogeneity_level: float = 0.05

    _name: ClassVar[str] = "fit"
    _checks: ClassVar[dict[str, Callable]] = {
        "decay_max_iterations": count, "decay_start_damping": tuple_of(non_negative),
        "ambient_max_iterations": count, "ambient_start_damping": tuple_of(positive),
        "heterogeneity_level": probability,
    }


@dataclass(frozen=True)
class ResidualOptions(OptionGroup):
    """Ambient records: the residual pass for modes the fitted ones leave unexplained (:mod:`.residual`).

    Attributes
    ----------
    false_alarm_share : float
        Its false-alarm probability, as a share of the record's, on top
        of the overview's (0.5).
    clearance_widths : float
        A residual peak within this many half-power widths of a fitted
        mode is that mode's misfit, not a proposal (1).
    """

    false_alarm_share: float = 0.5
    clearance_widths: float = 1.0

    _name: ClassVar[str] = "residual"
    _checks: ClassVar[dict[str, Callable]] = {"false_alarm_share": fraction, "clearance_widths": non_negative}


@dataclass(frozen=True)
class FilterOptions(OptionGroup):
    """What is reported of the fitted peaks: duplicates, mains hum, the channels that saw a peak.

    Attributes
    ----------
    deduplicate_max_std : float
        Two peaks within 3σ are one, each σ counted at most this fraction
        of its frequency (0.005: a poor fit's wide σ must not swallow its
        well-located neighbours).
    mains_frequencies : tuple of float
        Mains frequencies whose harmonics may carry hum, Hz (50, 60).
    mains_tolerance : float
        Relative distance to a harmonic within which a line is at it
        (0.002: grids keep within ±0.1 % of their nominal frequency, with margin).
    max_hum_damping : float
        A line this undamped at a mains harmonic is hum, not reported
        (5e-4; cable modes have ζ ≥ 1e-3).
    channel_snr_db : float
        A channel saw a peak standing this high above its own floor, dB (6).
    """

    deduplicate_max_std: float = 0.005
    mains_frequencies: tuple[float, ...] = (50.0, 60.0)
    mains_tolerance: float = 0.002
    max_hum_damping: float = 5e-4
    channel_snr_db: float = 6.0

    _name: ClassVar[str] = "filters"
    _checks: ClassVar[dict[str, Callable]] = {
        "deduplicate_max_std": positive, "mains_frequencies": tuple_of(positive),
        "mains_tolerance": probability, "max_hum_damping": non_negative, "channel_snr_db": non_negative,
    }


@dataclass(frozen=True)
class NumberingOptions(OptionGroup):
    """Mode numbers from the family of the nominal model (:mod:`.numbering`).

    Attributes
    ----------
    model_tolerance : float
        Relative misfit the model is allowed per mode after tension and EI
        are fitted (0.003: attachments, sag, end conditions).
    relaxed_tolerance : float
        Peaks the strict pass leaves unassigned are retried with this many
        times ``model_tolerance`` (10: 0.3 % → 3 %, a hidden effect's shift).
    unassigned_cost : float
        Cost of leaving a peak unassigned, in squared standardised
        residuals (16: a peak 4σ from every prediction is cheaper to call spurious).
    tension_range : (float, float)
        Tension ratios to nominal searched (0.6–1.5: frequencies 23 % below
        to 22 % above the nominal).
    EI_range : (float, float)
        Bending-stiffness ratios to nominal searched (0.2–5).
    ambiguity : float
        Cost difference within which another family counts as equally
        good (a χ² difference; 6 ≈ 2.4σ on one mode).
    """

    model_tolerance: float = 0.003
    relaxed_tolerance: float = 10.0
    unassigned_cost: float = 16.0
    tension_range: tuple[float, float] = (0.6, 1.5)
    EI_range: tuple[float, float] = (0.2, 5.0)
    ambiguity: float = 6.0

    _name: ClassVar[str] = "numbering"
    _checks: ClassVar[dict[str, Callable]] = {
        "model_tolerance": positive, "relaxed_tolerance": at_least(1.0), "unassigned_cost": positive,
        "tension_range": ratio_range, "EI_range": ratio_range, "ambiguity": non_negative,
    }
