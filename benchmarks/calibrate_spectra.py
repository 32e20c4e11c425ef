"""Is the stated 1σ of the picked frequencies honest under field-like conditions?

Simulates seeded records of two cables unlike each other and, per
condition group, scores ``stcs_ident.spectra.peaks.find_peaks`` against the
truth (the time-averaged frequency under a tension drift):

- hanger: 8 m, clamp attachment, 3 sensors, 512 Hz, 60 s, 1–3 hand blows;
- stay: 120 m inclined with sag and a damper mass, 3 sensors, 64 Hz,
  600 s, 1–3 blows (plus the ambient loading of the group).

Groups (sensor white noise 20–40 dB SNR and ζ 0.2–1 % throughout):

========================  ====================================================
clean                     blows only (the kind the toolkit was tuned on)
light_wind                blows under light white ambient loading
coloured_wind             blows under stronger low-pass ambient loading
ambient_coloured          low-pass ambient loading only
drift                     blows, light wind, tension drift (1e-5–1e-4 rel.)
drift_clean               blows and tension drift, no wind
pink                      blows, light wind, 1/f sensor noise
hum50, hum60              blows, light wind, mains hum and harmonics
dc_float32                blows, light wind, DC offsets, float32 samples
field                     blows under coloured wind, random_field_conditions
========================  ====================================================

Per group and cable it prints the number of (record, mode) pairs, the
median |z| (z = error / stated 1σ; 0.67 when the 1σ is honest), the
fractions |z| ≤ 1 (honest: 68 %) and ≤ 3 (honest: 99.7 %), the largest
|z|, the median relative |error|, missed modes, and any peak reported at a
mains harmonic that is not a mode (hum reported as a mode).

Run with the installed package (``import stcs_ident``); the header says
where it was imported from::

    python benchmarks/calibrate_spectra.py --records 30 --seed 1 --workers 2
    python benchmarks/calibrate_spectra.py --quick            # a few records per group
    python benchmarks/calibrate_spectra.py --group hum50 --records 10 --json /tmp/out.json
    python benchmarks/calibrate_spectra.py --group drift_clean --by-blows

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
from stcs_ident.core.model import Attachment, Cable
from stcs_ident.simulate import (
    Ambient,
    FieldConditions,
    Impulse,
    LowPassLoading,
    random_field_conditions,
    simulate_record_with_truth,
)
from stcs_ident.spectra.peaks import find_peaks


@dataclass(frozen=True)
class CableCase:
    """A cable with its records' settings and excitation levels."""

    cable: Cable
    attachments: tuple
    tension: float
    sampling_rate: float
    duration: float
    n_modes: int  # modes scored (the first ones)
    blow: float  # N s, magnitude of a blow
    light_wind: tuple[float, float]  # N/m, range of the rms pressure of light wind (log-uniform)
    strong_wind: tuple[float, float]  # N/m, of the wind that keeps going under the blows
    ambient: tuple[float, float]  # N/m, of ambient-only records


CABLES = {
    "hanger": CableCase(Cable(length=8.0, mass_per_length=30.0, EI=2.0e5), (Attachment("clamp", 2.7, 15.0),),
                        4.0e5, 512.0, 60.0, 8, 1.0, (0.01, 0.1), (0.1, 0.5), (0.5, 2.0)),
    "stay": CableCase(Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=math.radians(30)),
                      (Attachment("damper", 3.0, 50.0),), 4.0e6, 64.0, 600.0, 12, 30.0, (0.05, 0.5), (0.5, 2.0),
                      (0.5, 2.0)),
}

# The order fixes each group's random stream: new groups go at the end.
GROUPS = ("clean", "light_wind", "coloured_wind", "ambient_coloured", "drift", "pink", "hum50", "hum60",
          "dc_float32", "field", "drift_clean")
HUM_TOLERANCE = 0.1  # Hz: a reported peak this close to a mains harmonic, and not a mode, is hum reported


def _log_uniform(rng, lo, hi):
    return float(np.exp(rng.uniform(math.log(lo), math.log(hi))))


