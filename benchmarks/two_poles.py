"""One pole or two in a band: the likelihood-ratio statistic of :mod:`stcs_ident.spectra.two_poles` under one
pole (its threshold's calibration) and under two, and the second resonances reported on bridge records.

- ``null``: bands of one mode (an AR(2) filter of white noise: its exact damped poles; 5-15 Hz at 50 Hz, two
  channels, sensor noise 1-30 % of the rms; 30, 60, 120 or 600 s; ζ 0.2-2 % log-uniform), fitted with one pole
  and tested: the statistic's quantiles, per record length, and how many reach the threshold (false alarms);
- ``two``: a second mode sharing the channels' shape ``--separation`` half-power half-widths above the first at
  ``--ratio`` of its amplitude (ζ 0.5 %): how many are found (misfit gate and threshold) and within 3σ;
- ``bridge``: :func:`benchmarks.plane_records.make_bridge_case` records (``--layout``), the second poles reported
  as structural and how many lie within 3σ of a structural frequency (a deck's mode or its harmonic).

    python benchmarks/two_poles.py null [--records 3000] [--seed 2] [--durations 30 60 120 600]
    python benchmarks/two_poles.py two [--duration 120] [--separation 8] [--ratio 0.5]
    python benchmarks/two_poles.py bridge [--kind stay] [--layout biaxial] [--seed 200] [--records 30]
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.signal import lfilter

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import print_header

from stcs_ident.spectra.ambient_fit import fit_ambient
from stcs_ident.spectra.two_poles import THRESHOLD, second_resonance, two_poles

FS = 50.0


def mode(rng, n: int, frequency: float, zeta: float) -> np.ndarray:
    w = 2 * np.pi * frequency
    r = np.exp(-zeta * w / FS)
    return lfilter([1.0], [1, -2 * r * np.cos(w * np.sqrt(1 - zeta**2) / FS), r * r],
                   rng.standard_normal(n + 6000))[6000:]


def band_fit(x, f0, half_width, zeta):
    n = x.shape[0]
    dft = np.fft.rfft(x, axis=0) / np.sqrt(n)
    return fit_ambient(dft, n, FS, f0, half_width, np.ones(x.shape[1]), peak_width=2 * zeta * f0, spread=False)


def null(records: int, seed: int, durations=(30.0, 60.0, 120.0, 600.0)) -> None:
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(records):
        duration = float(rng.choice(durations))
        zeta = float(np.exp(rng.uniform(np.log(0.002), np.log(0.02))))
        f0 = rng.uniform(5, 15)
        x = np.outer(mode(rng, int(FS * duration), f0, zeta), rng.uniform(0.3, 1.0, 2))
        x += rng.uniform(0.01, 0.3) * x.std() * rng.standard_normal(x.shape)
        fit = band_fit(x, f0, max(8 * zeta * f0, 12 / duration), zeta)
        result = None if fit is None or fit.band is None else two_poles(*fit.band[:3])
        if result is not None:
            rows.append((duration, result.statistic))
    a = np.array(rows)
    print(f"{len(a)} single-mode bands: statistic 2Δℓ quantiles 50 / 90 / 99 / 99.9 % "
          + " / ".join(f"{np.quantile(a[:, 1], q):.1f}" for q in (0.5, 0.9, 0.99, 0.999))
          + f", largest {a[:, 1].max():.1f}; at the threshold {THRESHOLD:g} or above: {int(np.sum(a[:, 1] >= THRESHOLD))}")
    for duration in durations:
        s = a[a[:, 0] == duration, 1]
        print(f"  {duration:4.0f} s: {s.size} bands, median {np.median(s):.1f}, 99 % {np.quantile(s, 0.99):.1f}, "
              f"largest {s.max():.1f}")


def two(records: int, seed: int, duration: float, separation: float, ratio: float) -> None:
    rng = np.random.default_rng(seed)
    found = within = 0
    for _ in range(records):
        f0, zeta = rng.uniform(5, 15), 0.005
        f_b = f0 * (1 + separation * zeta)
        n = int(FS * duration)
        qa, qb = mode(rng, n, f0, zeta), mode(rng, n, f_b, zeta)
        x = np.outer(qa + ratio * np.std(qa) / np.std(qb) * qb, [1.0, 0.6])
        x += 0.3 * x.std() * rng.standard_normal(x.shape)
        fit = band_fit(x, f0, max(8 * zeta * f0, 3 * (f_b - f0)), zeta)
        second = None if fit is None else second_resonance(fit)
        if second is not None:
            found += 1
            within += abs(second[0] - f_b) <= 3 * second[1]
    print(f"two modes {separation:g} half-power half-widths apart, the second at {ratio:g} of the amplitude, "
          f"{duration:g} s: found in {found} of {records} bands, within 3σ of the second mode {within} of {found}")


def bridge(kind: str, layout: str, seed: int, records: int) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks.plane_records import make_bridge_case
    from stcs_ident.spectra.pipeline import analyse_record

    reported = within = 0
    for s in range(seed, seed + records):
        case = make_bridge_case(kind, s, layout=layout)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = analyse_record(case.campaign, case.test, case.record, "x")
        for f, u, reason in r.structural:
            if "second pole" in reason:
                reported += 1
                within += min(abs(f - d) for d in case.structural) <= 3 * u
    print(f"{kind} {layout}, seeds {seed}-{seed + records - 1}: {reported} second poles reported as structural, "
          f"{within} within 3σ of a structural frequency")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", choices=("null", "two", "bridge"))
    parser.add_argument("--records", type=int, default=None)
    parser.add_argument("--seed", type=int, default=None)
    parser.add_argument("--duration", type=float, default=120.0)
    parser.add_argument("--durations", type=float, nargs="+", default=(30.0, 60.0, 120.0, 600.0),
                        help="null: the record lengths drawn from, s")
    parser.add_argument("--separation", type=float, default=8.0)
    parser.add_argument("--ratio", type=float, default=0.5)
    parser.add_argument("--kind", default="stay", choices=("stay", "hanger"))
    parser.add_argument("--layout", default="biaxial", choices=("biaxial", "triaxial"))
    args = parser.parse_args(argv)
    print_header()
    t0 = time.perf_counter()
    if args.case == "null":
        null(args.records or 3000, 2 if args.seed is None else args.seed, tuple(args.durations))
    elif args.case == "two":
        two(args.records or 100, 6 if args.seed is None else args.seed, args.duration, args.separation, args.ratio)
    else:
        bridge(args.kind, args.layout, 200 if args.seed is None else args.seed, args.records or 30)
    print(f"({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
