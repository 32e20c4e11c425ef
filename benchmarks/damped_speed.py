"""A damper's cost: `spectra`, `identify` and `diagnose --max-effects 2` on a damped stay against its undamped twin.

Issue 25's target: with a damper, the numbering, the identification and the diagnosis cost at most twice
the same work without it. Each cable is timed twice, in one run, on the same simulated record:

- **damped**: the stay with a viscous damper (η₁ = c π x_d/(l √(H m)) = 1, mode 1's optimum) near its
  anchorage, the record simulated with the damper's exact complex modes;
- **undamped twin**: the same stay with the damper's dashpot removed (its moving mass kept), its own record.

For each: `spectra` (peaks, numbering against the model's family, shapes; `analyse_record`), `identify`
(tension and EI, with the dashpot too when there is one: from the frequencies and the damping ratios), and
`diagnose` with pairs of effects in one process (``workers=1``: the cost, not the parallelism). Timings are
the median of ``--repeat`` calls after one warm-up (diagnose: one call); ``spectra, first`` is the first call,
which solves the numbering's search grid (the later ones, like a monitoring archive's records of one cable,
reuse it).

``--baseline PYTHON`` also runs the same measurements with another installation's Python (the code before
a change) and prints its damped/undamped figures beside these.

Run from the repository root with an installed (non-editable) package::

    python benchmarks/damped_speed.py [--repeat 3] [--baseline /tmp/venv-before/bin/python]
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

#: (name, length m, mass kg/m, EI N m², EA N, tension N, damper position m, damper mass kg)
CABLES = (("stay 120 m", 120.0, 60.0, 2.0e6, 3.0e9, 4.0e6, 3.0, 10.0),
          ("stay 200 m", 200.0, 80.0, 5.0e5, 2.0e9, 5.0e6, 4.0, 10.0))
DURATION, RATE = 600.0, 100.0  # s, Hz: a monitoring record
SENSORS = (0.23, 0.5, 0.71)  # fractions of the length


def _case(index: int, damped: bool):
    from stcs_ident.core.model import Attachment, Cable, Campaign, Damper, Setup, Test
    from stcs_ident.simulate import simulate_record
    from stcs_ident.simulate.simulate import Ambient

    name, length, m, EI, EA, tension, xd, mass = CABLES[index]
    cable = Cable(length=length, mass_per_length=m, EI=EI, EA=EA, inclination=math.radians(30.0))
    optimum = math.sqrt(tension * m) * length / (math.pi * xd)
    att = Damper("D", xd, mass, coefficient=optimum) if damped else Attachment("D", xd, mass)
    campaign = Campaign(name, cable, setups=(Setup("S", (att,)),), tests=(Test("T", "S", tension),))
    record = simulate_record(cable, [att], tension * 1.01, [f * length for f in SENSORS], duration=DURATION,
                             sampling_rate=RATE, damping=0.003, ambient=Ambient(20.0), snr_db=30.0, seed=index + 1)
    return campaign, record


def measure(index: int, damped: bool, repeat: int) -> dict:
    """Seconds of spectra, identify and diagnose on one cable (damped or its twin)."""
    from common import timed

    from stcs_ident.diagnose import diagnose
    from stcs_ident.identify import identify
    from stcs_ident.spectra.pipeline import analyse_record

    campaign, record = _case(index, damped)
    test = campaign.tests[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a doubtful number is flagged in the result; the cost is timed here
        started = time.perf_counter()  # the first call: the numbering's grid solved (later calls reuse it)
        analyse_record(campaign, test, record, "record", max_modes=15)
        t_first = time.perf_counter() - started
        t_spectra, spectra = timed(lambda: analyse_record(campaign, test, record, "record", max_modes=15), repeat)
        picked = {test.name: spectra}
        params = "tension,EI,coefficient" if damped else "tension,EI"
        t_identify, result = timed(lambda: identify(campaign, [test.name], params, picked=picked), repeat)
        started = time.perf_counter()
        diagnosis = diagnose(campaign, [test.name], picked=picked, max_effects=2, workers=1)
        t_diagnose = time.perf_counter() - started
    return {"spectra, first": t_first, "spectra": t_spectra, "identify": t_identify, "diagnose": t_diagnose, "modes": len(spectra.modes),
            "tension": result.value("tension")[0], "hypotheses": len(diagnosis.fits)}


def _baseline(python: str, repeat: int) -> list[dict]:
    out = []
    for index in range(len(CABLES)):
        row = {}
        for damped in (True, False):
            text = subprocess.run([python, __file__, "--child", str(index), str(int(damped)), "--repeat", str(repeat)],
                                  check=True, capture_output=True, text=True).stdout
            row["damped" if damped else "undamped"] = json.loads(text.strip().splitlines()[-1])
        out.append(row)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--baseline", metavar="PYTHON", help="also time another installation's Python")
    parser.add_argument("--child", nargs=2, type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(measure(args.child[0], bool(args.child[1]), args.repeat)))
        return 0
    from common import print_header

    print_header()
    print(f"records: {DURATION:.0f} s at {RATE:.0f} Hz, {len(SENSORS)} sensors; diagnose: pairs of effects, one "
          "process; spectra and identify: median of " f"{args.repeat} calls", flush=True)
    rows = []
    for index, cable in enumerate(CABLES):
        rows.append({"damped": measure(index, True, args.repeat), "undamped": measure(index, False, args.repeat)})
    base = _baseline(args.baseline, args.repeat) if args.baseline else None
    head = f"{'cable':<12}{'work':<16}{'damped s':>10}{'undamped s':>12}{'ratio':>8}"
    if base:
        head += f"{'before: damped s':>18}{'undamped s':>12}{'ratio':>8}"
    print("\n" + head)
    worst = 0.0
    for index, row in enumerate(rows):
        for work in ("spectra, first", "spectra", "identify", "diagnose"):
            if work not in row["damped"] or (base and work not in base[index]["damped"]):
                continue
            d, u = row["damped"][work], row["undamped"][work]
            worst = max(worst, d / u)
            line = f"{CABLES[index][0]:<12}{work:<16}{d:>10.3f}{u:>12.3f}{d / u:>8.2f}"
            if base:
                bd, bu = base[index]["damped"][work], base[index]["undamped"][work]
                line += f"{bd:>18.3f}{bu:>12.3f}{bd / bu:>8.2f}"
            print(line)
        print(f"{'':<12}modes numbered: damped {row['damped']['modes']}, undamped {row['undamped']['modes']}; "
              f"hypotheses: {row['damped']['hypotheses']} and {row['undamped']['hypotheses']}")
    print(f"\nlargest damped / undamped ratio: {worst:.2f} (target <= 2)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