def build_case(group: str, cable: str, seed: int, index: int) -> dict:
    """The settings of one record (all draws from its own seeded stream)."""
    c = CABLES[cable]
    rng = np.random.default_rng([seed, GROUPS.index(group), list(CABLES).index(cable), index])
    length = c.cable.length
    positions = [0.23 * length, 0.5 * length, 0.71 * length]
    n_blows = int(rng.integers(1, 4))
    gap = c.duration / (n_blows + 0.5)
    impulses = tuple(Impulse(0.02 * c.duration + i * gap + rng.uniform(0, 0.1 * gap), rng.uniform(0.05, 0.95) * length,
                             c.blow * rng.uniform(0.5, 2.0) * rng.choice([-1.0, 1.0])) for i in range(n_blows))
    snr = float(rng.uniform(20.0, 40.0))
    zeta = float(rng.uniform(0.002, 0.01))
    # Field conditions drawn with every part on; the group picks the parts it uses.
    full = random_field_conditions(rng, c.sampling_rate, c.duration, 3, probability=1.0)
    lowpass = LowPassLoading(_log_uniform(rng, 0.3, 5.0) if cable == "hanger" else _log_uniform(rng, 0.3, 3.0),
                             int(rng.integers(1, 3)))
    light = Ambient(_log_uniform(rng, *c.light_wind))
    strong = Ambient(_log_uniform(rng, *c.strong_wind))
    hum_frequency = {"hum50": 50.0, "hum60": 60.0}.get(group)
    if hum_frequency is not None:
        hum_rng = np.random.default_rng([seed, 99, list(CABLES).index(cable), index])
        full_hum = random_field_conditions(hum_rng, c.sampling_rate, c.duration, 3, probability=1.0,
                                           mains_frequency=hum_frequency + float(hum_rng.uniform(-0.05, 0.05)))
    ambient, field = None, None
    if group == "clean":
        pass
    elif group == "light_wind":
        ambient = light
    elif group == "coloured_wind":
        ambient, field = strong, FieldConditions(ambient_lowpass=lowpass)
    elif group == "ambient_coloured":
        impulses, ambient = (), Ambient(_log_uniform(rng, *c.ambient))
        field = FieldConditions(ambient_lowpass=lowpass)
    elif group == "drift":
        ambient, field = light, FieldConditions(drift=full.drift)
    elif group == "drift_clean":
        field = FieldConditions(drift=full.drift)
    elif group == "pink":
        ambient, field = light, FieldConditions(pink_noise=full.pink_noise)
    elif group in ("hum50", "hum60"):
        ambient, field = light, FieldConditions(hum=full_hum.hum)
    elif group == "dc_float32":
        ambient, field = light, FieldConditions(dc_offsets=full.dc_offsets, float32=True)
    elif group == "field":
        ambient = strong
        field = random_field_conditions(rng, c.sampling_rate, c.duration, 3, probability=0.75)
    else:
        raise ValueError(f"unknown group {group!r}")
    return {"group": group, "cable": cable, "seed": seed, "index": index, "positions": positions,
            "impulses": impulses, "ambient": ambient, "field": field, "snr": snr, "zeta": zeta}


def run_case(case: dict) -> dict:
    """Simulate, pick, match to the truth: per scored mode (error, σ) or a miss, and hum lines reported."""
    c = CABLES[case["cable"]]
    t0 = time.perf_counter()
    record, truth = simulate_record_with_truth(
        c.cable, c.attachments, c.tension, case["positions"], duration=c.duration, sampling_rate=c.sampling_rate,
        damping=case["zeta"], impulses=case["impulses"], ambient=case["ambient"], snr_db=case["snr"],
        seed=[case["seed"], case["index"], 7], field=case["field"])
    true_f = truth.mean_frequencies
    scored = true_f[: c.n_modes]
    f_max = min(0.45 * c.sampling_rate, 1.15 * scored[-1])
    out = {k: case[k] for k in ("group", "cable", "seed", "index")} | {"blows": len(case["impulses"])}
    try:
        result = find_peaks(record, f_min=0.5 * scored[0], f_max=f_max)
    except Exception as exc:  # noqa: BLE001 -- a failure is a finding of the benchmark, not a crash of it
        out.update(error=f"{type(exc).__name__}: {exc}", pairs=[], missed=list(range(1, c.n_modes + 1)), hum=[])
        return out
    f = np.array([p.frequency for p in result.peaks])
    u = np.array([p.uncertainty for p in result.peaks])
    pairs, missed, used = [], [], set()
    for k, fk in enumerate(scored):
        gaps = np.abs(np.delete(true_f, k) - fk)
        window = min(0.3 * gaps.min(), 0.02 * fk)
        near = np.flatnonzero(np.abs(f - fk) < window) if f.size else np.zeros(0, int)
        if near.size == 0:
            missed.append(k + 1)
            continue
        j = int(near[np.argmin(np.abs(f[near] - fk))])
        used.add(j)
        pairs.append((k + 1, float(fk), float(f[j]), float(u[j])))
    hum = []
    mains = case["field"].hum.frequency if case["field"] is not None and case["field"].hum is not None else None
    for j, fj in enumerate(f):
        if j in used:
            continue
        not_a_mode = np.min(np.abs(true_f - fj)) > 0.3 * np.min(np.diff(true_f))
        for base in (mains,) if mains else (50.0, 60.0):
            h = round(fj / base)
            if h >= 1 and abs(fj - h * base) < HUM_TOLERANCE + 0.05 * h * (mains is None) and not_a_mode:
                hum.append(float(fj))
                break
    out.update(pairs=pairs, missed=missed, hum=hum, n_peaks=int(f.size), seconds=time.perf_counter() - t0)
    return out


