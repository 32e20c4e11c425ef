"""``stcs-ident spectra``: numbered modal frequencies picked from the acceleration records."""

from __future__ import annotations

import argparse
import os
import sys
from dataclasses import replace

from .common import (
    add_campaign_argument,
    add_json_option,
    command_parser,
    picked_spectra,
    prepare,
    progress_line,
    to_json,
    write_output,
)
from .reader_options import add_reader_options, as_options, reading_from_args


def add_parser(sub) -> None:
    """The ``spectra`` subcommand and its options."""
    parser = command_parser(sub, "spectra")
    add_campaign_argument(parser)
    add_json_option(parser)
    parser.add_argument("--plot", metavar="DIR", help="write one PNG per test and the picked modes (modes.csv) into DIR")
    parser.add_argument("--structural", metavar="HZ[,HZ...]", type=_frequencies,
                        help="known frequencies of the deck or pylon (Hz): peaks at them or their harmonics are "
                             "reported as structural, never numbered (records with channel directions)")
    add_reader_options(parser, "a RECORD file given instead of a campaign")


def _frequencies(text: str) -> tuple[float, ...]:
    """``1.23,2.5`` as (1.23, 2.5); argparse reports the error with the option's name."""
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be frequencies in Hz separated by commas, got {text!r}") from None
    if not values or not all(v > 0 and v < float("inf") for v in values):
        raise argparse.ArgumentTypeError(f"must be positive frequencies in Hz separated by commas, got {text!r}")
    return values


def run(args: argparse.Namespace) -> int:
    """Run ``spectra``; returns the exit status."""
    from ..report.spectra_tables import spectra_text

    reading = reading_from_args(args, _is_record(args.campaign), "a record file given instead of a campaign")
    if reading is not None or _is_record(args.campaign):
        return _run_record(args, reading)
    campaign, file, tests = prepare(args)
    if args.structural:
        from ..spectra.pipeline import analyse_campaign
        from ..spectra.plane_options import PlaneOptions

        results = analyse_campaign(campaign, tests, progress=progress_line,
                                   plane_options=PlaneOptions(structural=args.structural))
    else:
        results = picked_spectra(campaign, tests, file)
    skipped = [t.name for t in campaign.tests if t.record is None and (not tests or t.name in tests)]
    if args.json:
        from ..spectra.pipeline import campaign_summary

        write_output(args.json, to_json(campaign_summary(campaign.name, results, skipped)))
    if args.plot is not None:
        from ..report.plots import plot_test_spectra, save_figure
        from ..report.spectra_tables import write_modes_csv

        os.makedirs(args.plot, exist_ok=True)
        for r in results:
            save_figure(plot_test_spectra(r)["figure"], os.path.join(args.plot, f"{r.name}.png"))
        write_modes_csv(results, args.plot)
    if args.json != "-":
        sys.stdout.write(spectra_text(campaign.name, results, skipped))
    return 0


def _is_record(path: str) -> bool:
    """Whether the positional argument is a record file (not a campaign directory or its TOML file)."""
    return os.path.isfile(path) and not path.lower().endswith(".toml")


def _run_record(args: argparse.Namespace, reading) -> int:
    """``spectra FILE``: the record's peaks, unnumbered (no campaign: no model to number them against)."""
    from ..core.errors import InputError
    from ..identify.quick_record import pick_unnumbered, unnumbered_summary
    from ..io.records.validation import UnknownPositions
    from ..io.test_record import RecordReading, open_record

    for option, value in (("--test", args.test), ("--plot", args.plot), ("--structural", args.structural)):
        if value is not None:
            raise InputError("needs a campaign: a record alone is listed unnumbered", field=option)
    reading = reading or RecordReading()
    try:
        record = open_record(args.campaign, replace(reading, positions=reading.positions or UnknownPositions()))
    except InputError as err:  # a reader's fix said as the option to type
        raise as_options(err) from None
    peaks = pick_unnumbered(record)
    summary = unnumbered_summary(args.campaign, record, peaks)
    rows, hint = summary["peaks"], summary["hint"]
    if args.json:
        write_output(args.json, to_json(summary))
    if args.json != "-":
        lines = [(f"Record {args.campaign}: {peaks.kind}, {record.duration:.4g} s at {record.sampling_rate:.6g} Hz, "
                  f"channels {', '.join(record.channel_names)}; {len(rows)} peaks, unnumbered (no campaign)"), "",
                 f"{'frequency':>11} {'1σ (Hz)':>9} {'damping %':>9}  channels"]
        for r in rows:
            zeta = "-" if r["damping"] is None else f"{100 * r['damping']:.3f}"
            lines.append(f"{r['frequency']:>11.5f} {r['uncertainty']:>9.2g} {zeta:>9}  {' '.join(r['channels'])}")
        lines += [f"  note: {n}" for n in getattr(record, "notes", ())]
        lines += ["", f"numbered and a tension: {hint}"]
        sys.stdout.write("\n".join(lines) + "\n")
    return 0
