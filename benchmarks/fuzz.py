"""The long fuzz run: thousands of mutated inputs through the command line, every outcome classified.

Each case is a campaign directory with one mutation (campaign file, record or
command-line option; the kinds and the outcome classes are those of
tests/fuzz_inputs.py, which the suite runs briefly). Prints per kind how many
cases ran and their outcomes, every finding (a traceback, a hang, a modified
input, a message on more than one line or naming nothing, a non-standard
JSON file) with its command line, and the time.

Run with the installed package, from the repository root::

    python benchmarks/fuzz.py --cases 5000 --seed 1
"""

from __future__ import annotations

import argparse
import collections
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from fuzz_inputs import FINDINGS, KINDS, run

import stcs_ident


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=5000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--time-limit", type=float, default=60.0, help="seconds before a case counts as a hang")
    args = parser.parse_args(argv)
    print(f"stcs_ident {stcs_ident.__version__} from {Path(stcs_ident.__file__).parent}", flush=True)
    started = time.perf_counter()

    def progress(done, total, outcome):
        if done % 250 == 0 or done == total:
            elapsed = time.perf_counter() - started
            print(f"  {done}/{total} cases, {elapsed:.0f} s, ETA {elapsed / done * (total - done):.0f} s",
                  file=sys.stderr, flush=True)

    with tempfile.TemporaryDirectory() as tmp:
        outcomes = run(args.seed, args.cases, Path(tmp), args.time_limit, progress)
    table: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
    for o in outcomes:
        table[o.case.kind][o.status] += 1
    statuses = sorted({o.status for o in outcomes})
    print(f"\n{'kind':<28}" + "".join(f"{s:>10}" for s in statuses))
    for kind in KINDS:
        print(f"{kind:<28}" + "".join(f"{table[kind][s]:>10}" for s in statuses))
    totals = collections.Counter(o.status for o in outcomes)
    print(f"{'all':<28}" + "".join(f"{totals[s]:>10}" for s in statuses))
    findings = [o for o in outcomes if o.status in FINDINGS]
    print(f"\n{len(outcomes)} cases of {len(KINDS)} kinds in {time.perf_counter() - started:.0f} s: "
          f"{len(findings)} findings (tracebacks {totals['traceback']}, hangs {totals['hang']}, "
          f"inputs modified {totals['modified']})")
    for o in findings:
        last = o.stderr.strip().splitlines()[-1:] if o.stderr.strip() else []
        print(f"  {o.status}: {o.case.kind} {' '.join(o.case.argv)} -> {last}")
    return 1 if findings else 0


if __name__ == "__main__":
    raise SystemExit(main())
