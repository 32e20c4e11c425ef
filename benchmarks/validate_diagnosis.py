"""Does the diagnosis stay silent on healthy cables and name exactly the hidden effect on sick ones?

Simulates seeded field-like campaigns (records → spectra → diagnosis, as a
user's records would go) on two cables unlike each other, each with one
recorded attachment and two tests at different tensions:

- hanger: 8 m, ξ ≈ 11, 3 sensors, 256 Hz, 40 s, a hand blow;
- stay: 120 m inclined 30° with sag (λ² ≈ 1), 3 sensors, 64 Hz, 120 s.

Every record carries field-like conditions drawn by
``stcs_ident.simulate.random_field_conditions`` (coloured wind under the
blows, tension drift, pink noise, mains hum, DC offsets, float32 samples,
each on with probability 0.75) under ambient wind that keeps going through
the blow, SNR 20–40 dB, damping 0.2–1 %. The
campaign's stated tensions differ from the true ones by up to ±1.5 %
(within the default 2 % tolerance), as a ring gauge's would.

- ``healthy``: nothing else hidden; a named cause is a false alarm (a
  tension reported as a correction is not).
- ``effects``: each effect of the vocabulary hidden beyond its tolerance,
  on both cables; the named cause must be exactly that effect.

Run with the installed package::

    python benchmarks/validate_diagnosis.py --healthy 40 --workers 2
    python benchmarks/validate_diagnosis.py --healthy 0 --effects        # the sick campaigns only
    python benchmarks/validate_diagnosis.py --quick
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

import stcs_ident
from stcs_ident.core.model import Attachment, Cable, Campaign, Setup, Test
from stcs_ident.diagnose import diagnose
from stcs_ident.io.campaign import load_campaign
from stcs_ident.simulate import Ambient, Effects, Impulse, random_field_conditions, simulate_campaign
from stcs_ident.spectra import analyse_test

MAX_MODES = 12

BENCHES = {
    "hanger": {"cable": Cable(length=8.0, mass_per_length=30.0, EI=2.0e5), "attachment": Attachment("clamp", 2.7, 15.0),
               "tensions": (4.0e5, 5.0e5), "duration": 40.0, "rate": 256.0, "blow": 1.0, "wind": (0.01, 0.5)},
    "stay": {"cable": Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=math.radians(30)),
             "attachment": Attachment("damper", 3.0, 50.0), "tensions": (4.0e6, 4.6e6), "duration": 120.0,
             "rate": 64.0, "blow": 30.0, "wind": (0.05, 2.0)},
}


def hidden_effects(bench: str) -> dict[str, dict]:
    """Each effect of the vocabulary hidden beyond its default tolerance (Effects keywords)."""
    b = BENCHES[bench]
    cable, att, length = b["cable"], b["attachment"], b["cable"].length
    return {
        "tension": {"tension_ratio": 1.05},
        "bending_stiffness": {"EI_ratio": 1.45},
        "attachment_position": {"attachment_positions": {att.name: att.position + 0.08 * length}},
        # on the stay the damper sits at 2.5 % of the span, where a heavier attachment shifts mode n by ∝ n²
        # like an EI change: 60 % more (30 kg) reads as EI −9 %, inside the 30 % tolerance, and is told apart
        # only where the highest modes see past the n² law (Δχ² 3.8 on seed 3503, 16.7 on 5503), so the
        # stay's is made 2.5 times the recorded mass
        "attachment_mass": {"attachment_masses": {att.name: (1.6 if bench == "hanger" else 2.5) * att.mass}},
        "unmodeled_mass": {"extra_mass": (0.04 * cable.mass_per_length * length, 0.65 * length)},
        "unmodeled_support": {"extra_spring": (2.0 * b["tensions"][0] / length, 0.3 * length)},
        "end_restraint": {"end_stiffness": (2.0 * math.sqrt(cable.EI * b["tensions"][0]),) * 2},
        # on the stay (ξ ≈ 170, a string to 0.1 %) a length change reads as a tension change of twice its size:
        # 1 % hides inside the 2 % tension tolerance, so the stay's is made 3 %
        "length": {"length_ratio": 1.01 if bench == "hanger" else 1.03},
    }


def run_case(case: dict) -> dict:
    """Simulate one campaign, pick its spectra and diagnose it."""
    bench, seed, hidden = case["bench"], case["seed"], case["hidden"]
    b = BENCHES[bench]
    rng = np.random.default_rng([seed, 7])
    stated = [h * (1 + rng.uniform(-0.015, 0.015)) for h in b["tensions"]]
    truth_ratio = [h / s for h, s in zip(b["tensions"], stated)]
    setup = Setup("S", (b["attachment"],))
    nominal = Campaign(f"{bench}-{seed}", b["cable"], (setup,),
                       tuple(Test(f"T{i + 1}", "S", s) for i, s in enumerate(stated)))
    length = b["cable"].length
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        effects = {}
        for i, t in enumerate(nominal.tests):
            keywords = dict(hidden or {})
            keywords["tension_ratio"] = keywords.get("tension_ratio", 1.0) * truth_ratio[i]
            effects[t.name] = Effects(**keywords)
        field = {t.name: random_field_conditions(np.random.default_rng([seed, i, 11]), b["rate"], b["duration"], 3)
                 for i, t in enumerate(nominal.tests)}
        out = simulate_campaign(nominal, Path(tmp) / "c", positions=[0.23 * length, 0.5 * length, 0.71 * length],
                                duration=b["duration"], sampling_rate=b["rate"],
                                damping=float(rng.uniform(0.002, 0.01)),
                                impulses=(Impulse(0.5, 0.17 * length, b["blow"]),),
                                ambient=Ambient(float(np.exp(rng.uniform(*np.log(b["wind"]))))),
                                snr_db=float(rng.uniform(20, 40)),
                                effects=effects, seed=seed, field=field)
        campaign = load_campaign(out)
        picked = {t.name: analyse_test(campaign, t, max_modes=MAX_MODES) for t in campaign.tests}
    d = diagnose(campaign, picked=picked, workers=1)
    s = d.summary()["cause"]
    return {"bench": bench, "seed": seed, "expected": case["expected"], "named": s["effects"],
            "corrections": list(s["corrections"]), "seconds": time.perf_counter() - started,
            "statement": s["statement"],
            "alternatives": [list(a) for a in (*s["ambiguous_with"], *s["implausible"])]}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--healthy", type=int, default=40, help="healthy campaigns (default 40, both cables)")
    parser.add_argument("--effects", action="store_true", help="also every effect hidden, on both cables")
    parser.add_argument("--seed", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="4 healthy campaigns and 2 effects")
    parser.add_argument("--json", metavar="FILE", help="write every case's outcome")
    args = parser.parse_args(argv)
    print(f"stcs_ident {stcs_ident.__version__} from {Path(stcs_ident.__file__).parent}", flush=True)
    cases = []
    n_healthy = 4 if args.quick else args.healthy
    for k in range(n_healthy):
        cases.append({"bench": list(BENCHES)[k % 2], "seed": args.seed + k, "hidden": None, "expected": []})
    if args.effects or args.quick:
        for bench in BENCHES:
            for j, (effect, hidden) in enumerate(hidden_effects(bench).items()):
                if args.quick and effect not in ("bending_stiffness", "unmodeled_mass"):
                    continue
                cases.append({"bench": bench, "seed": args.seed + 500 + j, "hidden": hidden, "expected": [effect]})
    started = time.perf_counter()
    results = []
    with multiprocessing.get_context("fork").Pool(args.workers) as pool:
        for k, r in enumerate(pool.imap_unordered(run_case, cases), start=1):
            results.append(r)
            ok = r["named"] == r["expected"]
            print(f"[{k}/{len(cases)}] {r['bench']:<6} seed {r['seed']}: expected {r['expected'] or '-'}, named "
                  f"{r['named'] or '-'}, corrections {r['corrections'] or '-'} {'ok' if ok else 'WRONG'} "
                  f"({r['seconds']:.0f} s)", file=sys.stderr, flush=True)
    healthy = [r for r in results if not r["expected"]]
    sick = [r for r in results if r["expected"]]
    alarms = [r for r in healthy if r["named"]]
    print(f"healthy campaigns: {len(healthy)}, a cause named in {len(alarms)} "
          f"(tension corrected in {sum('tension' in r['corrections'] for r in healthy)})")
    for r in alarms:
        print(f"  false alarm: {r['bench']} seed {r['seed']}: {r['named']} — {r['statement']}")
    wrong = [r for r in sick if r["named"] != r["expected"]]
    print(f"hidden-effect campaigns: {len(sick)}, exact effect set named in {len(sick) - len(wrong)}")
    for r in wrong:
        print(f"  wrong: {r['bench']} {r['expected']} → {r['named']} — {r['statement']}")
    # A wrong case whose hidden effect is among the alternatives the report says the frequencies cannot
    # separate (ambiguous, or as good but less plausible) was decided by the stated tolerances, not missed.
    unseparated = [r for r in wrong if any(set(r["expected"]) <= set(a) for a in r["alternatives"])]
    print(f"  of the wrong ones, the hidden effect reported as not separable by the frequencies: {len(unseparated)}")
    print(f"{len(results)} campaigns in {time.perf_counter() - started:.0f} s")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
