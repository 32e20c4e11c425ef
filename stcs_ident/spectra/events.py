"""Impulse events in a hand-excitation record: onsets and free-decay segments.

A hand impulse (a blow, a pluck) puts energy into the cable at once, while
the response to random loading changes slowly: the envelope of a mode
moves on the time scale 1/(ζω), seconds to minutes. An onset is a frame
where the energy (summed over channels, each scaled by its median) of
three frames exceeds that of any three frames in the history before it
by 10 dB, on either of two scales:

* the first difference of the acceleration, 10 ms frames, 1 s history:
  it weights the broadband content of the blow and times the onset to a
  frame, but it weights white sensor noise too, so it misses blows that
  excite only modes far below the sampling rate;
* the acceleration itself, 0.1 s frames, 2 s history.

Comparing with the largest earlier level, not the mean, keeps a random
response that recovers from a fade from counting as a blow (it returns to
a level it had within the history); lightly damped modes change their
envelope far too slowly to jump; three frames of broadband noise hold
enough degrees of freedom never to jump by 10 dB; a record that starts
from rest (a simulation's filter transient) rises steadily. Measured: no
onset in 340 noise and ambient records (white, low-pass, band-pass 1–6 Hz,
lightly damped modes) but two band-pass records that start from rest. An
onset must also raise the mean square acceleration of the next 0.5 s by
3 dB over the previous second, which rejects isolated spikes in one sensor
(each candidate is confirmed on its own, before the two scales' candidates
are merged into one onset per blow).

Each event is then the free decay from the end of the most energetic
frame after its onset (the blow is over) up to one frame before the next
onset. A later blow changes the amplitudes of the modes, not their poles,
so overlapping decays are, inside each segment, again one damped
exponential per mode: fitting segment by segment with a common pole is
exact and leaves no fringes. A record that opens inside a decay (its first
second 15 dB above the median of its last quarter) starts with an event at 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from .options import EventOptions, OnsetScale

__all__ = ["Event", "detect_events", "whole_record_event"]

# The tuning values (frames, jumps, confirmation, shortest event) are :class:`.options.EventOptions`.
BLOCK_SAMPLES = 65536  # rows at a time in the scans of the whole record (bounded temporaries)


@dataclass(frozen=True)
class Event:
    """One free decay, as sample indices into the record.

    Parameters
    ----------
    onset : int
        First sample of the frame where the blow was detected.
    start : int
        First sample of the free decay used for fitting (after the blow).
    stop : int
        One past the last sample used (a frame before the next onset).
    """

    onset: int
    start: int
    stop: int

    @property
    def n_samples(self) -> int:
        return self.stop - self.start


@dataclass(frozen=True)
class _Onset:
    sample: int  # first sample of the onset frame
    frame: int  # frame length, samples (the timing resolution)
    start: int  # first sample after the blow


def _frame_length(scale: OnsetScale, sampling_rate: float) -> int:
    return max(scale.min_samples, round(scale.frame * sampling_rate))


def _frame_energy(signal: np.ndarray, frame: int, difference: bool = False) -> np.ndarray:
    """Mean over channels of signal² scaled per channel by its median, averaged per frame.

    With ``difference``, of the first difference of ``signal`` instead. Computed in blocks of whole frames,
    so that a record of gigabytes needs no temporary of its size.
    """
    n = signal.shape[0] - 1 if difference else signal.shape[0]
    rows = np.arange(0, n, max(1, n // 20000))  # a subsample is plenty for the median
    sample = signal[rows + 1] - signal[rows] if difference else signal[rows]
    power = sample**2
    scale = np.median(power, axis=0)
    scale = np.where(scale > 0, scale, np.maximum(power.mean(axis=0), np.finfo(float).tiny))
    n_frames = n // frame
    energy = np.empty(n_frames)
    block = max(1, BLOCK_SAMPLES // frame)  # frames per block
    for k in range(0, n_frames, block):
        lo, hi = k * frame, min(n_frames, k + block) * frame
        part = np.diff(signal[lo:hi + 1], axis=0) if difference else signal[lo:hi]
        energy[k:k + block] = ((part**2 / scale).mean(axis=1)).reshape(-1, frame).mean(axis=1)
    return energy


def _jumps(energy: np.ndarray, history: int, jump_db: float, persist: int) -> np.ndarray:
    """Frames k where the mean of frames k … k+persist−1 exceeds every such mean in the `history` frames before by `jump_db`.

    Averaging `persist` frames gives even a 4-sample frame enough degrees of
    freedom; comparing with the largest earlier mean (not their average)
    makes a narrow-band random response that recovers from a fade no
    onset, since it only returns to a level it had within the history.
    """
    first = max(2 * persist, history // 4)  # at least a quarter of the history must be seen
    if energy.size < first + persist:
        return np.array([], dtype=int)
    cum = np.concatenate([[0.0], np.cumsum(energy)])
    ahead = (cum[persist:] - cum[:-persist]) / persist  # ahead[k]: mean of frames k … k+persist−1
    span = history - persist + 1
    # Largest mean over windows starting in [k − history, k − persist] (all ending before k); near the
    # record's start the filter repeats the first value, so the window stays inside the frames seen so far.
    largest = ndimage.maximum_filter1d(ahead, size=span, origin=(span - 1) // 2, mode="nearest")
    k = np.arange(first, ahead.size)
    before = largest[k - persist]
    return k[ahead[k] >= 10 ** (jump_db / 10) * before]


def _scale_onsets(signal: np.ndarray, sampling_rate: float, scale: OnsetScale, options: EventOptions,
                  energy: np.ndarray | None = None, difference: bool = False) -> list[_Onset]:
    """Onsets at one scale (of the first difference with ``difference``); `energy`: the signal's
    :func:`_frame_energy` at this scale, if already computed."""
    frame = _frame_length(scale, sampling_rate)
    energy = _frame_energy(signal, frame, difference) if energy is None else energy
    if energy.size < 8:
        return []
    history = max(4, round(scale.history * sampling_rate / frame))
    search = max(1, int(np.ceil(options.force_search * sampling_rate / frame)))
    onsets = []
    for k in _jumps(energy, history, scale.jump_db, options.persist):
        peak = k + int(np.argmax(energy[k : k + search]))
        onsets.append(_Onset(sample=int(k * frame), frame=frame, start=int((peak + 1) * frame)))
    return onsets


def _normalised_power(x: np.ndarray) -> np.ndarray:
    """Mean over channels of x² divided by each channel's mean square, per sample (in blocks of rows)."""
    mean_square = np.array([np.mean(x[:, j] ** 2) for j in range(x.shape[1])])
    mean_square = np.maximum(mean_square, np.finfo(float).tiny)
    out = np.empty(x.shape[0])
    for lo in range(0, x.shape[0], BLOCK_SAMPLES):
        out[lo:lo + BLOCK_SAMPLES] = (x[lo:lo + BLOCK_SAMPLES] ** 2 / mean_square).mean(axis=1)
    return out


