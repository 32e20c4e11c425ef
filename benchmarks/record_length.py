"""Record length: how honest ``track``'s per-record 1σ is on 10-minute and on 60-s ambient records of a long stay.

The table of docs/track.md ("Record length"), end to end with the command line. The 120 m stay of
campaigns/damped-stay (4 MN, a viscous damper 3 m from the deck anchorage), and the same stay without its
damper (a copy of its campaign.toml without the ``[[setup.damper]]`` block). Per row: ``stcs-ident simulate
--archive`` writes two cables C1, C2 of records every 10 minutes (wind only, 100 Hz, the simulator's three
sensors, one seed), 2 hours of 600-s records or 6 hours of 60-s ones; ``stcs-ident track`` processes the
archive; each record's row of records.parquet is compared with the archive's truth.json:

- records with a tension (status ok, a finite tension and 1σ) of the records simulated;
- modes per record: the mean number of numbered modes of a record;
- frequencies: per numbered mode, z = (f − f_true) / σ with f_true the true model's frequency of that mode
  number; the share of |z| ≤ 1 and ≤ 3, modes 1-4 and mode 5 and up (all numbered modes, doubtful or not).
  The truth: the damped stay's complex modes as truth.json gives them; the bare stay's natural frequencies
  at the record's true tension (:func:`stcs_ident.forward.natural_frequencies`, the simulator's own model:
  the temperature only moves the tension);
- tension: z = (T − T_true) / σ_T of the records with a tension, the share within 1σ and 3σ.

Below the table, per row: the numbered modes off their truth by more than max(3σ, 0.5 %) (of which sure, not
doubtful), the modes whose nearest true frequency is another mode's (misnumbered), the doubtful ones, the
records without a tension and why.

Run it with the package to measure (``PYTHONPATH=/tmp/base`` measures another source tree; the command-line
subprocesses inherit it, and the header says which one is imported)::

    python benchmarks/record_length.py --workers 2                        # ~3 min on two idle cores
    python benchmarks/record_length.py --rows damped-600,bare-60 --keep /tmp/rl

With ``--keep DIR`` the archives and track outputs stay in DIR; an archive already there (with its truth.json)
is reused, the tracking is always done afresh.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

CAMPAIGN = Path(__file__).resolve().parents[1] / "campaigns" / "damped-stay"
#: key: (label, record length s, with its damper)
ROWS = {"damped-600": ("600 s, with its damper", 600, True),
        "damped-60": ("60 s, with its damper", 60, True),
        "bare-60": ("60 s, without it", 60, False),
        "bare-600": ("600 s, without it", 600, False)}


def bare_campaign(root: Path) -> Path:
    """A copy of the damped stay's campaign without its damper (checked: it parses, no attachment left)."""
    from stcs_ident.core.model import Damper
    from stcs_ident.io.campaign import load_campaign

    text = (CAMPAIGN / "campaign.toml").read_text()
    block = r"^[ \t]*\[\[setup\.damper\]\][^\n]*\n(?:[ \t]*[A-Za-z_][^\n]*\n)*"  # its header and its keys
    text, n = re.subn(block, "", text, flags=re.MULTILINE)
    if n != 1:
        raise SystemExit(f"expected one [[setup.damper]] block in {CAMPAIGN / 'campaign.toml'}, found {n}")
    text = text.replace('"with damper"', '"without damper"')
    text = text.replace('name = "damped-stay"', 'name = "damped-stay-bare"')
    text = "# campaigns/damped-stay without its damper (benchmarks/record_length.py)\n" + text
    folder = root / "bare-stay"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "campaign.toml").write_text(text)
    damped, bare = load_campaign(CAMPAIGN), load_campaign(folder)
    setup = bare.setup(bare.tests[0].setup)
    if setup.attachments or setup.name != "without damper" or bare.cable != damped.cable \
            or bare.tests[0].tension != damped.tests[0].tension:
        raise SystemExit(f"the bare copy {folder / 'campaign.toml'} is not the damped stay without its damper")
    assert any(isinstance(a, Damper) for a in damped.setup(damped.tests[0].setup).attachments)
    return folder


