"""Is the stated 1σ of the picked damping ratios honest, with and without a damper?

Simulates seeded records and, per condition group and cable, scores the
damping ratio ζ and its 1σ of each peak of
``stcs_ident.spectra.peaks.find_peaks`` against the truth: the modal ζ given
to the simulator, or, with a damper, the complex mode's −Re(s)/|s|
(``RecordTruth.damping``). Cables (3 sensors at 0.23, 0.5 and 0.71 of the span):

- stay: 200 m, 80 kg/m, 5 MN, EI 0.1–1 MN m², sag; 20 Hz, 10 minutes;
- short: 60 m, 40 kg/m, 2 MN, EI 0.1 MN m²; 128 Hz (mains hum in the band), 5 minutes;

each bare (its modal ζ log-uniform 0.2–5 %) and ``+damper`` (a damper at 2–4 m,
η = c π x_d / (l √(Hm)) log-uniform 0.3–3, the cable's own ζ 0.1–0.3 %: the
modes' ζ then spans about 0.2–1.2 % on the stay, 0.2–3.5 % on the short one).
The first 8 modes are scored.

Groups (sensor white noise 20–40 dB SNR throughout):

================  =============================================================
impulse           1–3 blows, no wind
impulse_wind      blows under light white wind
ambient           wind only (white in time, correlation length 5–50 m or none)
ambient_coloured  wind only, low-pass 0.3–3 Hz
drift             blows under light wind, tension drift (1e-5–1e-4 relative)
hum               blows under light wind, mains hum and harmonics
field             wind only, random_field_conditions (all parts, each with p = 0.75)
================  =============================================================

Per group and cable it prints the (record, mode) pairs with a damping
estimate, the median |z| (z = error / stated 1σ; 0.67 when honest), the
fractions |z| ≤ 1 (honest: 68.3 %) and ≤ 3 (99.7 %), the largest |z|, the
median relative |error| of ζ, the median true ζ, and the modes found without
a damping estimate or not found. Run with the installed package::

    python benchmarks/calibrate_damping.py --records 20 --seed 1 --workers 2
    python benchmarks/calibrate_damping.py --quick
    python benchmarks/calibrate_damping.py --group ambient --cable short+damper --json /tmp/out.json
    python benchmarks/calibrate_damping.py --records 40 --time-limit 1800   # stops starting records after 30 min

Tune on one seed, report on another (``--seed`` picks disjoint streams).
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing
import sys
import time
from dataclasses import dataclass

import numpy as np

import stcs_ident
from stcs_ident.core.model import Cable, Damper
from stcs_ident.simulate import (
    Ambient,
    FieldConditions,
    Impulse,
    LowPassLoading,
    random_field_conditions,
    simulate_record_with_truth,
)
from stcs_ident.spectra.peaks import find_peaks

SCORED = 8  # modes scored, from mode 1


@dataclass(frozen=True)
class CableCase:
    """A cable with its records' settings and excitation levels."""

    length: float
    mass_per_length: float
    tension: float
    EI: tuple[float, float]  # N m², log-uniform range
    EA: float | None
    inclination: float
    sampling_rate: float
    duration: float
    blow: float  # N s
    light_wind: tuple[float, float]  # N/m rms, log-uniform
    wind: tuple[float, float]  # N/m rms of ambient-only records


CABLES = {
    "stay": CableCase(200.0, 80.0, 5.0e6, (1.0e5, 1.0e6), 2.0e9, math.radians(25), 20.0, 600.0, 60.0,
                      (0.05, 0.3), (0.5, 2.0)),
    "short": CableCase(60.0, 40.0, 2.0e6, (1.0e5, 1.0e5), None, 0.0, 128.0, 300.0, 20.0, (0.05, 0.3), (0.5, 2.0)),
}
CASES = ("stay", "stay+damper", "short", "short+damper")
# The order fixes each group's random stream: new groups go at the end.
GROUPS = ("impulse", "impulse_wind", "ambient", "ambient_coloured", "drift", "hum", "field")


def _log_uniform(rng, lo, hi):
    return float(np.exp(rng.uniform(math.log(lo), math.log(hi))))


