"""From a test's acceleration record to numbered modal frequencies.

read the record (any format io reads: :func:`~stcs_ident.io.records.read_record`)
→ check it against the cable (positions, duration) → pick peaks across
channels (:mod:`.peaks`) → number them by the family of the nominal model
(:mod:`.numbering`). One :class:`TestSpectra` per test.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pandas as pd

from ..core.errors import InputError, NumberingWarning
from ..core.model import Campaign, Test
from ..core.notes import Note
from ..core.planes import NO_DIRECTIONS_NOTE, PLANE_NAMES, directions_note
from ..core.record import Record
from ..forward import natural_frequencies
from ..io.records.validation import check_bandwidth, check_duration, check_positions
from ..io.test_record import open_test_record
from .doubtful_modes import blends_doubtful, low_mac_doubtful
from .numbering import Numbering, number_modes
from .options import PickingOptions
from .peak_result import PickingResult
from .peaks import PeakResult, find_peaks
from .plane_analysis import PlanesOutcome, analyse_planes, misfit_uncertainty
from .plane_options import PlaneOptions
from .scale_check import MIN_PEAKS, ScaleCheck, check_scale, round_factor, shapes_confirm
from .second_resonances import MISFIT_QUESTION, with_second_resonances
from .structural import mac, model_shapes, shape_is_meaningful

#: Modes searched by default: enough for identification, few enough that a
#: long stay cable's hundreds of modes below Nyquist are not all numbered.
DEFAULT_MAX_MODES = 30
#: Said of a record whose channels have no directions (:func:`~stcs_ident.core.planes.directions_note`).
NO_DIRECTIONS = NO_DIRECTIONS_NOTE


@dataclass(frozen=True, repr=False)
class TestSpectra(PickingResult):
    """Numbered modal frequencies picked from one test's record.

    ``tables()`` holds ``modes`` (the numbered modes, the main table:
    :meth:`to_dataframe`) and ``peaks`` (every peak found, numbered or not:
    :meth:`PeakResult.to_dataframe`).

    Attributes
    ----------
    name, record : test name and record path
    modes, frequencies, uncertainty : assigned peaks, ordered by mode (Hz)
    damping, damping_uncertainty : damping ratios and their 1σ (NaN where not estimated)
    channels : per mode, the channels in which the peak was seen
    doubtful : per mode, True where the mode number is doubtful
    unassigned : (frequency, uncertainty) of peaks left without a number
    dropped : (channel, reason) removed when the record was read
    peaks, numbering : the full intermediate results (for plots)
    nominal_frequencies : the nominal model's frequencies of modes 1, 2, ... that the peaks were numbered
        against (Hz; for plots), or None
    options : the picking and numbering options used (how the result was made)
    record_replaced : (option, given, file's value) the campaign's ``record_format`` replaced in the record's
        file (:attr:`Record.replaced`)
    planes : per mode, ``"in"`` or ``"out"`` (None: all in-plane, a record without channel directions)
    mac : per mode, the modal assurance criterion of its operating shape against the model's shape of the mode
        at the sensors of its plane (NaN where not meaningful: fewer than two positions, or all at its nodes)
    shapes : per mode, its operating shape: (channel, amplitude signed by phase) over its plane's channels
    structural : (frequency, uncertainty, reason) of the peaks that are not the cable's (the deck's or pylon's
        modes moving the anchorage, their harmonics): never numbered
    unassigned_planes : the plane of each of ``unassigned`` (None: all in-plane)
    plane_peaks : (plane, PeakResult) per plane, for a record with channel directions (``peaks`` is the first)
    plane_nominal : (plane, nominal frequencies) per plane, as ``plane_peaks`` (``nominal_frequencies`` is the
        first's)
    plane_options : the options of the planes and of the structural peaks used
    plane_notes : what the analysis has to say (:attr:`notes`)
    scale : per plane, the peaks numbered from their own spacing against the nominal family
        (:class:`.scale_check.ScaleCheck`); where one is implausible every number is doubtful
    """

    __test__ = False

    name: str
    record: str
    modes: tuple[int, ...]
    frequencies: np.ndarray
    uncertainty: np.ndarray
    damping: np.ndarray
    channels: tuple[tuple[str, ...], ...]
    doubtful: tuple[bool, ...]
    unassigned: tuple[tuple[float, float], ...]
    dropped: tuple[tuple[str, str], ...]
    peaks: PeakResult
    numbering: Numbering
    damping_uncertainty: np.ndarray | None = None  # 1σ of ``damping`` (NaN where not estimated)
    nominal_frequencies: np.ndarray | None = None
    options: PickingOptions = field(default_factory=PickingOptions)
    record_replaced: tuple[tuple[str, Any, Any], ...] = ()
    planes: tuple[str, ...] | None = None  # per mode, "in" or "out" (None: all in-plane)
    mac: np.ndarray | None = None
    shapes: tuple[tuple[tuple[str, float], ...], ...] | None = None
    structural: tuple[tuple[float, float, str], ...] = ()
    unassigned_planes: tuple[str, ...] | None = None
    plane_peaks: tuple[tuple[str, PeakResult], ...] = ()
    plane_nominal: tuple[tuple[str, np.ndarray], ...] = ()
    plane_options: PlaneOptions = field(default_factory=PlaneOptions)
    plane_notes: tuple[Note, ...] = ()
    scale: tuple[ScaleCheck, ...] = ()

    main_table = "modes"

    @property
    def notes(self) -> tuple[Note, ...]:
        """What the analysis has to say (a record read without channel directions, leaks set aside)."""
        return self.plane_notes

    @property
    def mode_planes(self) -> tuple[str, ...]:
        """The plane of each numbered mode (``"in"`` or ``"out"``); mode numbers count per plane."""
        return ("in",) * len(self.modes) if self.planes is None else tuple(self.planes)

    def tables(self) -> dict[str, pd.DataFrame]:
        """``modes`` (one row per numbered mode) and ``peaks`` (one row per peak found)."""
        if not self.plane_peaks:
            return {"modes": self.to_dataframe(), "peaks": self.peaks.to_dataframe()}
        frames = []
        for plane, result in self.plane_peaks:
            frame = result.to_dataframe()
            frame.insert(0, "plane", plane)
            frames.append(frame)
        return {"modes": self.to_dataframe(), "peaks": pd.concat(frames, ignore_index=True)}

    def headline(self) -> str:
        """Test, modes numbered, peaks left unnumbered, channels dropped."""
        modes = f" ({_ranges(self.modes)})" if self.modes else ""
        if self.planes is not None and self.modes:
            per_plane = [(p, [m for m, q in zip(self.modes, self.planes) if q == p]) for p in ("in", "out")]
            modes = " (" + "; ".join(f"{p} {_ranges(ms)}" for p, ms in per_plane if ms) + ")"
        extra = f", {len(self.unassigned)} peaks unnumbered" if self.unassigned else ""
        extra += f", {len(self.structural)} structural peaks" if self.structural else ""
        extra += f", {len(self.dropped)} channels dropped" if self.dropped else ""
        return f"{self.name}: {len(self.modes)} modes picked{modes} from an {self.peaks.kind} record{extra}"

    def to_dataframe(self) -> pd.DataFrame:
        """One row per numbered mode: ``mode``, ``frequency_Hz``, ``uncertainty_Hz`` (1σ), ``damping_ratio`` (not
        percent) and ``damping_ratio_uncertainty`` (NaN where not estimated), ``doubtful``, ``channels`` (joined by
        ``;``), ``plane`` and ``mac``."""
        return pd.DataFrame({
            "mode": self.modes, "frequency_Hz": self.frequencies, "uncertainty_Hz": self.uncertainty,
            "damping_ratio": self.damping, "damping_ratio_uncertainty": self.damping_sigmas(),
            "doubtful": self.doubtful, "channels": [";".join(c) for c in self.channels], "plane": self.mode_planes,
            "mac": self._macs(),
        })

    def _macs(self) -> np.ndarray:
        return np.full(len(self.modes), np.nan) if self.mac is None else np.asarray(self.mac, float)

    def damping_sigmas(self) -> np.ndarray:
        """The 1σ of each mode's damping ratio (NaN where not estimated, all NaN when none was)."""
        if self.damping_uncertainty is None:
            return np.full(len(self.modes), np.nan)
        return np.asarray(self.damping_uncertainty, float)

    def summary(self) -> dict:
        return {
            "name": self.name, "record": self.record, "kind": self.peaks.kind, "modes": list(self.modes),
            "frequencies": [float(x) for x in self.frequencies],
            "uncertainty": [float(x) for x in self.uncertainty],
            "damping": [None if math.isnan(x) else float(x) for x in self.damping],
            "damping_uncertainty": [None if math.isnan(x) else float(x) for x in self.damping_sigmas()],
            "channels": [list(c) for c in self.channels], "doubtful": list(self.doubtful),
            "unassigned": [{"frequency": f, "uncertainty": u, "plane": p} for (f, u), p in zip(
                self.unassigned, self.unassigned_planes or ("in",) * len(self.unassigned))],
            "dropped_channels": [{"channel": c, "reason": r} for c, r in self.dropped],
            "options": self.options.summary(), "record_replaced": [
                {"option": option, "given": given, "file": found} for option, given, found in self.record_replaced],
            "planes": list(self.mode_planes), "mac": [None if math.isnan(x) else float(x) for x in self._macs()],
            "shape": [dict(s) for s in self.shapes] if self.shapes is not None else [{} for _ in self.modes],
            "structural": [{"frequency": f, "uncertainty": u, "reason": r} for f, u, r in self.structural],
            "plane_options": self.plane_options.summary(), "notes": [str(n) for n in self.notes],
            "scale_check": [c.summary() for c in self.scale],
        }

    @property
    def implausible_scale(self) -> tuple[ScaleCheck, ...]:
        """The planes whose peaks' own series is implausibly far from the nominal family (a unit or
        sampling-rate slip: :mod:`.scale_check`)."""
        return tuple(c for c in self.scale if c.implausible)


def _ranges(modes) -> str:
    """``1-6, 8`` for the modes 1, 2, 3, 4, 5, 6, 8."""
    parts, start = [], None
    for k, m in enumerate(modes):
        if start is None:
            start = m
        if k + 1 == len(modes) or modes[k + 1] != m + 1:
            parts.append(str(m) if m == start else f"{start}-{m}")
            start = None
    return ", ".join(parts)


def analyse_test(campaign: Campaign, test: Test, *, max_modes: int = DEFAULT_MAX_MODES,
                 tension_model: str = "uniform", options: PickingOptions | None = None,
                 plane_options: PlaneOptions | None = None) -> TestSpectra:
    """Pick and number the modal frequencies of one test's record (in any format io reads; the test's
    ``channels`` give the positions a file lacks, its ``record_format`` the reader options, the campaign's
    top-level ones where the test gives none).

    ``options`` tunes the picking and the numbering (default: the
    calibrated values); the result records them. ``plane_options``: the planes and the structural peaks
    (:class:`.plane_options.PlaneOptions`; used for a record whose channels have directions).
    """
    path, record = open_test_record(campaign, test)
    return analyse_record(campaign, test, record, path, max_modes=max_modes, tension_model=tension_model,
                          options=options, plane_options=plane_options)


def analyse_record(campaign: Campaign, test: Test, record: Record, path: str, *, max_modes: int = DEFAULT_MAX_MODES,
                   tension_model: str = "uniform", options: PickingOptions | None = None,
                   plane_options: PlaneOptions | None = None) -> TestSpectra:
    """:func:`analyse_test` of a record already read (from ``path``); its mean is removed in place.

    A record with channel directions is analysed per plane (:mod:`.plane_analysis`); one without is read as
    in-plane throughout, and the result says so in its notes.
    """
    options = PickingOptions() if options is None else options
    plane_options = PlaneOptions() if plane_options is None else plane_options
    if not isinstance(plane_options, PlaneOptions):
        raise InputError(f"must be a PlaneOptions, got {plane_options!r}", field="plane_options")
    if campaign.structural_frequencies:  # the campaign's [structure] with those given here
        known = tuple(sorted({*plane_options.structural, *campaign.structural_frequencies}))
        plane_options = replace(plane_options, structural=known)
    cable = campaign.cable
    atts = campaign.setup(test.setup).attachments
    check_positions(record, cable.length, file=path)
    nominal = natural_frequencies(cable, atts, test.tension, max_modes, tension_model=tension_model)
    usable = 0.45  # of the sampling rate: the analysis band ends below the anti-aliasing filter's roll-off
    try:
        check_duration(record, nominal[0] / 1.5, file=path)  # a few periods of mode 1, with margin for a 15 % error
        check_bandwidth(record, nominal[0], usable=usable, file=path)
    except InputError:
        # Too short or too slowly sampled for the nominal mode 1: or a slip that moved the nominal family (a mass
        # per length typed 1000x too large or small). The record's own peaks over its whole band tell which.
        slip = _slip_only(test, record, path, cable, atts, tension_model, usable, options, plane_options)
        if slip is None:
            raise
        return slip
    if record.channel_directions is not None:
        outcome = analyse_planes(record, cable, atts, test.tension, max_modes=max_modes, tension_model=tension_model,
                                 options=options, plane_options=plane_options, nominal_in=nominal)
        return _plane_spectra(test, record, path, outcome, options, plane_options, cable, atts, test.tension,
                              tension_model)
    f_max = min(usable * record.sampling_rate, 1.3 * nominal[-1])
    result = find_peaks(record, f_min=0.5 * nominal[0], f_max=f_max, overwrite=True, expected=nominal,  # ours
                        options=options)
    freqs = np.array([p.frequency for p in result.peaks])
    unc = np.array([p.uncertainty for p in result.peaks])
    numbering = number_modes(freqs, unc, cable, atts, test.tension, options=options.numbering,
                             tension_model=tension_model)
    order = [i for i in np.argsort(numbering.modes) if numbering.modes[i] > 0]
    peaks = result.peaks
    # A numbered mode whose fit misfits its band (a deck's mode merged with it, which a record read in one plane
    # cannot see apart) has its 1σ widened as a plane's would be without an axial channel (.plane_analysis).
    widened = {i: u for i in order if (u := misfit_uncertainty(float(unc[i]), peaks[i])) is not None}
    unc = np.array([widened.get(i, u) for i, u in enumerate(unc)], float)
    macs, shapes = _operating_shapes(record, [peaks[i] for i in order], [int(numbering.modes[i]) for i in order],
                                     numbering, cable, atts, test.tension, tension_model)
    spectra = TestSpectra(
        name=test.name, record=path,
        modes=tuple(int(numbering.modes[i]) for i in order),
        frequencies=freqs[order], uncertainty=unc[order],
        damping=np.array([np.nan if peaks[i].damping is None else peaks[i].damping for i in order]),
        channels=tuple(tuple(peaks[i].channels) for i in order),
        doubtful=tuple(bool(numbering.doubtful[i]) for i in order),
        unassigned=tuple((float(freqs[i]), float(unc[i])) for i in range(len(peaks)) if numbering.modes[i] == 0),
        dropped=tuple(record.dropped), peaks=result, numbering=numbering,
        damping_uncertainty=np.array([np.nan if peaks[i].damping_uncertainty is None else peaks[i].damping_uncertainty
                                      for i in order]),
        nominal_frequencies=np.asarray(nominal, float),
        options=options, record_replaced=tuple(record.replaced), mac=macs, shapes=shapes,
        plane_options=plane_options, plane_notes=(Note.plain("directions", directions_note(record)),)
        + tuple(Note.plain("misfit", f"mode {int(numbering.modes[i])}: 1σ widened by its own half-power half-width, "
                                     f"its fit misfits its band{MISFIT_QUESTION}") for i in widened),
    )
    if shapes_confirm(macs, ("in",) * len(order), "in"):  # the shapes confirm the numbers: no slip to look for
        return _with_scale(spectra, ())
    family = _nominal_family(cable, atts, test.tension, tension_model, "in")
    check = check_scale("in", freqs, unc, family)
    if freqs.size < MIN_PEAKS and f_max < usable * record.sampling_rate and (not order or any(spectra.doubtful)):
        # Too few peaks in the nominal band to judge its scale, and no sure number among them: a mass per length
        # typed 1000x too large puts the band's top below the cable's mode 2. The scale is judged on a band
        # WIDER_BAND times wider (the numbers stay the nominal band's). A record whose few peaks the nominal
        # numbers surely is left alone (a short or quiet record of a correct campaign: the wider search would
        # cost a second picking).
        wide = find_peaks(record, f_min=0.5 * nominal[0], f_max=min(usable * record.sampling_rate, WIDER_BAND * f_max),
                          options=options)
        check = check_scale("in", [p.frequency for p in wide.peaks], [p.uncertainty for p in wide.peaks], family)
    return _with_scale(spectra, () if check is None else (check,))


def _slip_only(test: Test, record: Record, path: str, cable, atts, tension_model: str, usable: float,
               options: PickingOptions, plane_options: PlaneOptions) -> TestSpectra | None:
    """The spectra of a record the nominal model cannot even be looked for in (too short or too slowly sampled
    for its mode 1) when the record's own peaks, over its whole band, form a series implausibly far from the
    nominal family: no mode numbered, the peaks unassigned, the scale check implausible (a warning, and the
    refusal with its hint in identify, diagnose and track). None when the peaks do not say so: the record is
    then too short or too slow indeed."""
    high = usable * record.sampling_rate
    low = 8.0 / record.duration
    if not high > low:
        return None
    result = find_peaks(record, f_min=low, f_max=high, options=options)
    freqs = np.array([p.frequency for p in result.peaks])
    unc = np.array([p.uncertainty for p in result.peaks])
    check = check_scale("in", freqs, unc, _nominal_family(cable, atts, test.tension, tension_model, "in"))
    if check is None or not check.implausible:
        return None
    spectra = TestSpectra(
        name=test.name, record=path, modes=(), frequencies=np.zeros(0), uncertainty=np.zeros(0),
        damping=np.zeros(0), channels=(), doubtful=(),
        unassigned=tuple((float(f), float(u)) for f, u in zip(freqs, unc)), dropped=tuple(record.dropped),
        peaks=result, numbering=number_modes([], [], cable, atts, test.tension), damping_uncertainty=np.zeros(0),
        nominal_frequencies=None, options=options, record_replaced=tuple(record.replaced), mac=np.zeros(0),
        shapes=(), plane_options=plane_options,
        plane_notes=(Note.plain("directions", directions_note(record)),))
    return _with_scale(spectra, (check,))


#: How much wider the band searched for the scale check is when the nominal band holds too few peaks.
WIDER_BAND = 10.0


def _nominal_family(cable, atts, tension, tension_model: str, plane: str):
    """``n -> the first n nominal frequencies`` of ``plane`` (Hz)."""
    return lambda n: natural_frequencies(cable, atts, tension, max(int(n), 1), tension_model=tension_model,
                                         plane=plane)


def _with_scale(spectra: TestSpectra, checks: tuple[ScaleCheck, ...]) -> TestSpectra:
    """``spectra`` with its scale checks; where one is implausible, every number doubtful, a warning and a note
    (the peaks' own spacing says the nominal model is on another scale: :mod:`.scale_check`)."""
    spectra = with_second_resonances(blends_doubtful(low_mac_doubtful(replace(spectra, scale=checks))))
    bad = spectra.implausible_scale
    if not bad:
        return spectra
    text = "; ".join(c.sentence() for c in bad)
    factor = next((round_factor(c.ratio) for c in bad if round_factor(c.ratio) is not None), None)
    word = "" if factor is None else (f"{factor:g}× too high" if factor > 1 else f"{1 / factor:g}× too low")
    cause = (f"a sampling rate {word}, or units?" if factor is not None else
             "the units of the tension or the mass per length?")
    message = f"{spectra.name}: {text}: {cause} every mode number is doubtful"
    warnings.warn(message, NumberingWarning, stacklevel=3)
    return replace(spectra, doubtful=(True,) * len(spectra.modes),
                   plane_notes=spectra.plane_notes + (Note.plain("scale", message),))


def _operating_shapes(record: Record, peaks, modes, numbering: Numbering, cable, atts, tension, tension_model):
    """Per numbered peak of a record read in-plane: MAC against the model's shape (NaN where it cannot tell
    shapes apart) and the operating shape per channel. Reported only: the numbers stay the family fit's."""
    shapes = tuple(tuple((n, float(a)) for n, a in zip(record.channel_names, p.amplitude)) for p in peaks)
    model = model_shapes(cable, atts, tension, modes, record.channel_positions, plane="in",
                         tension_model=tension_model, tension_ratio=numbering.tension_ratio,
                         EI_ratio=numbering.EI_ratio)
    macs = np.full(len(peaks), np.nan)
    if model is not None:
        for k, p in enumerate(peaks):
            phi = model[0][:, k]
            if shape_is_meaningful(record.channel_positions, phi, model[1][k], cable.length):
                macs[k] = mac(p.amplitude, phi)
    return macs, shapes


def _plane_spectra(test: Test, record: Record, path: str, outcome: PlanesOutcome, options: PickingOptions,
                   plane_options: PlaneOptions, cable, atts, tension: float, tension_model: str) -> TestSpectra:
    """The TestSpectra of a record analysed per plane."""
    peaks = outcome.peaks
    chosen = [peaks[m.plane].peaks[m.index] for m in outcome.modes]
    first = next(iter(peaks))
    unassigned = [peaks[plane].peaks[k] for plane, k in outcome.unassigned]
    notes = tuple(Note.plain("leak", f"{PLANE_NAMES[plane]} peak at {peaks[plane].peaks[k].frequency:.4f} Hz "
                                     f"set aside: {reason}") for plane, k, reason in outcome.leaks)
    notes += tuple(Note.plain("overlap", f"{PLANE_NAMES[m.plane]} mode {m.mode}: 1σ widened by its own half-power "
                                         f"half-width, a structural resonance at {m.overlapped_by:.4f} Hz "
                                         "overlaps it") for m in outcome.modes if m.overlapped_by is not None)
    notes += tuple(Note.plain("misfit", f"{PLANE_NAMES[m.plane]} mode {m.mode}: 1σ widened by its own half-power "
                                        f"half-width, its fit misfits its band{MISFIT_QUESTION}")
                   for m in outcome.modes if m.misfit)
    spectra = TestSpectra(
        name=test.name, record=path, modes=tuple(m.mode for m in outcome.modes),
        frequencies=np.array([p.frequency for p in chosen], float),
        uncertainty=np.array([m.uncertainty for m in outcome.modes], float),
        damping=np.array([np.nan if p.damping is None else p.damping for p in chosen], float),
        channels=tuple(tuple(p.channels) for p in chosen), doubtful=tuple(m.doubtful for m in outcome.modes),
        unassigned=tuple((float(p.frequency), float(p.uncertainty)) for p in unassigned),
        dropped=tuple(record.dropped), peaks=peaks[first], numbering=outcome.numbering[first],
        damping_uncertainty=np.array([np.nan if p.damping_uncertainty is None else p.damping_uncertainty
                                      for p in chosen], float),
        nominal_frequencies=np.asarray(outcome.nominal[first], float), options=options,
        record_replaced=tuple(record.replaced), planes=tuple(m.plane for m in outcome.modes),
        mac=np.array([m.mac for m in outcome.modes], float), shapes=tuple(m.shape for m in outcome.modes),
        structural=tuple((float(peaks[plane].peaks[k].frequency), float(peaks[plane].peaks[k].uncertainty), reason)
                         for plane, k, reason in outcome.structural),
        unassigned_planes=tuple(plane for plane, _ in outcome.unassigned),
        plane_peaks=tuple(peaks.items()), plane_options=plane_options, plane_notes=notes,
        plane_nominal=tuple((plane, np.asarray(outcome.nominal[plane], float)) for plane in peaks),
    )
    return _with_scale(spectra, _plane_scale(outcome, cable, atts, tension, tension_model, spectra))


def _plane_scale(outcome: PlanesOutcome, cable, atts, tension: float, tension_model: str,
                 spectra: TestSpectra) -> tuple[ScaleCheck, ...]:
    """Each plane's scale check on its peaks, the structural ones and the leaks left out; none for a plane whose
    numbered modes' shapes confirm their numbers (:func:`.scale_check.shapes_confirm`)."""
    out = []
    for plane, result in outcome.peaks.items():
        if shapes_confirm(spectra.mac, spectra.mode_planes, plane):
            continue
        aside = {k for p, k, _ in (*outcome.structural, *outcome.leaks) if p == plane}
        kept = [p for k, p in enumerate(result.peaks) if k not in aside]
        check = check_scale(plane, [p.frequency for p in kept], [p.uncertainty for p in kept],
                            _nominal_family(cable, atts, tension, tension_model, plane))
        if check is not None:
            out.append(check)
    return tuple(out)


def analyse_campaign(campaign: Campaign, tests: list[str] | None = None, *, progress=None,
                     tension_model: str = "uniform", options: PickingOptions | None = None,
                     plane_options: PlaneOptions | None = None) -> list[TestSpectra]:
    """:func:`analyse_test` for every selected test that has a record (with the same ``options``)."""
    selected = [campaign.test(n) for n in tests] if tests else list(campaign.tests)
    with_record = [t for t in selected if t.record is not None]
    out = []
    for k, test in enumerate(with_record, 1):
        if progress is not None:
            progress(f"spectra: test {test.name} ({k} of {len(with_record)})")
        out.append(analyse_test(campaign, test, tension_model=tension_model, options=options,
                                plane_options=plane_options))
    return out


def campaign_summary(name: str, results, skipped=()) -> dict:
    """The ``spectra CAMPAIGN`` JSON: the campaign's name, each analysed test's :meth:`TestSpectra.summary` and
    the tests skipped (no record)."""
    return {"campaign": name, "tests": [r.summary() for r in results], "skipped": list(skipped)}