def summarise(results: list[dict], by_blows: bool = False) -> list[dict]:
    """One row per group and cable (and number of blows if ``by_blows``: group "drift_clean/1" = one blow)."""
    if by_blows:
        results = [r | {"group": f"{r['group']}/{r['blows']}"} for r in results]
    order = {g: i for i, g in enumerate(GROUPS)}
    rows = []
    keys = sorted({(r["group"], r["cable"]) for r in results}, key=lambda k: (order[k[0].split("/")[0]], k))
    for group, cable in keys:
        rs = [r for r in results if r["group"] == group and r["cable"] == cable]
        z = np.array([(fe - ft) / s for r in rs for _, ft, fe, s in r["pairs"]])
        rel = np.array([abs(fe / ft - 1) for r in rs for _, ft, fe, s in r["pairs"]])
        az = np.abs(z)
        rows.append({
            "group": group, "cable": cable, "records": len(rs), "pairs": int(z.size),
            "median_abs_z": float(np.median(az)) if z.size else math.nan,
            "within_1": float(np.mean(az <= 1)) if z.size else math.nan,
            "within_3": float(np.mean(az <= 3)) if z.size else math.nan,
            "max_abs_z": float(az.max()) if z.size else math.nan,
            "median_rel_error": float(np.median(rel)) if z.size else math.nan,
            "missed": sum(len(r["missed"]) for r in rs),
            "hum_reported": sum(len(r["hum"]) for r in rs),
            "failed": sum(1 for r in rs if "error" in r),
        })
    return rows


def print_table(rows: list[dict]) -> None:
    head = (f"{'group':<17}{'cable':<8}{'rec':>4}{'pairs':>6}{'med|z|':>8}{'|z|<=1':>8}{'|z|<=3':>8}"
            f"{'max|z|':>8}{'med|err|':>10}{'miss':>6}{'hum':>5}{'fail':>5}")
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r['group']:<17}{r['cable']:<8}{r['records']:>4}{r['pairs']:>6}{r['median_abs_z']:>8.2f}"
              f"{100 * r['within_1']:>7.1f}%{100 * r['within_3']:>7.1f}%{r['max_abs_z']:>8.1f}"
              f"{r['median_rel_error']:>10.2e}{r['missed']:>6}{r['hum_reported']:>5}{r['failed']:>5}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--records", type=int, default=30, help="records per group and cable (default 30)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the record streams (default 1)")
    parser.add_argument("--group", action="append", choices=GROUPS, help="only this group (repeatable)")
    parser.add_argument("--cable", action="append", choices=list(CABLES), help="only this cable (repeatable)")
    parser.add_argument("--workers", type=int, default=2, help="processes (default 2)")
    parser.add_argument("--quick", action="store_true", help="3 records per group and cable")
    parser.add_argument("--json", help="write the per-record results and the table to this file")
    parser.add_argument("--by-blows", action="store_true",
                        help="also a table per number of blows (a single blow in a windless record cannot show a "
                             "tension drift over the rest of it)")
    args = parser.parse_args(argv)
    n = 3 if args.quick else args.records
    print(f"stcs_ident {getattr(stcs_ident, '__version__', '?')} imported from {stcs_ident.__file__}")
    print(f"python {sys.version.split()[0]}; seed {args.seed}; {n} records per group and cable")
    cases = [build_case(g, c, args.seed, i) for g in (args.group or GROUPS) for c in (args.cable or CABLES)
             for i in range(n)]
    t0 = time.perf_counter()
    if args.workers > 1:
        with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
            results = pool.map(run_case, cases, chunksize=1)
    else:
        results = [run_case(c) for c in cases]
    rows = summarise(results)
    print_table(rows)
    if args.by_blows:
        print("\nper number of blows (group/blows):")
        print_table(summarise(results, by_blows=True))
    print(f"{len(cases)} records in {time.perf_counter() - t0:.0f} s")
    for r in results:
        if "error" in r:
            print(f"failed: {r['group']} {r['cable']} #{r['index']}: {r['error']}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"rows": rows, "results": results}, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
