"""`track` end to end on a simulated monitoring archive: records per second per core, scaling, memory.

The archive: a hanger-like cable (8 m, 400 kN, a clamp) and a stay-like one
(120 m, 30°, 4 MN, sag, a 50 kg damper mass 3 m from the anchorage), each
with 3 accelerometers recording 10 minutes at 100 Hz every 10 minutes
(daily temperature cycles, record-to-record scatter; ``stcs-ident simulate
--archive``'s model). Two archives are made: the large one (``--records``,
default 2000) is tracked with 2 workers; a smaller one (``--scaling``,
default 400) with 1 and then 2 workers, which gives the scaling ratio and,
against the large one, whether memory stays flat with the archive's size.
Each run is a child process (the installed package's ``track``); its peak
resident memory is that of its largest process (wait4).

Targets (issue 25): ≥ 5 records/s/core (``--damped``: three damped stays of campaigns/damped-stay,
≥ 2), ≥ 1.8× from 1 to 2 workers, memory flat.

Run from the repository root::

    python benchmarks/track.py                   # about 15 minutes on two cores
    python benchmarks/track.py --records 400 --scaling 100   # quicker
    python benchmarks/track.py --false-alarms-only --months 300
    python benchmarks/track.py --damper-false-alarms --months 100   # the damper's history only, seconds

``--damper-false-alarms`` counts the damper events found on healthy synthetic histories of a damper's
coefficient (``tests/synthetic_dampers.py``: daily temperature cycles, the coefficient following the
damper's lagging temperature, per-record scatter from the measured 1σ; target ≤ 1 per cable-month), with the
residuals weighted by each record's 1σ (as ``track`` does) and, for comparison, unweighted; and how a 30 %
dashpot loss is found (delay, size against its 1σ).
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from common import print_header


def campaigns(root: Path) -> dict:
    from fuzz_inputs import BASE_TOML, _frequencies

    from stcs_ident.core.model import Attachment, Cable, Campaign, Setup, Test
    from stcs_ident.io.campaign import load_campaign

    (root / "hanger").mkdir(parents=True)
    (root / "hanger" / "campaign.toml").write_text(BASE_TOML.replace('record = "records/T2.h5"\n', "")
                                                   .format(f=_frequencies()), encoding="utf-8")
    stay = Campaign("stay", Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9,
                                  inclination=math.radians(30.0)),
                    setups=(Setup("S", (Attachment("D", 3.0, 50.0),)),), tests=(Test("T", "S", 4.0e6),))
    return {"hanger": load_campaign(root / "hanger"), "stay": stay}


def damped_campaigns() -> dict:
    """Three damped stays: the shipped campaigns/damped-stay (a 120 m stay, a viscous damper 3 m from A)."""
    from stcs_ident.io.campaign import load_campaign

    stay = load_campaign(Path(__file__).resolve().parents[1] / "campaigns" / "damped-stay")
    return {f"D{k}": stay for k in (1, 2, 3)}


def make_archive(path: Path, n_records: int, cables: dict) -> float:
    from stcs_ident.simulate.archive import ArchiveOptions, simulate_archive

    per_cable = n_records // len(cables)
    options = ArchiveOptions(days=per_cable * 600.0 / 86400.0, interval=600.0, duration=600.0, sampling_rate=100.0)
    started = time.perf_counter()
    simulate_archive(cables, path, options=options, seed=1, workers=2)
    return time.perf_counter() - started


def run_track(archive: Path, out: Path, workers: int) -> tuple[float, float, int]:
    """Wall time, peak resident memory (MB, its largest process), exit status of a `track` child process."""
    command = [sys.executable, "-c", "import sys; from stcs_ident.cli.main import main; sys.exit(main(sys.argv[1:]))",
               "track", str(archive), "--out", str(out), "--workers", str(workers)]
    with tempfile.TemporaryFile("w+") as err:
        started = time.perf_counter()
        child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=err)
        _, status, usage = os.wait4(child.pid, 0)
        return time.perf_counter() - started, usage.ru_maxrss / 1024, os.waitstatus_to_exitcode(status)


def false_alarms(months: int, seed: int = 11) -> list[tuple[str, int]]:
    """Events found on healthy 30-day histories of 10-minute tensions, per condition (none is true)."""
    import numpy as np

    from stcs_ident.track.events import analyse_history

    rng = np.random.default_rng(seed)
    conditions = {
        "daily cycle, 0.2 % scatter": {"lag": 0.0, "drift": 0.0, "scatter": 0.002},
        "+ weather drift the tension does not follow": {"lag": 0.0, "drift": 0.05, "scatter": 0.002},
        "+ cable lagging the air by 1 h": {"lag": 1.0, "drift": 0.05, "scatter": 0.002},
        "0.5 % scatter": {"lag": 1.0, "drift": 0.05, "scatter": 0.005},
    }
    out = []
    for label, c in conditions.items():
        events = 0
        for _ in range(months):
            hours = np.arange(4320) / 6.0
            weather = np.cumsum(rng.standard_normal(hours.size)) * c["drift"]
            air = 12 - 6 * np.cos(2 * np.pi * (hours - 5) / 24) + weather
            cable = 12 - 6 * np.cos(2 * np.pi * (hours - 5 - c["lag"]) / 24)
            tension = 4e5 * (1 - 5e-4 * (cable - 12)) * (1 + c["scatter"] * rng.standard_normal(hours.size))
            events += len(analyse_history(tension, air, 4e5).events)
        out.append((label, events))
    return out


def damper_false_alarms(months: int, seed: int = 13) -> list[tuple[str, int, int]]:
    """Damper events on healthy 30-day coefficient histories, weighted and unweighted, per condition."""
    import numpy as np
    from synthetic_dampers import REFERENCE, coefficient_history

    from stcs_ident.track.damper_history import analyse_coefficient

    conditions = {
        "10-min records, 1σ 9 % (spread 0.5)": {"sigma": 0.09, "spread": 0.5},
        "10-min records, 1σ 9 % (spread 1.0)": {"sigma": 0.09, "spread": 1.0},
        "60-s records, 1σ 40 % (spread 1.0)": {"sigma": 0.40, "spread": 1.0},
        "+ weather drift x4, oil lag 3 h": {"sigma": 0.09, "spread": 0.5, "drift": 0.2, "lag": 3.0},
        "+ a weather drift the oil does not follow": {"sigma": 0.09, "spread": 0.5, "unfollowed": 1.0},
    }
    out = []
    for label, c in conditions.items():
        rng = np.random.default_rng(seed)
        counts = [0, 0]
        for _ in range(months):
            coefficient, sigma, air, times = coefficient_history(rng, days=30, **c)
            for k, weighted in enumerate((True, False)):
                counts[k] += len(analyse_coefficient(coefficient, sigma, air, REFERENCE, times=times,
                                                     weighted=weighted).events)
        out.append((label, *counts))
    return out


def damper_losses(n: int, seed: int = 17) -> list[tuple[str, str]]:
    """A 30 % dashpot loss on the eighth day of 14-day histories: records to the alarm, share within 2σ."""
    import numpy as np
    from synthetic_dampers import REFERENCE, coefficient_history

    from stcs_ident.track.damper_history import analyse_coefficient

    out = []
    for label, c, weighted in (
            ("10-min records, 1σ 9 %", {"sigma": 0.09, "spread": 0.5}, True),
            ("+ weather the oil does not follow", {"sigma": 0.09, "spread": 0.5, "unfollowed": 1.0}, True),
            ("10-min records, spread 1.0", {"sigma": 0.09, "spread": 1.0}, True),
            ("    unweighted", {"sigma": 0.09, "spread": 1.0}, False),
            ("60-s records, 1σ 40 %", {"sigma": 0.40, "spread": 1.0}, True),
            ("    unweighted", {"sigma": 0.40, "spread": 1.0}, False)):
        rng = np.random.default_rng(seed)
        delays, z, missed = [], [], 0
        for _ in range(n):
            at = 144 * 7 + int(rng.integers(0, 144))
            coefficient, sigma, air, times = coefficient_history(rng, days=14, loss=0.3, at=at, **c)
            events = [e for e in analyse_coefficient(coefficient, sigma, air, REFERENCE, times=times,
                                                     weighted=weighted).events if e.alarm >= at]
            if not events or events[0].alarm > at + 144:
                missed += 1
                continue
            delays.append(events[0].alarm - at)
            z.append((events[0].change + 0.3) / events[0].uncertainty)
        z = np.abs(np.array(z))
        out.append((label, (f"found within a day {n - missed}/{n}, median delay {np.median(delays):.0f} records "
                            f"(max {max(delays, default=0)}), size within 1σ {np.mean(z < 1):.0%}, "
                            f"within 2σ {np.mean(z < 2):.0%}")))
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=2000)
    parser.add_argument("--scaling", type=int, default=400, help="records of the archive timed with 1 and 2 workers")
    parser.add_argument("--months", type=int, default=100, help="healthy cable-months per condition (false alarms)")
    parser.add_argument("--false-alarms-only", action="store_true")
    parser.add_argument("--damped", action="store_true",
                        help="archives of three damped stays (campaigns/damped-stay, the coefficient following the "
                             "temperature) instead of the hanger and the stay")
    parser.add_argument("--archive", type=Path, metavar="DIR",
                        help="track this archive (written by `stcs-ident simulate --archive`) as the large one instead "
                             "of simulating it (--records is then its number of records)")
    parser.add_argument("--keep", type=Path, metavar="DIR", help="copy the large run's `track` output to DIR")
    parser.add_argument("--damper-false-alarms", action="store_true",
                        help="only the damper's history: false damper events and 30 %% losses (synthetic)")
    args = parser.parse_args(argv)
    print_header()
    if args.damper_false_alarms:
        print(f"false damper events on healthy coefficient histories ({args.months} cable-months of 10-minute "
              "records per condition; bound: 1 per cable-month):")
        print(f"  {'':<44}{'weighted':>10}{'unweighted':>12}")
        for label, weighted, unweighted in damper_false_alarms(args.months):
            print(f"  {label:<44}{weighted:>10}{unweighted:>12}   ({weighted / args.months:.3f} per cable-month "
                  "weighted)")
        print("a 30 % dashpot loss (100 histories of 14 days):")
        for label, line in damper_losses(100):
            print(f"  {label:<36}{line}")
        return 0
    print(f"false events on healthy histories ({args.months} cable-months of 10-minute records per condition; "
          "bound: 1 per cable-month):")
    for label, events in false_alarms(args.months):
        print(f"  {label:<48}{events:>5} events, {events / args.months:.3f} per cable-month")
    if args.false_alarms_only:
        return 0
    print(f"cores: {os.cpu_count()}, load average before: {os.getloadavg()[0]:.2f}", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        cables = damped_campaigns() if args.damped else campaigns(root / "campaigns")
        large_archive = args.archive or root / "large"
        if args.archive:
            args.records = sum(1 for _ in args.archive.glob("*/records/*/*.h5"))
            print(f"archive large: {args.records} records of {args.archive}", flush=True)
        for name, n in (("small", args.scaling), ("large", args.records))[:1 if args.archive else 2]:
            seconds = make_archive(root / name, n, cables)
            print(f"archive {name}: {n} records ({len(cables)} cables, 3 channels, 600 s at 100 Hz) simulated in "
                  f"{seconds:.0f} s on 2 workers", flush=True)
        one, mem_one, code_one = run_track(root / "small", root / "out1", 1)
        two, mem_two, code_two = run_track(root / "small", root / "out2", 2)
        large, mem_large, code_large = run_track(large_archive, root / "out3", 2)
        import pandas as pd

        table = pd.read_parquet(root / "out3" / "records.parquet")
        if args.keep:
            import shutil

            shutil.copytree(root / "out3", args.keep)
        ok = int((table["status"] == "ok").sum())
        per_cable = table.groupby("cable")["status"].apply(lambda s: (s == "ok").mean())
    print(f"\n{'run':<34}{'records':>9}{'wall s':>9}{'rec/s':>8}{'rec/s/core':>12}{'peak MB':>9}{'exit':>6}")
    for label, n, wall, workers, mem, code in (
            ("small archive, 1 worker", args.scaling, one, 1, mem_one, code_one),
            ("small archive, 2 workers", args.scaling, two, 2, mem_two, code_two),
            ("large archive, 2 workers", args.records, large, 2, mem_large, code_large)):
        print(f"{label:<34}{n:>9}{wall:>9.1f}{n / wall:>8.2f}{n / wall / workers:>12.2f}{mem:>9.0f}{code:>6}")
    print(f"\nscaling 1 -> 2 workers: {one / two:.2f}x (target >= 1.8)")
    target = 2 if args.damped else 5
    print(f"records per second per core, large archive: {args.records / large / 2:.2f} (target >= {target}, issue 25)")
    print(f"peak memory: {mem_two:.0f} MB on {args.scaling} records, {mem_large:.0f} MB on {args.records} "
          f"({mem_large / mem_two:.2f}x for {args.records / args.scaling:.0f}x the records)")
    print(f"large archive: {ok} of {len(table)} records with a tension "
          f"({', '.join(f'{c} {100 * f:.1f} %' for c, f in per_cable.items())})")
    return 0 if code_one == code_two == code_large == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