def simulate_and_track(root: Path, key: str, campaign: Path, hours: float, seed: int, workers: int) -> dict:
    """Simulate (unless kept from an earlier run) and track one row's archive; the times."""
    from common import run_cli

    _, duration, _ = ROWS[key]
    archive, tracked = root / key / "archive", root / key / "tracked"
    times = {"simulate": 0.0}
    if (archive / "truth.json").is_file():
        print(f"{key}: reusing the archive {archive}", flush=True)
    else:
        shutil.rmtree(archive, ignore_errors=True)
        archive.parent.mkdir(parents=True, exist_ok=True)
        times["simulate"] = run_cli("simulate", campaign, "--out", archive, "--archive", hours / 24, "--cables", 2,
                                    "--duration", duration, "--sampling-rate", 100, "--seed", seed, "--workers", workers)
    shutil.rmtree(tracked, ignore_errors=True)
    times["track"] = run_cli("track", archive, "--out", tracked, "--workers", workers)
    n = sum(1 for _ in archive.glob("*/records/*/*.h5"))
    print(f"{key}: {n} records, simulated in {times['simulate']:.0f} s, tracked in {times['track']:.0f} s "
          f"on {workers} workers", flush=True)
    return {"archive": archive, "tracked": tracked, "times": times}


def evaluate(archive: Path, tracked: Path, campaign: Path) -> dict:
    """The row's figures: records with a tension, modes per record, frequency and tension coverage, oddities."""
    import numpy as np
    import pandas as pd

    from stcs_ident.forward import natural_frequencies
    from stcs_ident.io.campaign import load_campaign

    truth = json.loads((archive / "truth.json").read_text())
    table = pd.read_parquet(tracked / "records.parquet")
    model = load_campaign(campaign)
    cable, attachments = model.cable, model.setup(model.tests[0].setup).attachments
    rows = {(r.cable, r.record): r for r in table.itertuples(index=False)}
    out = {"records": 0, "with_tension": 0, "modes": [], "z_low": [], "z_high": [], "z_tension": [],
           "off": 0, "off_sure": 0, "misnumbered": [], "doubtful": 0, "no_tension": [], "out_of_plane": 0}
    for name, cable_truth in truth["cables"].items():
        for true in cable_truth["records"]:
            out["records"] += 1
            row = rows.get((name, true["record"]))
            if row is None:
                out["no_tension"].append(f"{name} {true['record']}: no row in records.parquet")
                continue
            modes = np.asarray(row.modes, int) if row.status == "ok" else np.zeros(0, int)
            out["modes"].append(modes.size)
            if modes.size:
                if "frequencies" in true:  # the damped stay: the complex modes the simulator used
                    f_true = np.asarray(true["frequencies"], float)
                else:  # the bare stay: its natural frequencies at the record's true tension
                    f_true = natural_frequencies(cable, attachments, true["tension"], int(modes.max()) + 1)
                f = np.asarray(row.frequencies_Hz, float)
                s = np.asarray(row.frequency_sigma_Hz, float)
                doubtful = np.asarray(row.doubtful, bool)
                planes = np.asarray(row.planes, object)
                out["out_of_plane"] += int(np.sum(planes != "in"))
                out["doubtful"] += int(doubtful.sum())
                for n, fk, sk, dk in zip(modes, f, s, doubtful):
                    if n > f_true.size:
                        out["misnumbered"].append(f"{name} {true['record']}: mode {n} beyond the truth's "
                                                  f"{f_true.size}")
                        continue
                    t = f_true[n - 1]
                    (out["z_low"] if n <= 4 else out["z_high"]).append((fk - t) / sk)
                    if abs(fk - t) > max(3 * sk, 0.005 * t):
                        out["off"] += 1
                        out["off_sure"] += not dk
                    nearest = int(np.argmin(np.abs(f_true - fk))) + 1
                    if nearest != n:
                        out["misnumbered"].append(f"{name} {true['record']}: mode {n} at {fk:.3f} ± {sk:.3f} Hz, "
                                                  f"nearest true mode {nearest} ({f_true[nearest - 1]:.3f} Hz; "
                                                  f"mode {n} is {t:.3f})" + (" doubtful" if dk else ""))
            ok = (row.status == "ok" and np.isfinite(row.tension_N) and np.isfinite(row.tension_sigma_N)
                  and row.tension_sigma_N > 0)
            if ok:
                out["with_tension"] += 1
                out["z_tension"].append((row.tension_N - true["tension"]) / row.tension_sigma_N)
            else:
                out["no_tension"].append(f"{name} {true['record']}: status {row.status}"
                                         + (f" ({row.reason})" if row.reason else "")
                                         + f", tension {row.tension_N:.0f} ± {row.tension_sigma_N:.3g} N, "
                                         f"{modes.size} modes")
    return out