def _confirmed(x2: np.ndarray, onset: _Onset, sampling_rate: float, options: EventOptions) -> bool:
    after = x2[onset.sample : onset.sample + int(options.confirm_after * sampling_rate)].mean()
    before_lo = max(0, onset.sample - int(options.confirm_before * sampling_rate))
    if before_lo == onset.sample:
        return True
    return after >= 10 ** (options.confirm_db / 10) * x2[before_lo : onset.sample].mean()


def _merge(fine: list[_Onset], coarse: list[_Onset], gap: int) -> list[_Onset]:
    """One onset per blow; the finer timing wins when both scales saw it."""
    merged: list[_Onset] = []
    for onset in sorted(fine + coarse, key=lambda o: (o.sample, o.frame)):
        if merged and onset.sample - merged[-1].sample < gap:
            if onset.frame < merged[-1].frame and onset.sample < merged[-1].sample + 2 * merged[-1].frame:
                merged[-1] = onset
            continue
        merged.append(onset)
    return merged


def _starts_in_decay(x: np.ndarray, sampling_rate: float, coarse: OnsetScale,
                     energy: np.ndarray | None = None) -> bool:
    """The record opens inside a decay: its first second 15 dB above the median of its last quarter.

    `energy`: :func:`_frame_energy` of `x` in `coarse` frames, if already computed.
    """
    frame = _frame_length(coarse, sampling_rate)
    energy = _frame_energy(x, frame) if energy is None else energy
    head = max(1, round(sampling_rate / frame))
    if energy.size < 4 * head:
        return False
    return energy[:head].mean() >= 10**1.5 * np.median(energy[3 * energy.size // 4 :])


def detect_events(acceleration: np.ndarray, sampling_rate: float, options: EventOptions | None = None) -> list[Event]:
    """Find the blows of a hand-excitation record and its free-decay segments.

    Parameters
    ----------
    acceleration : ndarray (n_samples, n_channels)
        Mean-removed acceleration.
    sampling_rate : float
        Hz.
    options : EventOptions, optional
        Frames, jumps and confirmation (default: the calibrated values).

    Returns
    -------
    list of Event
        Empty for an ambient record (no blow found).
    """
    options = EventOptions() if options is None else options
    x = np.asarray(acceleration, dtype=float)
    fine = _scale_onsets(x, sampling_rate, options.fine, options, difference=True)
    coarse_energy = _frame_energy(x, _frame_length(options.coarse, sampling_rate))
    coarse = _scale_onsets(x, sampling_rate, options.coarse, options, coarse_energy)
    onsets = []
    if fine or coarse:  # (an ambient record has none: the normalised power is not needed)
        # Each candidate confirmed before they are merged: at a low sampling rate a jump is seen up to
        # persist − 1 frames (0.8 s at 20 Hz) before the blow, so the earliest candidate's confirm_after
        # may end before the blow; merged first, it took the later ones with it (a blow of 46 dB lost).
        # Where every candidate is confirmed (a blow seen at most confirm_after early) nothing changes.
        x2 = _normalised_power(x)
        fine = [o for o in fine if _confirmed(x2, o, sampling_rate, options)]
        coarse = [o for o in coarse if _confirmed(x2, o, sampling_rate, options)]
        onsets = _merge(fine, coarse, int(options.min_gap * sampling_rate))
    if (not onsets or onsets[0].sample > 2 * sampling_rate) and _starts_in_decay(x, sampling_rate, options.coarse,
                                                                                  coarse_energy):
        frame = _frame_length(options.coarse, sampling_rate)
        onsets.insert(0, _Onset(sample=0, frame=frame, start=0))
    events = []
    for i, onset in enumerate(onsets):
        stop = onsets[i + 1].sample - onsets[i + 1].frame if i + 1 < len(onsets) else x.shape[0]
        if stop - onset.start >= options.min_event * sampling_rate:
            events.append(Event(onset=onset.sample, start=onset.start, stop=stop))
    return events


def whole_record_event(acceleration: np.ndarray, sampling_rate: float, options: EventOptions | None = None) -> Event:
    """The decay from the record's most energetic frame to its end (when a blow is assumed but none found).

    Its frames are the coarse scale of ``options``; a decay shorter than ``options.min_event`` is not taken.
    """
    options = EventOptions() if options is None else options
    frame = _frame_length(options.coarse, sampling_rate)
    energy = _frame_energy(np.asarray(acceleration, dtype=float), frame)
    peak = int(np.argmax(energy)) if energy.size else 0
    start = min(peak * frame, max(0, acceleration.shape[0] - int(options.min_event * sampling_rate)))
    return Event(onset=start, start=start, stop=acceleration.shape[0])
