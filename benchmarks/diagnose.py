"""Diagnosis benchmark: the whole han2020 diagnosis, and the time per hypothesis fit.

The target (issue 37): ``stcs-ident diagnose campaigns/han2020`` (cases 1-3,
levels 4-5, tables only: 6 tests, 36 frequencies, 43 hypotheses: the
nominal model, 8 single effects, 28 pairs and the baseline plus each of 6
further effects) in ≤ 5 s on two quiet cores (issue 1's was 60 s).

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

``--main-job N`` times the main job itself instead, N times: the command in a
child process (its imports included, from a neutral directory so that the
package of the Python given runs), with the load average before each run;
``--baseline PYTHON`` runs another installation's Python in turns with this
one (the code before: a venv's python, or a wrapper script setting
PYTHONPATH), and the medians and their ratio are printed.

Run: ``python benchmarks/diagnose.py [--serial-only | --parallel-only | --main-job N [--baseline PYTHON]]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

from common import CHECKOUT, print_header

from stcs_ident.diagnose import diagnose
from stcs_ident.diagnose.api import default_workers
from stcs_ident.identify import identify
from stcs_ident.io.campaign import load_campaign

CAMPAIGN = CHECKOUT / "campaigns" / "han2020"
TARGET = 5.0


def _run(campaign, workers):
    start = time.perf_counter()
    d = diagnose(campaign, workers=workers,
                 progress=lambda k, n, label: print(f"\r  hypothesis {k:2d} of {n} ", end="", file=sys.stderr))
    print(file=sys.stderr)
    return d, time.perf_counter() - start


def _main_job(python: str) -> tuple[float, float]:
    """Wall time (s) of ``stcs-ident diagnose campaigns/han2020`` run by ``python``, and the load average before."""
    command = [python, "-c", "import sys; from stcs_ident.cli.main import main; sys.exit(main(sys.argv[1:]))",
               "diagnose", str(CAMPAIGN)]
    load = os.getloadavg()[0]
    start = time.perf_counter()
    # from a neutral directory: run from a checkout, ``-c`` would import the checkout's package, not python's
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tempfile.gettempdir())
    return time.perf_counter() - start, load


def main_job(repeat: int, baseline: str | None) -> int:
    """The main job ``repeat`` times (in turns with ``baseline``'s Python when given): each run, and the medians."""
    pythons = {"this": sys.executable} | ({"baseline": baseline} if baseline else {})
    seconds: dict[str, list[float]] = {name: [] for name in pythons}
    print(f"stcs-ident diagnose campaigns/han2020, {repeat} run(s) each{' in turns' if baseline else ''}; "
          f"{os.cpu_count()} CPUs")
    for i in range(repeat):
        for name, python in pythons.items():
            t, load = _main_job(python)
            seconds[name].append(t)
            print(f"  run {i + 1} {name:<8} {t:6.2f} s  (load average {load:.2f} before)", flush=True)
    medians = {name: statistics.median(v) for name, v in seconds.items()}
    for name, m in medians.items():
        print(f"median {name:<8} {m:6.2f} s  target {TARGET:.0f} s: {'met' if m <= TARGET else 'NOT met'}")
    if baseline:
        print(f"this / baseline: {medians['this'] / medians['baseline']:.2f}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--serial-only", action="store_true", help="only the one-process run")
    group.add_argument("--parallel-only", action="store_true", help="only the shipped (parallel) run")
    group.add_argument("--main-job", type=int, metavar="N", help="time the command itself N times instead")
    parser.add_argument("--baseline", metavar="PYTHON", help="with --main-job: another installation's Python, in turns")
    args = parser.parse_args(argv)
    if args.baseline and not args.main_job:
        parser.error("--baseline goes with --main-job N")
    print_header()
    if args.main_job:
        return main_job(args.main_job, args.baseline)
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