def build_case(group: str, case: str, seed: int, index: int) -> dict:
    """The settings of one record (all draws from its own seeded stream)."""
    name, _, damped = case.partition("+")
    c = CABLES[name]
    rng = np.random.default_rng([seed, GROUPS.index(group), CASES.index(case), index])
    cable = Cable(c.length, c.mass_per_length, _log_uniform(rng, *c.EI), EA=c.EA, inclination=c.inclination)
    attachments = ()
    x_d = rng.uniform(2.0, 4.0)
    eta = _log_uniform(rng, 0.3, 3.0)
    if damped:
        coefficient = eta * math.sqrt(c.tension * c.mass_per_length) / (math.pi * x_d / c.length)
        attachments = (Damper("damper", x_d, coefficient=coefficient),)
        zeta = _log_uniform(rng, 0.001, 0.003)
    else:
        zeta = _log_uniform(rng, 0.002, 0.05)
    positions = [0.23 * c.length, 0.5 * c.length, 0.71 * c.length]
    n_blows = int(rng.integers(1, 4))
    gap = c.duration / (n_blows + 0.5)
    impulses = tuple(Impulse(0.02 * c.duration + i * gap + rng.uniform(0, 0.1 * gap),
                             rng.uniform(0.05, 0.95) * c.length,
                             c.blow * rng.uniform(0.5, 2.0) * rng.choice([-1.0, 1.0])) for i in range(n_blows))
    snr = float(rng.uniform(20.0, 40.0))
    correlation = None if rng.random() < 0.3 else _log_uniform(rng, 5.0, 50.0)
    light = Ambient(_log_uniform(rng, *c.light_wind), correlation)
    wind = Ambient(_log_uniform(rng, *c.wind), correlation)
    full = random_field_conditions(rng, c.sampling_rate, c.duration, 3, probability=1.0)
    lowpass = LowPassLoading(_log_uniform(rng, 0.3, 3.0), int(rng.integers(1, 3)))
    ambient, field = None, None
    if group == "impulse":
        pass
    elif group == "impulse_wind":
        ambient = light
    elif group == "ambient":
        impulses, ambient = (), wind
    elif group == "ambient_coloured":
        impulses, ambient, field = (), wind, FieldConditions(ambient_lowpass=lowpass)
    elif group == "drift":
        ambient, field = light, FieldConditions(drift=full.drift)
    elif group == "hum":
        ambient, field = light, FieldConditions(hum=full.hum)
    elif group == "field":
        impulses, ambient = (), wind
        field = random_field_conditions(rng, c.sampling_rate, c.duration, 3, probability=0.75)
    else:
        raise ValueError(f"unknown group {group!r}")
    return {"group": group, "case": case, "seed": seed, "index": index, "cable": cable,
            "attachments": attachments, "positions": positions, "impulses": impulses, "ambient": ambient,
            "field": field, "snr": snr, "zeta": zeta}


def run_case(case: dict) -> dict:
    """Simulate, pick, match to the truth: per scored mode (true ζ, estimate, 1σ), or why there is none."""
    c = CABLES[case["case"].partition("+")[0]]
    t0 = time.perf_counter()
    out = {k: case[k] for k in ("group", "case", "seed", "index")}
    record, truth = simulate_record_with_truth(
        case["cable"], case["attachments"], c.tension, case["positions"], duration=c.duration,
        sampling_rate=c.sampling_rate, damping=case["zeta"], impulses=case["impulses"], ambient=case["ambient"],
        snr_db=case["snr"], seed=[case["seed"], case["index"], 7], field=case["field"])
    true_f = truth.mean_frequencies
    n = min(SCORED, len(true_f))
    f_max = min(0.45 * c.sampling_rate, 1.15 * true_f[n - 1])
    try:
        result = find_peaks(record, f_min=0.5 * true_f[0], f_max=f_max)
    except Exception as exc:  # noqa: BLE001 -- a failure is a finding of the benchmark, not a crash of it
        out.update(error=f"{type(exc).__name__}: {exc}", pairs=[], no_damping=[], missed=list(range(1, n + 1)))
        return out
    f = np.array([p.frequency for p in result.peaks])
    pairs, no_damping, missed = [], [], []
    for k in range(n):
        gaps = np.abs(np.delete(true_f, k) - true_f[k])
        window = min(0.3 * gaps.min(), 0.02 * true_f[k])
        near = np.flatnonzero(np.abs(f - true_f[k]) < window) if f.size else np.zeros(0, int)
        if near.size == 0:
            missed.append(k + 1)
            continue
        p = result.peaks[int(near[np.argmin(np.abs(f[near] - true_f[k]))])]
        if p.damping is None or p.damping_uncertainty is None or not p.damping_uncertainty > 0:
            no_damping.append(k + 1)
            continue
        pairs.append((k + 1, float(truth.damping[k]), float(p.damping), float(p.damping_uncertainty),
                      float(true_f[k]), float(p.frequency), float(p.uncertainty)))
    out.update(kind=result.kind, pairs=pairs, no_damping=no_damping, missed=missed,
               seconds=time.perf_counter() - t0)
    return out


