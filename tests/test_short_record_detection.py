"""Modes a Hz apart on a short record's coarse overview are told apart (issue 36).

A 60-s record's overview (Welch segments of about 5 s: 0.2 Hz cells) is an average of many segments that
barely ripples; its peaks' -3 dB widths, taken on a 5-cell running mean (1 Hz), used to merge three modes
1.16 Hz apart into one resonance, and the weaker were suppressed as its shoulders. Measured on 40 records
(seed 7): each mode found in 12, 1 and 20 of them before, 31, 29 and 34 now (all three in 0, now 14). The
valley of the overview itself between them now tells them apart.

The records are three independent modes (AR(2) filters of white noise: exact damped poles at ζ 0.5 %), each of
unit variance, on two channels with random shapes, and white sensor noise of unit variance per channel.
"""

import warnings

import numpy as np
from scipy.signal import lfilter

from stcs_ident.core.record import Record
from stcs_ident.spectra.peaks import find_peaks

FS, DURATION, ZETA = 50.0, 60.0, 0.005
MODES = (10.84, 12.0, 13.16)


def record(rng) -> Record:
    n = int(FS * DURATION)
    x = np.zeros((n, 2))
    for f in MODES:
        w = 2 * np.pi * f
        r = np.exp(-ZETA * w / FS)
        q = lfilter([1.0], [1.0, -2 * r * np.cos(w * np.sqrt(1 - ZETA**2) / FS), r * r],
                    rng.standard_normal(n + 3000))[3000:]
        x += np.outer(q / q.std(), rng.uniform(0.3, 1.0, 2))
    return Record(x + rng.standard_normal(x.shape), FS, ("A1", "A2"), (1.0, 2.0))


def test_three_modes_a_hz_apart_are_three_peaks():
    rng = np.random.default_rng(7)
    hits, z = np.zeros(3, int), []
    for _ in range(12):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            peaks = find_peaks(record(rng), f_min=0.5, f_max=22.0).peaks
        for i, f in enumerate(MODES):
            near = [p for p in peaks if abs(p.frequency - f) < 0.3]
            hits[i] += bool(near)
            if near and i == 1:
                z.append((near[0].frequency - f) / near[0].uncertainty)
    # 78 % of the modes found now, 28 % before (binomial sd over 36: 7 %): at least 22 of 36; and the middle
    # one, found in 1 of 40 before and 29 of 40 now, in at least 6 of 12
    assert hits.sum() >= 22 and hits[1] >= 6, hits
    # its 1σ about honest where found (rms of z 1.2 over 58 records of the middle mode alone): a loose guard
    assert np.sqrt(np.mean(np.square(z))) < 2.0, z
