"""Peaks picked and numbered per plane, and the peaks that are not the cable's (a record with channel directions).

1. Channels by plane (:mod:`.channels`): in-plane and out-of-plane components, axial channels aside.
2. Peaks per plane: :func:`.peaks.find_peaks` on each plane's channels alone, so a mode of one plane is fitted
   with the noise of that plane's channels and a close pair (an in-plane and an out-of-plane mode a few per
   mil apart, each in its own channels) is never fitted as one peak. (Fitting the axial channels with them
   was tried: a deck mode's broad skirt on the axial channel then pulled a cable mode 9 % away by 10σ.) A peak found in both planes within 3σ
   is one mode leaking through a misaligned sensor where the weaker plane's amplitude (rms over its
   channels) is below ``leak_ratio`` of the stronger's: it is kept in the stronger plane only. Otherwise
   both planes carry it: two peaks, never merged.
3. Structural peaks (:mod:`.structural`): a peak at a given structural frequency or a harmonic of one, or
   where the axial channels' amplitude (fine Welch spectra) reaches ``axial_ratio`` of the plane's
   largest (the anchorage moving along the chord), is set aside before numbering. Each plane's peaks are numbered against that plane's family
   (:func:`.numbering.number_modes` with ``plane``); a numbered peak whose operating shape has a MAC below
   ``min_mac`` against its mode's model shape (where meaningful) is structural, and the plane is numbered
   again without it. Of the unassigned peaks, one found in both planes with the other plane's peak not a
   cable mode either, or at a harmonic of a structural peak, is structural.
   The rest stay unassigned.
4. Uncertainty: a numbered mode's 1σ is widened by its half-power half-width where a structural resonance
   overlaps it (:func:`_overlapped`) or, in a record without axial channels, where its fit misfits its band
   (:func:`_misfit`: a deck mode merged with it, seen by nothing else).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..core.errors import InputError
from ..core.planes import PLANE_NAMES
from ..core.record import Record
from ..forward import natural_frequencies
from .channels import PlaneChannels, plane_channels, plane_record
from .numbering import Numbering, number_modes
from .options import PickingOptions
from .peak_result import PeakResult
from .peaks import find_peaks
from .plane_options import PlaneOptions
from .structural import harmonic_of, mac, model_shapes, shape_is_meaningful

__all__ = ["PlaneMode", "PlanesOutcome", "analyse_planes", "misfit_uncertainty"]


@dataclass(frozen=True)
class PlaneMode:
    """One numbered peak of one plane."""

    plane: str
    mode: int
    index: int  # in the plane's PeakResult
    doubtful: bool
    mac: float  # NaN where not meaningful
    shape: tuple[tuple[str, float], ...]
    uncertainty: float  # the peak's 1σ, widened where a structural resonance overlaps it (Hz)
    overlapped_by: float | None = None  # that resonance's frequency (Hz)
    misfit: bool = False  # 1σ widened as the band is not one mode's (:func:`_misfit`)


@dataclass(frozen=True)
class PlanesOutcome:
    """What :func:`analyse_planes` found: per plane its channels, peaks, numbering and nominal frequencies;
    the numbered modes, the unassigned and the structural peaks (plane, index, reason), the leaks dropped."""

    channels: dict[str, PlaneChannels]
    peaks: dict[str, PeakResult]
    numbering: dict[str, Numbering]
    nominal: dict[str, np.ndarray]
    modes: list[PlaneMode] = field(default_factory=list)
    unassigned: list[tuple[str, int]] = field(default_factory=list)
    structural: list[tuple[str, int, str]] = field(default_factory=list)
    leaks: list[tuple[str, int, str]] = field(default_factory=list)


def analyse_planes(record: Record, cable, attachments, tension: float, *, max_modes: int, tension_model: str,
                   options: PickingOptions, plane_options: PlaneOptions,
                   nominal_in: np.ndarray | None = None) -> PlanesOutcome:
    """Peaks per plane, numbered per plane, structural ones set apart (the module's steps). ``nominal_in``: the
    in-plane nominal frequencies of ``max_modes`` modes when the caller has them already."""
    channels, axial = plane_channels(record)
    if not channels:
        raise InputError("every channel is axial: the cable's transverse modes need an in-plane or out-of-plane "
                         "channel", field="channel_direction", file=record.source)
    fs = record.sampling_rate
    peaks, nominal, axial_share = {}, {}, {}
    for plane in channels:
        nominal[plane] = (nominal_in if plane == "in" and nominal_in is not None else
                          natural_frequencies(cable, attachments, tension, max_modes, tension_model=tension_model,
                                              plane=plane))
    bands = {plane: (0.5 * nominal[plane][0], min(0.45 * fs, 1.3 * nominal[plane][-1])) for plane in channels}
    for plane, chans in channels.items():
        sub = plane_record(record, chans, axial)
        if axial:
            axial_share[plane] = _axial_share(sub.acceleration, len(chans), fs, options)
            sub = plane_record(record, chans)
        peaks[plane] = find_peaks(sub, *bands[plane], overwrite=True, options=options,
                                  expected=nominal[plane])  # the plane's record is a copy, ours
    out = PlanesOutcome(channels, peaks, {}, nominal)
    kept = {plane: set(range(len(result.peaks))) for plane, result in peaks.items()}
    structural: dict[tuple[str, int], str] = {}
    given = [(f, 0.0) for f in plane_options.structural]
    for plane, result in peaks.items():
        for k, p in enumerate(result.peaks):
            hit = harmonic_of(p.frequency, p.uncertainty, given, plane_options.max_harmonic)
            if hit is not None:
                structural[(plane, k)] = _harmonic_text(*hit, "given structural frequency")
            elif plane in axial_share:  # axial channels: the anchorage moving along the chord
                ratio = axial_share[plane](p.frequency)
                if ratio >= plane_options.axial_ratio:
                    structural[(plane, k)] = (f"on the axial channels at {ratio:.2f} of the transverse amplitude: "
                                              "the anchorage moving")
    pairs = _pairs(peaks)
    for (i, j) in pairs:
        a, b = peaks["in"].peaks[i], peaks["out"].peaks[j]
        if ("in", i) in structural and ("out", j) in structural:  # one structural peak, seen by both: once
            weak = ("in", i) if a.uncertainty > b.uncertainty else ("out", j)
            kept[weak[0]].discard(weak[1])
            del structural[weak]
            continue
        if ("in", i) in structural or ("out", j) in structural:
            continue
        sa, sb = _strength(a.amplitude[:len(channels["in"])]), _strength(b.amplitude[:len(channels["out"])])
        if min(sa, sb) < plane_options.leak_ratio * max(sa, sb):
            weak, strong = (("in", i), "out") if sa < sb else (("out", j), "in")
            kept[weak[0]].discard(weak[1])
            out.leaks.append((*weak, f"the {PLANE_NAMES[strong]} mode leaking through a sensor's misalignment"))
    numbering_options = options.numbering
    order = sorted(peaks, key=lambda pl: -sum((pl, k) not in structural for k in kept[pl]))  # the richer first
    for plane in order:
        result = peaks[plane]
        candidates = [k for k in sorted(kept[plane]) if (plane, k) not in structural]
        for attempt in range(4):  # numbered, then again without the peaks whose shape is not their mode's
            numbering = _number(result, candidates, cable, attachments, tension, tension_model, numbering_options,
                                plane)
            shapes = _shapes(result, channels[plane], candidates, numbering, cable, attachments, tension,
                             tension_model, plane)
            rejected = [k for k, (value, meaningful, mode) in shapes.items()
                        if meaningful and value < plane_options.min_mac and attempt < 3]
            for k in rejected:
                value, _, mode = shapes[k]
                structural[(plane, k)] = (f"operating shape unlike mode {mode}'s ({PLANE_NAMES[plane]}): "
                                          f"MAC {value:.2f}")
            if not rejected:
                break
            candidates = [k for k in candidates if k not in rejected]
            if np.sum(numbering.modes > 0) >= 2:  # numbered again near the family just found
                numbering_options = _near(numbering_options, numbering)
        out.numbering[plane] = numbering
        if np.sum(numbering.modes > 0) >= 2:
            # The planes share the tension and the bending stiffness: the next plane's family is searched
            # near this one's (the planes' models differ by sag and attachments, which they model).
            numbering_options = _near(options.numbering, numbering)
        names = channels[plane].names
        for pos, k in enumerate(candidates):
            mode = int(numbering.modes[pos])
            if mode > 0:
                value, meaningful, _ = shapes[k]
                amplitude = result.peaks[k].amplitude[:len(names)]
                out.modes.append(PlaneMode(plane, mode, k, bool(numbering.doubtful[pos]),
                                           value if meaningful else float("nan"),
                                           tuple((n, float(a)) for n, a in zip(names, amplitude)),
                                           float(result.peaks[k].uncertainty)))
            else:
                out.unassigned.append((plane, k))
    _unassigned_structural(out, pairs, structural, plane_options)
    resonances = [(peaks[pl].peaks[k].frequency, peaks[pl].peaks[k].damping) for pl, k in structural]
    resonances += [(order * f, None) for f in plane_options.structural
                   for order in range(1, plane_options.max_harmonic + 1)]
    if axial:
        resonances += _axial_resonances(record, axial, bands, axial_share, options, plane_options)
    resonances += [(2 * f, zeta) for f, zeta in resonances[:] if zeta is not None]  # the structure's 2nd harmonic
    typical = {plane: _typical_damping([peaks[m.plane].peaks[m.index] for m in out.modes if m.plane == plane])
               for plane in peaks}
    out.modes[:] = [_overlapped(m, peaks[m.plane].peaks[m.index], resonances, typical[m.plane])
                    for m in out.modes]
    if not axial:  # nothing sees a structural resonance apart: the band's misfit tells of one merged
        out.modes[:] = [_misfit(m, peaks[m.plane].peaks[m.index]) for m in out.modes]
    out.structural.extend((plane, k, reason) for (plane, k), reason in structural.items())
    out.structural.sort(key=lambda s: peaks[s[0]].peaks[s[1]].frequency)
    out.modes.sort(key=lambda m: (m.plane != "in", m.mode))
    return out


def _number(result: PeakResult, candidates, cable, attachments, tension, tension_model, options,
            plane) -> Numbering:
    f = np.array([result.peaks[k].frequency for k in candidates], float)
    u = np.array([result.peaks[k].uncertainty for k in candidates], float)
    return number_modes(f, u, cable, attachments, tension, options=options, tension_model=tension_model,
                        plane=plane)


#: The second plane's family is searched within these factors of the first plane's fitted tension and
#: bending-stiffness ratios (3 %: ten model tolerances, since the planes' models differ only by what they
#: model, sag and attachments; EI within 1.5 times, as a few modes determine it poorly).
NEAR_TENSION, NEAR_EI = 1.03, 1.5


def _near(options, numbering: Numbering):
    """``options`` (NumberingOptions) with the ranges narrowed around ``numbering``'s fitted ratios (within the
    original ranges)."""
    def around(value, factor, bounds):
        low, high = max(value / factor, bounds[0]), min(value * factor, bounds[1])
        return (low, high) if low < high else bounds

    return replace(options, tension_range=around(numbering.tension_ratio, NEAR_TENSION, options.tension_range),
                   EI_range=around(numbering.EI_ratio, NEAR_EI, options.EI_range))


def _shapes(result, chans: PlaneChannels, candidates, numbering, cable, attachments, tension, tension_model,
            plane) -> dict[int, tuple[float, bool, int]]:
    """Per numbered candidate: (MAC against its mode's model shape, whether meaningful, mode)."""
    numbered = [(k, int(m)) for k, m in zip(candidates, numbering.modes) if m > 0]
    if not numbered:
        return {}
    model = model_shapes(cable, attachments, tension, [m for _, m in numbered], chans.positions, plane=plane,
                         tension_model=tension_model, tension_ratio=numbering.tension_ratio,
                         EI_ratio=numbering.EI_ratio)
    out = {}
    for col, (k, mode) in enumerate(numbered):
        if model is None:
            out[k] = (float("nan"), False, mode)
            continue
        phi, largest = model[0][:, col], model[1][col]
        value = mac(result.peaks[k].amplitude[:len(chans)], phi)
        meaningful = shape_is_meaningful(chans.positions, phi, largest, cable.length) and np.isfinite(value)
        out[k] = (value, bool(meaningful), mode)
    return out


def _pairs(peaks: dict[str, PeakResult]) -> list[tuple[int, int]]:
    """(in index, out index) of the peaks found in both planes within 3σ (combined), nearest first, each peak in
    one pair at most."""
    if "in" not in peaks or "out" not in peaks:
        return []
    a, b = peaks["in"].peaks, peaks["out"].peaks
    close = []
    for i, p in enumerate(a):
        for j, q in enumerate(b):
            z = abs(p.frequency - q.frequency) / np.hypot(p.uncertainty, q.uncertainty)
            if z <= 3.0:
                close.append((z, i, j))
    used_a, used_b, out = set(), set(), []
    for _, i, j in sorted(close):
        if i not in used_a and j not in used_b:
            used_a.add(i)
            used_b.add(j)
            out.append((i, j))
    return out


def _strength(amplitude: np.ndarray) -> float:
    """A peak's amplitude over a plane's channels (rms)."""
    return float(np.sqrt(np.mean(np.square(amplitude)))) if len(amplitude) else 0.0


def _harmonic_text(base: float, order: int, what: str) -> str:
    if order == 1:
        return f"at the {what} {base:.4g} Hz"
    return f"harmonic {order} of the {what} {base:.4g} Hz"


def _unassigned_structural(out: PlanesOutcome, pairs, structural: dict, plane_options: PlaneOptions) -> None:
    """Move the unassigned peaks found in both planes or at a structural harmonic into ``structural`` (in
    place)."""
    if not out.unassigned:
        return
    peaks = out.peaks
    unassigned = set(out.unassigned)
    partner = {("in", i): ("out", j) for i, j in pairs} | {("out", j): ("in", i) for i, j in pairs}
    for key in sorted(unassigned):
        other = partner.get(key)
        if other is not None and (other in unassigned or other in structural):
            structural[key] = "in both planes at one frequency"
    changed = True
    while changed:  # harmonics of the structural peaks, found or given
        changed = False
        bases = [(peaks[pl].peaks[k].frequency, peaks[pl].peaks[k].uncertainty) for pl, k in structural]
        for key in sorted(unassigned):
            if key in structural:
                continue
            p = peaks[key[0]].peaks[key[1]]
            hit = harmonic_of(p.frequency, p.uncertainty, bases, plane_options.max_harmonic)
            if hit is not None:
                structural[key] = _harmonic_text(*hit, "structural peak at")
                changed = True
    out.unassigned[:] = [key for key in out.unassigned if key not in structural]


def _axial_share(x: np.ndarray, n: int, fs: float, options: PickingOptions):
    """f ↦ the largest amplitude at f on the axial channels (columns ``n`` on of ``x``) over the largest on the
    transverse ones (the first ``n``), from fine Welch spectra (4 segments: a resolution of a quarter of the
    record's, a few times a lightly damped cable mode's half-power width on the usual records, so a sharp
    cable mode stands above a broad deck mode a per cent away; the overview's 16 segments smeared the
    cable's peak and a cable mode 1 % from a deck mode took the deck's axial share). ``options``: unused,
    the spectra's tuning is fixed here."""
    from scipy.signal import welch

    segment = max(256, x.shape[0] // 4)
    frequency, power = welch(x - x.mean(axis=0), fs, nperseg=min(segment, x.shape[0]), axis=0)

    def share(f: float) -> float:
        k = int(np.argmin(np.abs(frequency - f)))
        transverse, along = power[k, :n].max(), power[k, n:].max()
        return float(np.sqrt(along / transverse)) if transverse > 0 else float("inf")

    return share


#: A structural resonance overlaps a cable mode within this many of its half-power half-widths ζ_s f_s
#: (:func:`_overlapped`).
OVERLAP_WIDTHS = 4.0
#: Damping ratio taken for a resonance whose damping is not known (a given structural frequency; 2 %: a deck
#: or pylon mode's is 0.5–2 %, the wider the more cable modes it is said to overlap).
STRUCTURAL_DAMPING = 0.02
#: A peak of the axial channels alone is the anchorage's, for widening the 1σ of the cable modes it
#: overlaps, where the axial share reaches this (0.1: a sensor turned by 5.7° reads that much of a cable
#: mode along the chord; lower than ``axial_ratio``, since a deck mode merged with a cable mode shares the
#: transverse channels with it, and a widened 1σ costs little where a missed one costs coverage).
AXIAL_RESONANCE_SHARE = 0.1
#: Damping ratio taken for a cable mode whose fit gave none (0.5 %).
CABLE_DAMPING = 0.005
#: An overlapped mode's ζ is taken as at least this share of the median ζ of its plane's numbered modes
#: (:func:`_overlapped`).
TYPICAL_DAMPING_SHARE = 0.5
#: Share of the half-power half-width ζ f added in quadrature to an overlapped mode's 1σ (:func:`_overlapped`)
#: and to a misfitting one's (:func:`_misfit`): the pull is spread over up to ζ f, and the whole of it
#: over-covered (set on seeds 0–49 of the bridge records, below).
OVERLAP_SHARE = 0.8
MISFIT_SHARE = 0.7


def _typical_damping(peaks) -> float:
    """The median fitted ζ of a plane's numbered peaks (NaN when none has one)."""
    values = [p.damping for p in peaks if p.damping is not None and np.isfinite(p.damping)]
    return float(np.median(values)) if values else float("nan")


def _overlapped(mode: PlaneMode, peak, resonances, typical_damping: float = float("nan")) -> PlaneMode:
    """``mode`` with its 1σ widened where a structural resonance overlaps it.

    The fit of a cable mode takes the background under it as flat; a deck's or pylon's resonance a per cent
    away is not (the anchorage's narrow-band motion drives the cable there), and the fitted maximum moves
    by up to about the cable mode's own half-power half-width ζ f. On simulated bridge records (a deck mode
    within 0.5–2 % of a cable mode, the cable's exact dynamic answer to the support's motion) the modes
    beyond 3σ were nearly all within 2 % of a deck mode or its harmonic, off by 0.2–0.5 % of f with ζ of
    0.3–0.8 %. So the 1σ gains ζ f in quadrature, for a resonance within ``OVERLAP_WIDTHS`` of its
    half-power half-widths (set on seeds 0–49 of benchmarks/plane_records.make_bridge_case, triaxial: 3σ
    coverage 96–98 % → 98–99 %, 1σ 65–67 % → 69–70 %; ζ f / √3 within 3 widths gave the former).

    The pull also narrows the fitted ζ (the deck's motion, narrower than the cable's resonance, shapes the
    peak): the modes off by 3σ or more had a fitted ζ of 0.05–0.2 % where their plane's other modes had
    0.3–0.8 %. So ζ is taken as at least :data:`TYPICAL_DAMPING_SHARE` of ``typical_damping``, the median ζ of
    the plane's numbered modes in the same record (set on the same seeds 0–49, all four kinds × layouts:
    triaxial 3σ coverage in / out 98.9 / 98.7 % → 99.3 / 99.1 %, 1σ 69.8 / 70.1 % → 71.9 / 71.4 %; the whole
    median gave 76.7 / 74.6 % within 1σ, too wide). The widened modes were then within 1σ for 82 / 87 % with
    the whole ζ f and all within 3σ: :data:`OVERLAP_SHARE` of it is added (with :data:`MISFIT_SHARE` in
    :func:`_misfit`, 3σ coverage of all four kinds × layouts in / out 98.8 / 98.8 %, 1σ 70.3 / 68.8 %).
    """
    f = peak.frequency
    zeta = peak.damping if peak.damping is not None and np.isfinite(peak.damping) else CABLE_DAMPING
    if np.isfinite(typical_damping):
        zeta = max(zeta, TYPICAL_DAMPING_SHARE * typical_damping)
    for f_s, zeta_s in resonances:
        zeta_s = STRUCTURAL_DAMPING if zeta_s is None or not np.isfinite(zeta_s) else zeta_s
        if abs(f - f_s) <= max(OVERLAP_WIDTHS * zeta_s * f_s, 3 * mode.uncertainty):
            sigma = float(np.hypot(mode.uncertainty, OVERLAP_SHARE * zeta * f))
            return replace(mode, uncertainty=sigma, overlapped_by=float(f_s))
    return mode


#: A cable mode's fit whose misfit-robust 1σ exceeds the Fisher information's by this factor
#: (:attr:`.peak_result.Peak.misfit`) holds more than one resonance, in a record without axial channels
#: (:func:`_misfit`).
MISFIT_RATIO = 1.15


def _misfit(mode: PlaneMode, peak) -> PlaneMode:
    """``mode`` with its 1σ widened by :data:`MISFIT_SHARE` of the half-power half-width max(ζ,
    :data:`CABLE_DAMPING`) f in quadrature where its fit misfits its band (:data:`MISFIT_RATIO`) and no
    structural resonance widened it already.

    Without an axial channel a deck mode within a per cent or two of a cable mode is rarely a peak of its
    own: the cable's mode, driven through its anchorage by the deck's narrow-band motion (2–4 % wide), is one
    peak whose excitation is far from white across it; its maximum is pulled towards the deck's by up to
    ζ f, and the fitted ζ is narrowed (the fitted ζ of the modes within 2 % of a deck mode or its harmonic:
    median 0.31 %, against 0.57 % for the others of the same records; hence the floor). One motion only:
    the cross-spectral matrix of the plane's channels there is of rank one (second singular value 0.000 of
    the first, median, on the modes off by 3σ or more; 0.001–0.004 elsewhere). What shows is the fit's
    misfit: its sandwich 1σ over its Fisher 1σ exceeded 1.15 for 54 % of the modes within 2 % of a
    structural frequency and for 7 % of those 5 % or more from one (benchmarks/plane_records.
    make_bridge_case, biaxial, seeds 0–99: 3σ coverage in / out 92.4 / 92.3 % → 98.6 / 97.9 %, 1σ
    57.8 / 56.5 % → 72.7 / 66.8 %; with the share, seeds 0–49 of all four kinds × layouts: see
    :func:`_overlapped`).
    """
    sigma = None if mode.overlapped_by is not None else misfit_uncertainty(mode.uncertainty, peak)
    return mode if sigma is None else replace(mode, uncertainty=sigma, misfit=True)


def misfit_uncertainty(uncertainty: float, peak) -> float | None:
    """``uncertainty`` (Hz) with :data:`MISFIT_SHARE` of the half-power half-width max(ζ, :data:`CABLE_DAMPING`) f
    added in quadrature where ``peak``'s fit misfits its band (:data:`MISFIT_RATIO`: :func:`_misfit`); None where
    it does not. Used as well on a record read in one plane (no channel directions), where nothing else can see a
    resonance merged with a cable mode: measured on :func:`benchmarks.plane_records.make_bridge_case` records
    reduced to their in-plane channels without directions (seeds 400-439, not used to set the constants), the
    in-plane modes within 2 % of a structural frequency within 1σ / 3σ 45.5 / 90.9 → 80.0 / 94.5 % (stays) and
    36 / 90 → 70 / 94 % (hangers), the others 73.8 / 98.4 → 75.4 / 99.2 % and 66.0 / 97.9 → 68.8 / 99.3 %."""
    if not peak.misfit > MISFIT_RATIO:
        return None
    zeta = peak.damping if peak.damping is not None and np.isfinite(peak.damping) else CABLE_DAMPING
    return float(np.hypot(uncertainty, MISFIT_SHARE * max(zeta, CABLE_DAMPING) * peak.frequency))


def _axial_resonances(record: Record, axial, bands: dict, axial_share: dict, options: PickingOptions,
                      plane_options: PlaneOptions) -> list[tuple[float, float | None]]:
    """(frequency, damping) of the peaks of the axial channels alone where they are the anchorage's (the
    axial share at least :data:`AXIAL_RESONANCE_SHARE` in a plane): a deck mode beside a cable mode, which the
    plane's picking sees merged with the cable's, stands alone there. (``plane_options``: unused here.)"""
    low, high = min(b[0] for b in bands.values()), max(b[1] for b in bands.values())
    x = record.acceleration[:, list(axial)]
    along = Record(acceleration=x - x.mean(axis=0), sampling_rate=record.sampling_rate,
                   channel_names=tuple(record.channel_names[k] for k in axial),
                   channel_positions=record.channel_positions[list(axial)])
    out = []
    for p in find_peaks(along, low, high, overwrite=True, options=options).peaks:
        if any(share(p.frequency) >= AXIAL_RESONANCE_SHARE for share in axial_share.values()):
            out.append((p.frequency, p.damping))
    return out

