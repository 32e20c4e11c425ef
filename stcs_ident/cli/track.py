"""``stcs-ident track`` (an archive of field records into tension histories) and ``simulate --archive``'s options."""

from __future__ import annotations

import argparse
import sys

from ..core.errors import InputError
from .commands import ARCHIVE_EXAMPLE, COMMANDS
from .common import add_plausibility_option, command_parser, to_json, worker_count, write_output

TRACK_EXAMPLE = COMMANDS["track"].examples[0]

__all__ = ["ARCHIVE_EXAMPLE", "TRACK_EXAMPLE", "add_archive_options", "add_parser", "check_archive_only", "run",
           "simulate_archive_from_args"]


def add_parser(sub) -> None:
    """The ``track`` subcommand and its options."""
    trk = command_parser(sub, "track",
                         description="Brings the table of ARCHIVE/<cable>/records/ up to date (a record new, "
                                     "changed, processed under another campaign or failed before is processed; "
                                     "a record gone leaves the table): modes, tension with 1σ, temperature "
                                     "normalisation, lasting changes. Writes OUT/records.parquet (and the same table as "
                                     "OUT/records.csv), OUT/report.md, OUT/<cable>.png, OUT/events.csv and "
                                     "OUT/cables.csv.")
    trk.add_argument("archive", help="archive directory: one folder per cable with campaign.toml and records/")
    trk.add_argument("--cable", action="append", metavar="NAME", help="only this cable (repeatable)")
    trk.add_argument("--out", metavar="DIR", help="output directory, also the state of reruns "
                                                  "(default ARCHIVE.track beside the archive)")
    trk.add_argument("--json", metavar="FILE", help="write the JSON summary ('-' for standard output)")
    trk.add_argument("--workers", type=worker_count, default=1, metavar="N", help="local processes (default 1)")
    trk.add_argument("--scheduler", metavar="ADDRESS",
                     help="a Dask distributed scheduler (tcp://host:8786) to run the records on instead")
    add_plausibility_option(trk)


def run(args: argparse.Namespace) -> int:
    """Run ``track``; returns the exit status."""
    import os

    from ..core.files import check_outputs, check_path
    from ..core.formatting import counted
    from ..report.track import write_report
    from ..track.api import default_out, track
    from ..track.archive import discover, record_paths

    if args.scheduler is not None:  # a malformed address, or no Dask scheduler behind it: refused before any work
        from ..track.execution import probe_scheduler

        probe_scheduler(args.scheduler)
    check_path(args.archive)  # (default_out resolves it)
    out = args.out if args.out is not None else str(default_out(args.archive))
    specs = discover(args.archive, args.cable)  # refuses a bad archive before any work
    inputs = [os.path.join(s.directory, "campaign.toml") for s in specs]
    inputs += [str(p) for s in specs for p in record_paths(s)]
    check_outputs([("--out", out, True), ("--json", args.json, False)], inputs)
    result = track(args.archive, out, cables=args.cable, workers=args.workers, scheduler=args.scheduler,
                   progress=True if sys.stderr.isatty() else _lines(), check_plausibility=args.plausibility_check)
    print(result.run_line(), file=sys.stderr)
    write_report(result)
    summary = result.summary()
    if args.json:
        write_output(args.json, to_json(summary))
    if args.json != "-":
        for name, cable in summary["cables"].items():
            events = "; ".join(f"{100 * e['change']:+.2f} ± {100 * e['uncertainty']:.2f} % from {e['start_time']}"
                               for e in cable["events"]) or _quiet(cable)
            print(f"{name}: {cable['processed']} of {counted(cable['records'], 'record')} with a tension, "
                  f"{cable['failed']} failed; {events}")
            if "damper" in cable:
                damper = cable["damper"]
                changes = "; ".join(f"{100 * e['change']:+.1f} ± {100 * e['uncertainty']:.1f} % from "
                                    f"{e['start_time']}" for e in damper["events"]) or _quiet(damper)
                print(f"{name} damper: {damper['records']} records with a coefficient; {changes}")
        print(f"wrote {out}")
    return 0


def _quiet(history: dict) -> str:
    """What a history without events says: no lasting change while monitoring; else its state in words (the
    summary's ``state_note``: not monitoring yet, the rule and the records still needed), as the report says it."""
    return "no lasting change" if history["state"] == "monitoring" else history["state_note"]


def add_archive_options(sim) -> None:
    arc = sim.add_argument_group("archive (days of monitoring records instead of one record per test)")
    arc.add_argument("--archive", type=float, metavar="DAYS",
                     help="write OUT as an archive for `track`: DAYS of ambient records per cable (the campaign's "
                          "cable and first test), with daily temperature cycles and record-to-record scatter")
    arc.add_argument("--cables", type=int, default=1, metavar="N", help="cables C1 … CN, all of the campaign (1)")
    arc.add_argument("--interval", type=float, default=600.0, metavar="S", help="seconds between records (600)")
    arc.add_argument("--workers", type=worker_count, default=1, metavar="N",
                     help="local processes simulating the records (default 1; the archive is the same whatever N)")
    arc.add_argument("--tension-change", metavar="CABLE,TIME,REL",
                     help="a lasting relative tension change of one cable from an ISO 8601 time on")
    arc.add_argument("--damper-change", action="append", metavar="CABLE[:DAMPER],KIND,TIME[,FRACTION[,DAYS]]",
                     help="a damper of a cable degrades from an ISO 8601 time on (repeatable): KIND leak (the "
                          "coefficient drops by FRACTION), loss (linearly, by FRACTION after DAYS) or seizure (the "
                          "coefficient grows 20-fold: the damper's node nearly stops); every damper of the cable "
                          "unless :DAMPER names one")
    arc.add_argument("--damper-temperature-coefficient", type=float, metavar="A",
                     help="per °C: a damper's coefficient is c·exp(-A (θ - θ_mean)), stiffer in the cold "
                          "(default 0.015, silicone oil; 0: constant)")