def _share(z, k: float) -> float:
    import numpy as np

    z = np.abs(np.asarray(z, float))
    return float(100 * np.mean(z <= k)) if z.size else float("nan")


def cells(r: dict) -> list[str]:
    """The row of docs/track.md's table."""
    import numpy as np

    return [f"{r['with_tension']} of {r['records']}", f"{np.mean(r['modes']):.0f}" if r["modes"] else "–",
            f"{_share(r['z_low'], 1):.0f} / {_share(r['z_low'], 3):.0f} %",
            f"{_share(r['z_high'], 1):.0f} / {_share(r['z_high'], 3):.0f} %",
            f"{_share(r['z_tension'], 1):.0f} / {_share(r['z_tension'], 3):.0f} %"]


def report(results: dict, keys: list[str]) -> None:
    import numpy as np

    head = ["records", "records with a tension", "modes per record", "frequencies within 1σ / 3σ, modes 1–4",
            "the same, mode 5 and up", "tension within 1σ / 3σ"]
    print("\n| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for key in keys:
        print("| " + " | ".join([ROWS[key][0], *cells(results[key])]) + " |")
    print()
    for key in keys:
        r = results[key]
        n_modes = len(r["z_low"]) + len(r["z_high"])
        print(f"{ROWS[key][0]}: {n_modes} numbered modes (modes 1-4: {len(r['z_low'])}, 5 and up: "
              f"{len(r['z_high'])}), modes per record mean {np.mean(r['modes']):.1f}, median "
              f"{np.median(r['modes']):.0f}, {min(r['modes'])}-{max(r['modes'])}; median |z| modes 1-4 "
              f"{np.median(np.abs(r['z_low'])):.2f}, 5 and up {np.median(np.abs(r['z_high'])):.2f}, tension "
              f"{np.median(np.abs(r['z_tension'])):.2f}; within 2σ: modes 1-4 {_share(r['z_low'], 2):.0f} %, "
              f"5 and up {_share(r['z_high'], 2):.0f} %, tension {_share(r['z_tension'], 2):.0f} %")
        print(f"  off their truth by more than max(3σ, 0.5 %): {r['off']} ({r['off_sure']} sure); doubtful: "
              f"{r['doubtful']}; out of plane: {r['out_of_plane']}; misnumbered: {len(r['misnumbered'])}; "
              f"records without a tension: {len(r['no_tension'])}")
        for line in r["misnumbered"][:10] + r["no_tension"][:10]:
            print(f"    {line}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--hours-short", type=float, default=6.0, help="hours of 60-s records per cable (6)")
    parser.add_argument("--hours-long", type=float, default=2.0, help="hours of 600-s records per cable (2)")
    parser.add_argument("--rows", default=",".join(ROWS),
                        help=f"comma-separated, of {', '.join(ROWS)} (default: all)")
    parser.add_argument("--keep", type=Path, metavar="DIR", help="keep the archives and track outputs in DIR "
                        "(an archive already there is reused)")
    args = parser.parse_args(argv)
    keys = [k.strip() for k in args.rows.split(",") if k.strip()]
    unknown = [k for k in keys if k not in ROWS]
    if unknown or not keys:
        parser.error(f"--rows: unknown {', '.join(unknown)} (of {', '.join(ROWS)})")
    from common import print_header

    print_header()
    from stcs_ident.forward import damped

    # the damped stay's complex modes (simulate, and track's damper coefficient) run it: without it, ~40x slower
    print(f"damped solver: {'compiled kernel' if damped.use_kernel() else 'NUMPY FALLBACK (slow)'}\n", flush=True)
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        root = args.keep if args.keep is not None else Path(tmp)
        root.mkdir(parents=True, exist_ok=True)
        bare = bare_campaign(root)
        results = {}
        for key in keys:
            _, duration, damped = ROWS[key]
            campaign = CAMPAIGN if damped else bare
            hours = args.hours_long if duration == 600 else args.hours_short
            run = simulate_and_track(root, key, campaign, hours, args.seed, args.workers)
            results[key] = evaluate(run["archive"], run["tracked"], campaign) | {"times": run["times"]}
    report(results, keys)
    print(f"\nseed {args.seed}, {args.hours_long:g} h of 600-s and {args.hours_short:g} h of 60-s records per cable, "
          f"2 cables, 100 Hz; {args.workers} workers; "
          + ", ".join(f"{k} {r['times']['simulate']:.0f} + {r['times']['track']:.0f} s" for k, r in results.items())
          + f" (simulate + track); total {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