def summarise(results: list[dict]) -> list[dict]:
    """One row per group and case."""
    order = {g: i for i, g in enumerate(GROUPS)}
    rows = []
    for group, case in sorted({(r["group"], r["case"]) for r in results}, key=lambda k: (order[k[0]], CASES.index(k[1]))):
        rs = [r for r in results if r["group"] == group and r["case"] == case]
        p = np.array([q for r in rs for q in r["pairs"]]).reshape(-1, 7)
        z = np.abs((p[:, 2] - p[:, 1]) / p[:, 3])
        zf = np.abs((p[:, 5] - p[:, 4]) / p[:, 6])
        rows.append({
            "group": group, "case": case, "records": len(rs), "pairs": int(z.size),
            "median_abs_z": _stat(np.median, z), "within_1": _stat(lambda v: np.mean(v <= 1), z),
            "within_3": _stat(lambda v: np.mean(v <= 3), z), "max_abs_z": _stat(np.max, z),
            "median_rel_error": _stat(np.median, np.abs(p[:, 2] / p[:, 1] - 1)),
            "median_zeta": _stat(np.median, p[:, 1]),
            "f_within_1": _stat(lambda v: np.mean(v <= 1), zf),
            "no_damping": sum(len(r["no_damping"]) for r in rs), "missed": sum(len(r["missed"]) for r in rs),
            "failed": sum(1 for r in rs if "error" in r),
        })
    return rows


def _stat(func, values):
    return float(func(values)) if len(values) else math.nan


def print_table(rows: list[dict]) -> None:
    head = (f"{'group':<17}{'case':<14}{'rec':>4}{'pairs':>6}{'med|z|':>8}{'|z|<=1':>8}{'|z|<=3':>8}{'max|z|':>8}"
            f"{'med|err|':>9}{'med ζ':>8}{'f|z|<=1':>8}{'no ζ':>6}{'miss':>6}{'fail':>5}")
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r['group']:<17}{r['case']:<14}{r['records']:>4}{r['pairs']:>6}{r['median_abs_z']:>8.2f}"
              f"{100 * r['within_1']:>7.1f}%{100 * r['within_3']:>7.1f}%{r['max_abs_z']:>8.1f}"
              f"{r['median_rel_error']:>9.3f}{100 * r['median_zeta']:>7.2f}%{100 * r['f_within_1']:>7.1f}%"
              f"{r['no_damping']:>6}{r['missed']:>6}{r['failed']:>5}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--records", type=int, default=20, help="records per group and case (default 20)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the record streams (default 1)")
    parser.add_argument("--group", action="append", choices=GROUPS, help="only this group (repeatable)")
    parser.add_argument("--cable", action="append", choices=CASES, help="only this case (repeatable)")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    parser.add_argument("--quick", action="store_true", help="3 records per group and case")
    parser.add_argument("--time-limit", type=float, default=3600.0,
                        help="s: no record is started after this (default 3600); the table holds those done")
    parser.add_argument("--json", help="write the per-record results and the table to this file")
    args = parser.parse_args(argv)
    n = 3 if args.quick else args.records
    print(f"stcs_ident {getattr(stcs_ident, '__version__', '?')} imported from {stcs_ident.__file__}")
    print(f"python {sys.version.split()[0]}; seed {args.seed}; {n} records per group and case; "
          f"time limit {args.time_limit:g} s")
    # Interleaved (record index outermost), so a run stopped by the time limit has every group and case.
    cases = [build_case(g, c, args.seed, i) for i in range(n) for g in (args.group or GROUPS)
             for c in (args.cable or CASES)]
    t0 = time.time()  # wall clock: the deadline is shared by the worker processes
    results = []
    if args.workers > 1:
        with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
            pending = [pool.apply_async(_timed, (c, t0 + args.time_limit)) for c in cases]
            results = [r for r in (p.get() for p in pending) if r is not None]
    else:
        results = [r for r in (_timed(c, t0 + args.time_limit) for c in cases) if r is not None]
    skipped = len(cases) - len(results)
    print_table(summarise(results))
    print(f"{len(results)} records in {time.time() - t0:.0f} s"
          + (f"; {skipped} not started (time limit)" if skipped else ""))
    for r in results:
        if "error" in r:
            print(f"failed: {r['group']} {r['case']} #{r['index']}: {r['error']}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"rows": summarise(results), "results": results}, fh, indent=1)
    return 0


def _timed(case: dict, deadline: float) -> dict | None:
    """run_case, unless the deadline (wall clock) has passed."""
    if time.time() > deadline:
        return None
    return run_case(case)


if __name__ == "__main__":
    sys.exit(main())
