"""Simulated biaxial and triaxial records of a cable with the deck's modes moving its anchorage (for
tests/test_spectra_planes.py and benchmarks/spectra.py).

Each plane's response is the project's simulator run on that plane's model (out-of-plane:
:func:`~stcs_ident.core.planes.plane_view`), with independent wind in each plane; the planes are uncoupled.
A deck mode is a lightly damped oscillator driven by white noise (the traffic) that moves the anchorage at
end A: the cable follows it quasi-statically, (1 − x/l) times the anchorage's transverse motion in the
plane the deck moves it, and along the chord as a whole (the axial channels). Its second harmonic (a
nonlinear bearing) rides on it at a tenth of its amplitude. Sensor noise is white, per channel at
``snr_db`` below the channel's rms.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from stcs_ident.core.model import Attachment, Cable, Campaign, Setup, Test
from stcs_ident.core.planes import plane_view
from stcs_ident.core.record import Record
from stcs_ident.simulate import Ambient
from stcs_ident.simulate.simulate import simulate_record_with_truth

STAY = Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=math.radians(30))
STAY_ATTS = (Attachment("clamp", 6.0, 40.0),)
HANGER = Cable(length=12.0, mass_per_length=30.0, EI=2.0e5)
HANGER_ATTS = (Attachment("clamp", 2.7, 15.0),)


@dataclass(frozen=True)
class Kind:
    """One cable and how it is recorded."""

    name: str
    cable: Cable
    attachments: tuple
    tension: float
    sampling_rate: float
    duration: float
    positions: tuple[float, ...]  # fractions of the span


KINDS = {
    "stay": Kind("stay", STAY, STAY_ATTS, 4.0e6, 12.8, 400.0, (0.17, 0.29, 0.41)),
    "hanger": Kind("hanger", HANGER, HANGER_ATTS, 4.0e5, 128.0, 80.0, (0.19, 0.33, 0.44)),
}


@dataclass
class PlaneCase:
    """A simulated record and what it truly holds."""

    record: Record
    campaign: Campaign
    test: Test
    truth: dict  # plane -> true frequencies (Hz) of modes 1, 2, ...
    deck: list = field(default_factory=list)  # (frequency, plane) of the deck modes
    structural: list = field(default_factory=list)  # every structural frequency in the record (with harmonics)
    visible: dict = field(default_factory=dict)  # plane -> number of modes below the analysis band's top


def make_case(kind: str, seed: int, *, layout: str = "biaxial", deck: bool = True, snr_db: float = 30.0,
              near: float | None = None) -> PlaneCase:
    """One record. ``layout``: "biaxial" (in and out at each position), "triaxial" (and an axial channel at
    the first position). ``near``: the relative distance of the first deck mode from a cable mode (default
    drawn in 0.5–2 %)."""
    k = KINDS[kind]
    rng = np.random.default_rng(seed)
    tension_true = k.tension * rng.uniform(0.93, 1.07)  # the nominal tension a few per cent off
    positions = np.array(k.positions) * k.cable.length
    fs, n = k.sampling_rate, round(k.duration * k.sampling_rate)
    planes, truth = {}, {}
    for j, plane in enumerate(("in", "out")):
        cable, atts = plane_view(k.cable, k.attachments, plane)
        record, rt = simulate_record_with_truth(
            cable, atts, tension_true, positions, duration=k.duration, sampling_rate=fs,
            damping=rng.uniform(0.003, 0.008), ambient=Ambient(rms_pressure=rng.uniform(5.0, 15.0)),
            seed=int(rng.integers(2**31)) + j)
        planes[plane] = record.acceleration
        truth[plane] = np.asarray(rt.frequencies, float)
    signal = {"in": planes["in"], "out": planes["out"], "axial": np.zeros((n, 1))}
    decks = []
    if deck:
        top = min(0.45 * fs, truth["in"][-1])
        plane = "in" if rng.random() < 0.6 else "out"
        mode = int(rng.integers(1, min(6, int(np.sum(truth[plane] < top)))))
        offset = near if near is not None else rng.uniform(0.005, 0.02)
        f1 = truth[plane][mode] * (1 + offset * rng.choice([-1.0, 1.0]))
        f2 = rng.uniform(1.2 * truth["in"][0], 0.5 * top)
        for f_deck, deck_plane, scale in ((f1, plane, 1.0), (f2, "in" if plane == "out" else "out", 0.7)):
            motion = _oscillator(rng, n, fs, f_deck, rng.uniform(0.01, 0.02))
            harmonic = _oscillator(rng, n, fs, 2 * f_deck, 0.01) if 2 * f_deck < 0.45 * fs else 0.0
            d = motion + 0.1 * harmonic * np.std(motion) / max(np.std(harmonic), 1e-30)
            level = scale * np.std(signal[deck_plane]) / np.std(d)
            shape = 1.0 - positions / k.cable.length
            signal[deck_plane] = signal[deck_plane] + level * d[:, None] * shape[None, :]
            signal["axial"] = signal["axial"] + 0.5 * level * d[:, None]
            decks.append((float(f_deck), deck_plane))
    columns, names, where, directions = [], [], [], []
    for i, x in enumerate(positions):
        for plane in ("in", "out"):
            columns.append(signal[plane][:, i])
            names.append(f"{plane}{i + 1}")
            where.append(x)
            directions.append(plane)
    if layout == "triaxial":
        columns.append(signal["axial"][:, 0] + 1e-3 * np.std(signal["in"]) * rng.standard_normal(n))
        names.append("ax1")
        where.append(positions[0])
        directions.append("axial")
    acc = np.column_stack(columns)
    acc = acc + acc.std(axis=0) * 10 ** (-snr_db / 20) * rng.standard_normal(acc.shape)
    record = Record(acceleration=acc, sampling_rate=fs, channel_names=tuple(names),
                    channel_positions=np.array(where), channel_directions=tuple(directions))
    setup = Setup("s", k.attachments)
    test = Test("t", "s", k.tension)
    campaign = Campaign("c", k.cable, (setup,), (test,))
    structural = [f * h for f, _ in decks for h in (1, 2)]
    return PlaneCase(record, campaign, test, truth, decks, structural)


def _oscillator(rng, n: int, fs: float, frequency: float, zeta: float) -> np.ndarray:
    """The acceleration of a white-noise-driven oscillator (exact discretisation of its pole pair)."""
    from scipy.signal import lfilter

    w = 2 * math.pi * frequency
    pole = np.exp((-zeta * w + 1j * w * math.sqrt(1 - zeta**2)) / fs)
    a = [1.0, -2 * pole.real, abs(pole) ** 2]
    burn = int(10 / (zeta * frequency) * fs / (2 * math.pi)) + 1
    x = lfilter([1.0], a, rng.standard_normal(n + burn))[burn:]
    return x


def make_bridge_case(kind: str, seed: int, *, layout: str = "triaxial", near: float | None = None,
                     traffic: bool = True, misalignment: float = 1.5, snr_db: float = 30.0,
                     deck: bool = True) -> PlaneCase:
    """One record from the project's simulator with a bridge (:class:`~stcs_ident.simulate.BridgeConditions`):
    both planes under independent wind, sensors misaligned by N(0, ``misalignment``°), two deck modes moving
    anchorage A (the exact dynamic answer of the cable to a support motion, so a deck mode beside a cable
    mode drives it), one within 0.5–2 % (``near``) of a cable mode of its plane, one elsewhere in the band,
    each with a second harmonic at a tenth, and vehicles crossing (``traffic``)."""
    from stcs_ident.forward import natural_frequencies
    from stcs_ident.simulate.bridge import BridgeConditions, StructuralMode, Traffic
    from stcs_ident.simulate.simulate import simulate_record

    k = KINDS[kind]
    rng = np.random.default_rng(seed)
    tension_true = k.tension * rng.uniform(0.93, 1.07)
    positions = np.array(k.positions) * k.cable.length
    fs = k.sampling_rate
    xs = [x for x in positions for _ in ("in", "out")]
    directions = [d for _ in positions for d in ("in", "out")]
    if layout == "triaxial":
        xs.append(positions[0])
        directions.append("axial")
    kw = {"duration": k.duration, "sampling_rate": fs, "damping": rng.uniform(0.003, 0.008),
          "ambient": Ambient(rms_pressure=rng.uniform(5.0, 15.0)), "snr_db": snr_db, "seed": int(rng.integers(2**31))}
    quiet = simulate_record(k.cable, k.attachments, tension_true, xs, directions=directions, **kw)
    level = float(np.std(quiet.acceleration[:, [i for i, d in enumerate(directions) if d != "axial"]]))
    top = 0.45 * fs
    nominal = {p: natural_frequencies(k.cable, k.attachments, tension_true, 12, plane=p) for p in ("in", "out")}
    plane = "in" if rng.random() < 0.6 else "out"
    mode = int(rng.integers(1, min(6, int(np.sum(nominal[plane] < top)))))
    offset = near if near is not None else rng.uniform(0.005, 0.02)
    f1 = nominal[plane][mode] * (1 + offset * rng.choice([-1.0, 1.0]))
    f2 = rng.uniform(1.2 * nominal["in"][0], 0.5 * top)
    way = {"in": (0.8, 0.1, 0.6), "out": (0.15, 0.95, 0.3)}  # vertical deck motion; lateral (a pylon's sway)
    decks = [StructuralMode(f, rng.uniform(0.3, 1.0) * level * scale, damping=rng.uniform(0.01, 0.02), end="A",
                            direction=way[p], harmonics=(0.1,))
             for f, p, scale in ((f1, plane, 1.0), (f2, "in" if plane == "out" else "out", 0.7))]
    bridge = BridgeConditions(
        out_of_plane_ratio=rng.uniform(0.5, 1.0),
        misalignment=tuple(float(v) for v in rng.normal(0.0, misalignment, len(xs))) if misalignment else None,
        anchorage_motion=tuple(decks) if deck else (), traffic=Traffic(rng.uniform(20.0, 60.0)) if traffic else None)
    record, truth = simulate_record_with_truth(k.cable, k.attachments, tension_true, xs, directions=directions,
                                               bridge=bridge, **kw)
    names = [f"{d}{1 + i // 2}" if d != "axial" else "ax1" for i, d in enumerate(directions)]
    record = Record(acceleration=record.acceleration, sampling_rate=fs, channel_names=tuple(names),
                    channel_positions=record.channel_positions, channel_directions=record.channel_directions)
    setup = Setup("s", k.attachments)
    test = Test("t", "s", k.tension)
    campaign = Campaign("c", k.cable, (setup,), (test,))
    truths = {"in": np.asarray(truth.frequencies, float), "out": np.asarray(truth.out.frequencies, float)}
    deck_list = [(d.frequency, p) for d, p in zip(decks, (plane, "in" if plane == "out" else "out"))] if deck else []
    return PlaneCase(record, campaign, test, truths, deck_list, [f * h for f, _ in deck_list for h in (1, 2)])


#: Bins of a mode's distance from the nearest structural frequency (a deck mode or its harmonic), relative.
OFFSET_BINS = ((0.0, 0.005), (0.005, 0.01), (0.01, 0.02), (0.02, 0.05), (0.05, math.inf))


def offset_coverage(kind: str, seeds, *, layout: str = "biaxial") -> list[dict]:
    """Per bin of :data:`OFFSET_BINS`: the numbered cable modes of :func:`make_bridge_case` records whose true
    frequency lies that far from a structural frequency, the share within 1σ and 3σ of it, and how many of
    them had the structural resonance picked as a peak of its own (unassigned or structural, within 0.3 % of
    it: "apart"; the others are merged with the cable's peak)."""
    import warnings

    from stcs_ident.spectra.pipeline import analyse_record

    z, offset, apart = [], [], []
    for seed in seeds:
        case = make_bridge_case(kind, seed, layout=layout)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = analyse_record(case.campaign, case.test, case.record, "x")
        others = [f for f, _ in r.unassigned] + [f for f, _, _ in r.structural]
        for plane, mode, f, u in zip(r.mode_planes, r.modes, r.frequencies, r.uncertainty):
            if mode > len(case.truth[plane]):
                continue
            true = case.truth[plane][mode - 1]
            near = min(case.structural, key=lambda s: abs(true - s))
            z.append(abs(f - true) / u)
            offset.append(abs(true - near) / true)
            apart.append(any(abs(o - near) <= 0.003 * near for o in others))
    z, offset, apart = np.array(z), np.array(offset), np.array(apart, bool)
    out = []
    for low, high in OFFSET_BINS:
        m = (offset >= low) & (offset < high)
        out.append({"bin": (low, high), "modes": int(m.sum()), "apart": int(apart[m].sum()),
                    "one_sigma": float(np.mean(z[m] <= 1)) if m.any() else float("nan"),
                    "three_sigma": float(np.mean(z[m] <= 3)) if m.any() else float("nan")})
    return out


if __name__ == "__main__":  # python -m benchmarks.plane_records [first seed] [records] [layout]
    import sys

    first, count = (int(v) for v in (sys.argv[1:3] + ["0", "100"][len(sys.argv[1:3]):]))
    layout = sys.argv[3] if len(sys.argv) > 3 else "biaxial"
    for kind in ("stay", "hanger"):
        for row in offset_coverage(kind, range(first, first + count), layout=layout):
            low, high = row["bin"]
            print(f"{kind:6s} {layout} offset [{100 * low:.1f}, {100 * high:.1f}) %: {row['modes']:4d} modes, "
                  f"1σ {row['one_sigma']:.3f}, 3σ {row['three_sigma']:.3f}, resonance picked apart {row['apart']}")
