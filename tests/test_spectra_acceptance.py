"""Spectra acceptance: simulated records → picked, numbered frequencies.

At least 100 seeded records from the simulator (exact modal superposition of
the DSM's modes): three cables unlike each other (a short stiff hanger, a
long inclined stay with sag and a damper mass, the han2020 strand with its
weight); 1–5 sensors, half of the records with one at a node of some mode;
one impulse, repeated impulses, or ambient loading; sensor noise from 0 to
40 dB SNR; damping 0.1–2 %; the nominal tension up to 10 % off.

A mode counts as visible when, at some sensor, the Welch spectrum of the
noise-free record peaks at the mode (6 dB above the spectrum half-way to
the neighbouring modes: a peak, not the tail of a neighbour at a node) and
stands 10 dB above the spectrum of the noise alone. No peak may
carry a wrong number without being flagged doubtful, and every visible mode
must be found (within 2 %) and correctly numbered. For free decays at ≥ 20 dB the
frequency errors are compared with the Cramér–Rao bound of the case
(spectra/crb.py: Yao & Pandit's bound for damped sinusoids with common
frequency and decay across channels, per-channel amplitude and noise):
median |error| / bound ≤ 2.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.signal import welch

from stcs_ident.core.errors import NumberingWarning
from stcs_ident.core.model import Attachment, Cable
from stcs_ident.forward import natural_frequencies
from stcs_ident.forward.shapes import mode_shapes
from stcs_ident.simulate.simulate import Ambient, Impulse, simulate_record
from stcs_ident.spectra.crb import crb_frequency
from stcs_ident.spectra.numbering import number_modes
from stcs_ident.spectra.peaks import find_peaks

N_RECORDS = 105
VISIBLE_DB = 10.0

CABLES = {
    # name: cable, attachments, tension, duration (s), sampling rate (Hz), modes assessed
    "hanger": (Cable(length=8.0, mass_per_length=30.0, EI=2.0e5), [Attachment("clamp", 2.7, 15.0)], 4.0e5,
               60.0, 600.0, 8),
    "stay": (Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=math.radians(30)),
             [Attachment("damper", 3.0, 50.0)], 4.0e6, 150.0, 50.0, 12),
    "strand": (Cable(length=19.715, mass_per_length=16.6, EI=117338.3, EA=4.1382e8),
               [Attachment("W1", 9.8575, 8.3)], 1.2467e6, 60.0, 200.0, 8),
}


def _case(seed):
    rng = np.random.default_rng(seed)
    name = list(CABLES)[seed % 3]
    cable, atts, H, duration, fs, n_modes = CABLES[name]
    length = cable.length
    n_sensors = int(rng.integers(1, 6))
    positions = list(rng.uniform(0.08, 0.92, n_sensors) * length)
    if rng.random() < 0.5:  # a sensor at a node of some mode (midspan, third or quarter point)
        positions[0] = length * rng.choice([0.5, 1 / 3, 0.25])
    kind = ["impulse", "repeated", "ambient"][int(rng.integers(3))]
    snr = float(rng.uniform(0, 40))
    zeta = float(rng.uniform(0.001, 0.02))
    impulses, ambient = (), None
    if kind == "impulse":
        impulses = (Impulse(1.0, rng.uniform(0.05, 0.95) * length, 50.0),)
    elif kind == "repeated":
        n = int(rng.integers(2, 6))
        gap = duration / (n + 0.5)
        impulses = tuple(Impulse(1.0 + i * gap, rng.uniform(0.05, 0.95) * length, rng.uniform(20, 80))
                         for i in range(n))
    else:
        ambient = Ambient(rms_pressure=50.0)
    return {"name": name, "cable": cable, "atts": atts, "H": H, "duration": duration, "fs": fs, "n_modes": n_modes,
                "positions": positions, "kind": kind, "snr": snr, "zeta": zeta, "impulses": impulses, "ambient": ambient,
                "nominal_error": float(rng.uniform(0.9, 1.1)), "seed": seed}


def _simulate(case, snr):
    return simulate_record(case["cable"], case["atts"], case["H"], case["positions"], duration=case["duration"],
                           sampling_rate=case["fs"], damping=case["zeta"], impulses=case["impulses"],
                           ambient=case["ambient"], snr_db=snr, seed=case["seed"])


def _visible(clean, noise, fs, freqs):
    nper = 2 ** round(math.log2(max(256, clean.shape[0] / 8)))
    f, p_clean = welch(clean, fs=fs, nperseg=nper, axis=0)
    _, p_noise = welch(noise, fs=fs, nperseg=nper, axis=0)
    floor = np.maximum(p_noise, 1e-300)
    edges = np.concatenate([[freqs[0] / 2], (freqs[1:] + freqs[:-1]) / 2, [freqs[-1] + (freqs[-1] - freqs[-2]) / 2]])
    at = lambda x: np.argmin(np.abs(f - x))
    out = []
    for k, fk in enumerate(freqs):
        band = np.abs(f - fk) <= 2 * (f[1] - f[0])
        peak = p_clean[band].max(axis=0)
        above_noise = peak / floor[band].max(axis=0) >= 10 ** (VISIBLE_DB / 10)
        shoulders = np.maximum(p_clean[at(edges[k])], p_clean[at(edges[k + 1])])
        is_peak = peak >= 4.0 * shoulders
        out.append(bool(np.any(above_noise & is_peak)))
    return np.array(out)


def _crb(case, true_f, record_clean, noise_std):
    """Bound for each mode from the true modal amplitudes at the sensors."""
    shapes = mode_shapes(case["cable"], case["atts"], case["H"], len(true_f))
    phi_s = shapes(np.array(case["positions"]))  # (n_sensors, n_modes)
    fs = case["fs"]
    out = []
    for k, fk in enumerate(true_f):
        omega = 2 * math.pi * fk
        info_amp, lengths = [], []
        amps = np.zeros(len(case["positions"]))
        for imp in case["impulses"]:
            # acceleration amplitude of an impulse J at x0: J φ(x0) φ(x) ω (light damping)
            a = imp.magnitude * shapes(np.array([imp.position]))[0, k] * phi_s[:, k] * omega
            amps = np.sqrt(amps**2 + a**2)
            lengths.append(int((case["duration"] - imp.time) * fs))
        info_amp.append(amps)
        out.append(crb_frequency(amps, noise_std, [max(lengths)], fs, decay_rate=case["zeta"] * omega))
    return np.array(out)


def _assess(seed):
    """One record: (visible modes, missed modes, mislabelled peaks, |error| / CRB of the free-decay modes)."""
    missed, mislabelled, ratios = [], [], []
    case = _case(seed)
    true_f = natural_frequencies(case["cable"], case["atts"], case["H"], case["n_modes"])
    clean = _simulate(case, None)
    noisy = _simulate(case, case["snr"])
    noise = noisy.acceleration - clean.acceleration
    visible = _visible(clean.acceleration, noise, case["fs"], true_f)
    result = find_peaks(noisy, f_min=0.5 * true_f[0], f_max=min(0.45 * case["fs"], 1.15 * true_f[-1]))
    f = np.array([p.frequency for p in result.peaks])
    u = np.array([p.uncertainty for p in result.peaks])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NumberingWarning)  # doubtful numbers are read from the result
        numbering = number_modes(f, u, case["cable"], case["atts"], case["H"] * case["nominal_error"]) \
            if f.size else None
    labels = numbering.modes if numbering is not None else np.zeros(0, int)
    doubtful = numbering.doubtful if numbering is not None else np.zeros(0, bool)
    for fj, kj, dj in zip(f, labels, doubtful):
        if kj == 0 or kj > len(true_f):
            continue
        nearest = int(np.argmin(np.abs(true_f - fj))) + 1
        if nearest != kj and not dj:
            mislabelled.append((seed, case["name"], case["kind"], fj, kj, nearest))
    for k in np.flatnonzero(visible):
        hit = (labels == k + 1) & (np.abs(f - true_f[k]) < 0.02 * true_f[k])
        if not hit.any():
            missed.append((seed, case["name"], case["kind"], round(case["snr"], 1), k + 1, true_f[k]))
    if case["kind"] != "ambient" and case["snr"] >= 20 and f.size:
        bound = _crb(case, true_f, clean, noise.std(axis=0))
        for k in range(len(true_f)):
            hit = np.flatnonzero((labels == k + 1) & (np.abs(f - true_f[k]) < 0.02 * true_f[k]))
            if hit.size and visible[k]:
                ratios.append(abs(f[hit[0]] - true_f[k]) / bound[k])
    return int(visible.sum()), missed, mislabelled, ratios


@pytest.mark.slow
def test_spectra_acceptance_over_simulated_records():
    missed, mislabelled, ratios, n_visible = [], [], [], 0
    # One test over all records, in seed order: the median is a statistic of them all (pytest-xdist spreads
    # the other tests over the CPUs meanwhile).
    for visible, m, wrong, r in map(_assess, range(N_RECORDS)):
        n_visible += visible
        missed += m
        mislabelled += wrong
        ratios += r
    print(f"{N_RECORDS} records, {n_visible} visible modes, {len(missed)} missed, {len(mislabelled)} mislabelled, "
          f"median error/CRB {np.median(ratios):.2f} over {len(ratios)} modes")
    assert not mislabelled, mislabelled[:5]
    # The hardest case, seed 100 (the stay, ambient, ζ = 1.8 %, 4 sensors, broad overlapping resonances): mode 9
    # is found only by the residual pass (spectra/residual.py: what the fitted modes leave unexplained), and
    # mode 8 only since a candidate's width stops at the valley before a stronger neighbour (detection.py:
    # mode 7's width had spanned 7.3 Hz and hidden mode 8 as its shoulder).
    assert not missed, missed
    assert np.median(ratios) <= 2.0
