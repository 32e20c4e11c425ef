"""Diagnosis benchmark: the whole han2020 diagnosis, and the time per hypothesis fit.

The issue's target: ``stcs-ident diagnose campaigns/han2020`` (cases 1-3,
levels 4-5, tables only: 6 tests, 36 frequencies, 37 hypotheses: the
nominal model, 8 single effects, 28 pairs) in ≤ 60 s on this machine.

Side by side in one run:

1. the diagnosis as shipped (hypotheses fitted in worker processes, one per
   CPU available);
2. the same diagnosis in one process (``workers=1``): the ratio is the
   gain of the parallel fits, and its per-hypothesis times are the cost of
   each fit and its leave-one-mode-out cross-validation without
   contention;
3. the identification step's (tension, EI) least-squares fit alone (the
   paper's correction, the cheapest hypothesis) for scale.

Both runs must name the same cause (checked). The load average is printed:
timings on a busy machine are not comparable.

Run: ``python benchmarks/diagnose.py [--serial-only | --parallel-only]``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from common import CHECKOUT, print_header

from stcs_ident.diagnose import diagnose
from stcs_ident.diagnose.api import default_workers
from stcs_ident.identify import identify
from stcs_ident.io.campaign import load_campaign

CAMPAIGN = CHECKOUT / "campaigns" / "han2020"
TARGET = 60.0


def _run(campaign, workers):
    start = time.perf_counter()
    d = diagnose(campaign, workers=workers,
                 progress=lambda k, n, label: print(f"\r  hypothesis {k:2d} of {n} ", end="", file=sys.stderr))
    print(file=sys.stderr)
    return d, time.perf_counter() - start


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--serial-only", action="store_true", help="only the one-process run")
    group.add_argument("--parallel-only", action="store_true", help="only the shipped (parallel) run")
    args = parser.parse_args(argv)
    print_header()
    campaign = load_campaign(CAMPAIGN)
    print(f"han2020 diagnosis; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs; "
          f"{default_workers()} worker(s) by default")
    runs = {}
    if not args.serial_only:
        runs["shipped (parallel)"] = _run(campaign, None)
    if not args.parallel_only:
        runs["one process"] = _run(campaign, 1)
    start = time.perf_counter()
    identify(campaign, [m for m in ("case1-L4", "case1-L5")], "tension,EI")
    lsq = time.perf_counter() - start

    print(f"\n{'run':<20} {'hypotheses':>10} {'total (s)':>10} {'target (s)':>10} {'met':>5}")
    for name, (d, seconds) in runs.items():
        print(f"{name:<20} {len(d.fits):>10} {seconds:>10.1f} {TARGET:>10.0f} {'yes' if seconds <= TARGET else 'NO':>5}")
    if len(runs) == 2:
        (_, t_par), (_, t_ser) = runs["shipped (parallel)"], runs["one process"]
        print(f"parallel / one process: {t_par / t_ser:.2f} ({t_ser / t_par:.2f}x faster)")
        causes = {name: d.selection.effects for name, (d, _) in runs.items()}
        same = len(set(causes.values())) == 1
        print(f"same cause in both runs: {'yes' if same else 'NO'} {causes}")
    d, _ = runs.get("one process", runs.get("shipped (parallel)"))
    label = "one process" if "one process" in runs else "parallel (with contention)"
    print(f"\nTime per hypothesis (fit + leave-one-mode-out cross-validation, {label}):")
    print(f"{'hypothesis':<44} {'k':>3} {'seconds':>8}")
    for effects, seconds in sorted(d.timings.items(), key=lambda kv: -kv[1]):
        name = " + ".join(effects) if effects else "nominal"
        print(f"{name:<44} {d.fits[effects].n_parameters:>3} {seconds:>8.2f}")
    print(f"{'sum':<44} {'':>3} {sum(d.timings.values()):>8.2f}")
    print(f"\nFor scale: identify (tension, EI) least squares on case 1 (L4 + L5): {lsq:.3f} s")
    print(f"Cause: {d.cause_text()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
