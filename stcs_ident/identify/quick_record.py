"""One record to one tension: the quick answer from a file, a length and a mass (no campaign, no nominal tension).

The commonest field question is "here is my record, the length and the mass:
what is the tension?". :func:`tension_from_record` answers it as ``spectra``
and ``tension`` would together, without a campaign:

1. the record is read through the record readers (any format, the reader
   options as a campaign's ``record_format``);
2. the peaks are picked as ``spectra`` picks them (:func:`~stcs_ident.spectra.peaks.find_peaks`), over the whole
   band below the anti-aliasing roll-off;
3. they are numbered from their own spacing (:func:`~stcs_ident.spectra.harmonic.harmonic_series`: no nominal
   tension is needed), and on an ambient record picked again with that series' modes proposed where no peak was
   detected (as ``spectra`` proposes the nominal family's); where the first peaks number no series (a short
   record of a long cable), the spacings whose harmonics stand highest in the overview are proposed instead;
4. every method of :func:`~stcs_ident.identify.quick.quick_tension` runs on the lowest numbered peaks (up to
   :data:`MAX_MODES`, and to the first jump of more than :data:`MAX_JUMP` mode numbers), with each frequency's 1σ
   from the record.

A series that several spacings explain (one peak, or peaks a sub-harmonic
numbers as well) is refused: its numbers would be a guess, and a wrong number
is a tension tens of per cent off with a small σ.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..core.errors import InputError
from ..core.planes import PLANES
from ..core.record import Record
from ..core.result import Result
from ..io.records.validation import UnknownPositions
from ..io.test_record import RecordReading, open_record
from ..spectra.channels import plane_channels, plane_record
from ..spectra.harmonic import HarmonicSeries, harmonic_series
from ..spectra.peaks import PeakResult, find_peaks
from .quick import QuickTensionResult, quick_tension

__all__ = ["RecordTensionResult", "pick_unnumbered", "tension_from_record"]

#: The analysis band ends at this share of the sampling rate, below the anti-aliasing filter's roll-off (as
#: ``spectra``'s).
USABLE = 0.45
#: Most modes passed to the tension methods: the lowest of the series (enough for tension and EI; a long stay
#: shows hundreds below the Nyquist frequency, and the beam-string form the peaks are numbered by drifts from a
#: sagging stay's exact family at its higher modes: a 198 m stay's modes from 20 on came out one number low).
MAX_MODES = 15


@dataclass(frozen=True)
class RecordTensionResult(Result):
    """The tension from one record (:func:`tension_from_record`).

    Attributes
    ----------
    tension : QuickTensionResult
        Every method side by side, on the numbered peaks (their 1σ from the record).
    record : dict
        ``path``, ``channels`` read, ``sampling_rate`` (Hz), ``duration`` (s), ``kind`` (impulse or ambient),
        ``replaced`` (the file's values the reader options replaced), ``dropped`` channels, ``notes``.
    peaks : tuple of dict
        Every peak picked: ``frequency``, ``uncertainty`` (Hz), ``mode`` (its number in the series, None when
        left out), ``doubtful``, ``damping``.
    series : HarmonicSeries
        The peaks' own series (fundamental, inharmonicity).
    notes : tuple of str
    """

    tension: QuickTensionResult
    record: dict
    peaks: tuple[dict, ...]
    series: HarmonicSeries
    notes: tuple[str, ...] = field(default_factory=tuple)

    main_table = "methods"

    @property
    def settings(self):
        return None

    @property
    def inputs(self) -> dict:
        return self.tension.inputs

    @property
    def methods(self) -> dict:
        return self.tension.methods

    def summary(self) -> dict:
        """The JSON of ``tension --record``: ``tension``'s, plus ``record``, ``peaks`` and ``series``."""
        out = self.tension.summary()
        out["notes"] = list(out.get("notes", [])) + list(self.notes)
        out["record"] = dict(self.record)
        out["peaks"] = [dict(p) for p in self.peaks]
        out["series"] = {"fundamental": self.series.fundamental, "inharmonicity": self.series.inharmonicity,
                         "numbered": self.series.n_assigned}
        return out

    to_dict = summary

    def tables(self):
        import pandas as pd

        tables = self.tension.tables()
        # the JSON's keys with their units, as every table's columns
        names = {"frequency": "frequency_Hz", "uncertainty": "uncertainty_Hz", "mode": "mode", "doubtful": "doubtful",
                 "damping": "damping_ratio"}
        tables["peaks"] = pd.DataFrame(list(self.peaks), columns=list(names)).rename(columns=names)
        return tables


def pick_unnumbered(record: Record, *, f_min: float | None = None, f_max: float | None = None,
                    expected=None) -> PeakResult:
    """The peaks of ``record`` as ``spectra`` picks them, over the band from a few periods of the record's
    length (``f_min`` default: 8 / duration) to :data:`USABLE` of its sampling rate, unnumbered."""
    low = 8.0 / record.duration if f_min is None else f_min
    high = USABLE * record.sampling_rate if f_max is None else f_max
    if not high > low:
        raise InputError(f"the record ({record.duration:.4g} s at {record.sampling_rate:.4g} Hz) has no band to "
                         f"search: {low:.4g} Hz (8 periods of its length) to {high:.4g} Hz", field="acceleration",
                         file=record.source)
    return find_peaks(record, f_min=low, f_max=high, expected=expected)


def unnumbered_summary(path: str, record: Record, peaks: PeakResult) -> dict:
    """The ``spectra FILE`` JSON: a record's peaks as :func:`pick_unnumbered` picks them, unnumbered (no model
    to number them against), with the record's rate, length, channels and notes, and how to get them numbered."""
    rows = [{"frequency": p.frequency, "uncertainty": p.uncertainty,
             "damping": None if p.damping is None else float(p.damping), "channels": list(p.channels)}
            for p in peaks.peaks]
    return {"record": str(path), "kind": peaks.kind, "sampling_rate": record.sampling_rate,
            "duration": record.duration, "channels": list(record.channel_names), "peaks": rows,
            "notes": [str(n) for n in getattr(record, "notes", ())], "numbered": False,
            "hint": (f"stcs-ident tension --record {path} --length L --mass M numbers them from their own spacing "
                     "and gives the tension")}


def tension_from_record(path: str | os.PathLike, length: float, mass: float, *,
                        reading: RecordReading | Mapping[str, Any] | None = None, EI: float | None = None,
                        EA: float | None = None, inclination: float = 0.0, boundary: str = "clamped",
                        plane: str = "in", EI_tolerance: float | None = None, length_tolerance: float | None = None,
                        mass_tolerance: float | None = None) -> RecordTensionResult:
    """A cable's tension from one record, its length and its mass per length (module docstring).

    Parameters
    ----------
    path : str or path-like
        The record, in any format the record readers take.
    length, mass : float
        Chord length (m) and mass per length (kg/m).
    reading : RecordReading or mapping, optional
        Channel positions and directions, and reader options (``sampling_rate``, ``unit``, ``channels``,
        ``separator``, ``decimal``, ``header_row`` …), as a campaign's; positions are not needed (the peaks are
        numbered from their spacing, not from shapes).
    EI, EA, inclination, boundary, EI_tolerance, length_tolerance, mass_tolerance
        As :func:`~stcs_ident.identify.quick.quick_tension`.
    plane : {"in", "out"}
        The plane of the modes: with channel directions, only that plane's channels are used.

    Returns
    -------
    RecordTensionResult

    Raises
    ------
    InputError
        A record that cannot be read (one line naming the file and the field), no peak found, or peaks whose
        mode numbers several harmonic series explain.
    """
    if plane not in PLANES:
        raise InputError(f'must be "in" or "out", got {plane!r}', field="plane")
    if isinstance(reading, Mapping):
        reading = RecordReading(**dict(reading))
    reading = reading or RecordReading()
    if reading.positions is None:  # not needed: the peaks are numbered from their spacing, not their shapes
        reading = replace(reading, positions=UnknownPositions())
    read = open_record(path, reading)
    file = os.fspath(path)
    record, used = _plane_channels(_named_channels(read, reading.options.get("channels")), plane)
    first = pick_unnumbered(record)
    if not first.peaks:
        raise InputError(f"no peak found between {8 / record.duration:.3g} and {USABLE * record.sampling_rate:.4g} Hz "
                         "on any channel", field="acceleration", file=file)
    series = _series_of(first)
    peaks = first
    if first.kind == "ambient" and (series.ambiguous or series.n_assigned < MIN_SERIES):
        # A short ambient record of a long cable: most modes below the detection threshold, too few peaks to
        # number themselves. The overview's harmonic sum says which spacings its weaker peaks share; each of the
        # best is proposed (as spectra proposes the nominal family) and kept if its peaks then number themselves.
        peaks, series = _from_harmonic_sum(record, first, series)
    series = _series(peaks, series, file)
    if peaks.kind == "ambient" and peaks is first:  # undetected modes proposed where the series puts them
        top = series.frequency(np.arange(1, MAX_MODES + 1))
        again = pick_unnumbered(record, expected=top[top < USABLE * record.sampling_rate])
        if again.peaks:
            retry = _series_of(again)
            if retry is not None and not retry.ambiguous and abs(retry.fundamental / series.fundamental - 1) < 0.02:
                peaks, series = again, retry
    freqs = np.array([p.frequency for p in peaks.peaks])
    sigma = np.array([p.uncertainty for p in peaks.peaks])
    usable = np.isfinite(sigma) & (sigma > 0) & (sigma < MAX_SHARE * freqs)
    numbered = _low_block(np.where(usable, series.modes, 0))
    quick = quick_tension(length, mass, freqs[numbered], series.modes[numbered], EI=EI, EA=EA,
                          inclination=inclination, boundary=boundary, uncertainty=sigma[numbered],
                          uncertainty_source="from the record's spectra (each peak's fit)",
                          EI_tolerance=EI_tolerance, length_tolerance=length_tolerance,
                          mass_tolerance=mass_tolerance, plane=plane)
    shown = set(numbered.tolist())
    table = tuple({"frequency": float(p.frequency), "uncertainty": float(p.uncertainty),
                   "mode": int(series.modes[k]) if k in shown else None, "doubtful": False,
                   "damping": None if p.damping is None or not math.isfinite(p.damping) else float(p.damping)}
                  for k, p in enumerate(peaks.peaks))
    notes = []
    left = [p for p in table if p["mode"] is None]
    if left:
        notes.append(f"{len(left)} peak(s) not used (not in the series, or beyond its first {MAX_MODES} modes or "
                     f"a jump of more than {MAX_JUMP} mode numbers): "
                     + ", ".join(f"{p['frequency']:.4g} Hz" for p in left[:8]) + (" …" if len(left) > 8 else ""))
    info = {"path": file, "channels": list(used), "sampling_rate": record.sampling_rate,
            "duration": record.duration, "kind": peaks.kind,
            "replaced": [{"option": o, "given": g, "file": f} for o, g, f in read.replaced],
            "dropped": [{"channel": c, "reason": r} for c, r in read.dropped],
            "notes": list(read.notes)}
    return RecordTensionResult(quick, info, table, series, tuple(notes))


#: A numbered peak whose 1σ is this share of its frequency or more is not passed on (a fit that says nothing of the
#: frequency: one such peak of a 60-s record had a 1σ above its frequency, which the methods refuse).
MAX_SHARE = 0.05
#: The modes passed on stop before a jump of more than this many mode numbers: sparse high peaks are numbered from a
#: stretch extrapolated beyond the modes that fixed it (a 198 m stay's peaks at 17.6 and 19.9 Hz, after its run of
#: modes up to 37 at 13.7 Hz, came out as modes 42 and 46 for 47 and 53).
MAX_JUMP = 3


def _low_block(modes: np.ndarray) -> np.ndarray:
    """Indices of the numbered peaks passed to the methods, by mode: from the lowest, up to the first jump of more
    than :data:`MAX_JUMP` mode numbers, at most :data:`MAX_MODES`."""
    numbered = np.flatnonzero(modes > 0)
    numbered = numbered[np.argsort(modes[numbered])]
    jumps = np.flatnonzero(np.diff(modes[numbered]) > MAX_JUMP)
    if jumps.size:
        numbered = numbered[: jumps[0] + 1]
    return numbered[:MAX_MODES]


def _series_of(peaks: PeakResult) -> HarmonicSeries | None:
    """The harmonic series of picked peaks (their frequencies and 1σ)."""
    return harmonic_series([p.frequency for p in peaks.peaks], [p.uncertainty for p in peaks.peaks])


def _series(peaks: PeakResult, series: HarmonicSeries, file: str) -> HarmonicSeries:
    """``series``, the harmonic series of ``peaks``; refused where it is not sure (module docstring)."""
    freqs = [p.frequency for p in peaks.peaks]
    if series.ambiguous:
        listed = ", ".join(f"{f:.4g}" for f in sorted(freqs)[:8])
        other = f" or {series.alternative:.4g} Hz" if series.alternative else ""
        raise InputError(f"the peaks ({listed} Hz) do not number themselves: harmonic series with a fundamental "
                         f"of {series.fundamental:.4g}{other} explain them about as well; give the frequencies "
                         "with their mode numbers (--frequencies, --modes) instead", field="acceleration", file=file)
    return series


def _plane_channels(record: Record, plane: str) -> tuple[Record, tuple[str, ...]]:
    """The record of ``plane``'s channels as spectra reads a plane (:func:`~stcs_ident.spectra.channels.plane_channels`:
    a turned sensor pair rotated, a sensor at an angle scaled); every channel when the record has no directions."""
    if record.channel_directions is None:
        return record, record.channel_names
    channels, _ = plane_channels(record)
    if plane not in channels:
        given = ", ".join(f"{n} {d}" for n, d in zip(record.channel_names, record.channel_directions))
        raise InputError(f"no {plane!r} channel among {given}: give --plane or the channels' directions",
                         field="channel_direction", file=record.source)
    sub = plane_record(record, channels[plane])
    return sub, sub.channel_names


def _named_channels(record: Record, names) -> Record:
    """The record with only the channels ``names`` (all when None; a text file's reader has left the others out
    already, another format's are dropped here)."""
    if not names or tuple(names) == record.channel_names:
        return record
    missing = [n for n in names if n not in record.channel_names]
    if missing:
        raise InputError(f"no channel named {missing[0]!r}; the record has {', '.join(record.channel_names)}",
                         field="channels", file=record.source)
    keep = [record.channel_names.index(n) for n in names]
    return replace(record, acceleration=record.acceleration[:, keep], channel_names=tuple(names),
                   channel_positions=record.channel_positions[keep],
                   channel_directions=None if record.channel_directions is None else
                   tuple(record.channel_directions[k] for k in keep))


#: Fewest peaks a short ambient record's first series must number before the overview's harmonic sum is not asked.
MIN_SERIES = 4
#: Spacings of the harmonic sum tried (:func:`_from_harmonic_sum`: the sum over a spacing's harmonics of the
#: overview's log-ratio above its floor, less its median, the noise's level; on a 60-s record of a 196 m stay
#: whose overview showed two peaks, the true spacing 0.759 Hz scored 14.1 at 0.765, the next 6.9).
SUM_CANDIDATES = 3


def _from_harmonic_sum(record: Record, first: PeakResult, series: HarmonicSeries) -> tuple[PeakResult, HarmonicSeries]:
    """The best of the overview's harmonic-sum spacings proposed as a series (module docstring): (peaks, series)
    of the one whose peaks number themselves with the most modes, else ``first`` and ``series`` as they were."""
    best = (first, series)
    f = np.asarray(first.frequency_axis, float)
    ratio = np.asarray(first.combined_spectrum, float) / np.maximum(np.asarray(first.combined_floor, float), 1e-300)
    if f.size < 16:
        return best
    level = np.log(np.maximum(ratio, 1e-12))
    top = USABLE * record.sampling_rate
    lo = max(8.0 / record.duration, 3 * (f[1] - f[0]))
    grid = np.geomspace(lo, top / 3, 3000)
    n = np.arange(1, 61)
    harmonics = grid[:, None] * n[None, :]
    inside = harmonics < top
    score = np.where(inside, np.interp(harmonics, f, level) - np.median(level), 0.0).sum(axis=1)
    chosen: list[float] = []
    for i in np.argsort(score)[::-1]:
        if score[i] <= 0 or len(chosen) == SUM_CANDIDATES:
            break
        if all(abs(grid[i] / c - 1) > 0.03 for c in chosen):
            chosen.append(float(grid[i]))
    for f0 in chosen:
        expected = f0 * n[f0 * n < top][:MAX_MODES * 2]
        again = pick_unnumbered(record, expected=expected)
        if not again.peaks:
            continue
        trial = _series_of(again)
        if trial is not None and not trial.ambiguous and (best[1].ambiguous or trial.n_assigned > best[1].n_assigned):
            best = (again, trial)
    return best