def check_archive_only(args) -> None:
    """Refuses the damper options of an archive given without ``--archive`` (one line, exit 2)."""
    for flag, given in (("--damper-change", args.damper_change),
                        ("--damper-temperature-coefficient", args.damper_temperature_coefficient)):
        if given is not None:
            raise InputError("applies to an archive (--archive DAYS), not to a campaign's records", field=flag)


def simulate_archive_from_args(args, campaign) -> int:
    from ..simulate.archive import ArchiveOptions, TensionChange, simulate_archive
    from ..simulate.damper_history import check_damper_changes

    if not 1 <= args.cables <= 1000:
        raise InputError(f"must be 1 … 1000, got {args.cables}", field="--cables")
    names = [f"C{k}" for k in range(1, args.cables + 1)]
    change = None
    if args.tension_change:
        parts = args.tension_change.split(",")
        if len(parts) != 3:
            raise InputError(f"expected CABLE,TIME,REL, got {args.tension_change!r}", field="--tension-change")
        try:
            change = TensionChange(parts[0], parts[1], float(parts[2]))
        except ValueError as err:
            raise InputError(getattr(err, "message", str(err)), field="--tension-change") from None
        if change.cable not in names:
            raise InputError(f"no cable named {change.cable!r} (cables: {', '.join(names)})",
                             field="--tension-change")
    damper_changes = [_damper_change(text) for text in args.damper_change or ()]
    if damper_changes and campaign.tests:  # a campaign without a test is refused by the archive itself
        try:
            check_damper_changes(damper_changes, dict.fromkeys(names, campaign.setup(campaign.tests[0].setup)
                                                               .attachments))
        except ValueError as err:
            raise InputError(getattr(err, "message", str(err)), field="--damper-change") from None
    temperature = {} if args.damper_temperature_coefficient is None else {
        "damper_temperature_coefficient": args.damper_temperature_coefficient}
    try:
        options = ArchiveOptions(days=args.archive, interval=args.interval, duration=args.duration,
                                 sampling_rate=args.sampling_rate, snr_db=args.snr, damping=args.damping,
                                 rms_pressure=args.ambient or 20.0,
                                 sensors=tuple(float(x) for x in args.sensors.split(",")), **temperature)
    except ValueError as err:
        options_of = {"archive.days": "--archive", "archive.snr_db": "--snr", "archive.rms_pressure": "--ambient",
                      "archive.interval": "--interval", "archive.duration": "--duration",
                      "archive.sampling_rate": "--sampling-rate", "archive.damping": "--damping",
                      "archive.damper_temperature_coefficient": "--damper-temperature-coefficient"}
        raise InputError(getattr(err, "message", str(err)),
                         field=options_of.get(getattr(err, "field", None), "--archive")) from None
    if options.n_records * args.cables > 10**6:
        raise InputError(f"gives {options.n_records * args.cables} records; at most 1,000,000", field="--archive")
    out = simulate_archive(dict.fromkeys(names, campaign), args.out, options=options, change=change,
                           damper_changes=damper_changes, seed=args.seed, workers=args.workers,
                           progress=_every(500))
    print(f"wrote {out}")
    return 0


def _damper_change(text: str):
    """``CABLE[:DAMPER],KIND,TIME[,FRACTION[,DAYS]]`` as a DamperChange; InputError naming ``--damper-change``."""
    from ..simulate.damper_history import DamperChange

    parts = text.split(",")
    if not 3 <= len(parts) <= 5:
        raise InputError(f"expected CABLE[:DAMPER],KIND,TIME[,FRACTION[,DAYS]], got {text!r}", field="--damper-change")
    cable, _, damper = parts[0].partition(":")
    numbers = []
    for label, part in zip(("FRACTION", "DAYS"), parts[3:]):
        try:
            numbers.append(float(part))
        except ValueError:
            raise InputError(f"{label} must be a number, got {part!r} in {text!r}", field="--damper-change") from None
    fraction, days = (*numbers, None, None)[:2]
    try:
        return DamperChange(cable, parts[1].strip(), parts[2], fraction=fraction, days=days, damper=damper or None)
    except ValueError as err:
        what = getattr(err, "field", None) or ""
        raise InputError(f"{what.removeprefix('damper_change.') or 'value'}: {getattr(err, 'message', str(err))} "
                         f"(in {text!r})", field="--damper-change") from None


def _lines():
    """Progress as a line on standard error every 5 % of the records, with the time left (not a terminal)."""
    import time

    from ..core.formatting import counted

    started, shown = time.perf_counter(), [-1]

    def progress(done, total):
        step = int(20 * done / total)
        if step > shown[0] or done == total:
            shown[0] = step
            elapsed = time.perf_counter() - started
            left = elapsed / done * (total - done)
            print(f"track: {done} of {counted(total, 'record')}, {elapsed:.0f} s, about {left:.0f} s left", file=sys.stderr,
                  flush=True)
    return progress


def _every(n: int):
    def progress(done, total):
        if done % n == 0 or done == total:
            print(f"simulate: record {done} of {total}", file=sys.stderr, flush=True)
    return progress
