"""``stcs-ident spectra``: numbered modal frequencies picked from the acceleration records."""

from __future__ import annotations

import argparse
import os
import sys

from .common import add_campaign_argument, add_json_option, command_parser, picked_spectra, prepare, write_output


def add_parser(sub) -> None:
    """The ``spectra`` subcommand and its options."""
    parser = command_parser(sub, "spectra")
    add_campaign_argument(parser)
    add_json_option(parser)
    parser.add_argument("--plot", metavar="DIR", help="write one PNG per test and the picked modes (modes.csv) into DIR")


def run(args: argparse.Namespace) -> int:
    """Run ``spectra``; returns the exit status."""
    from ..report.forward import spectra_text, to_json

    campaign, file, tests = prepare(args)
    results = picked_spectra(campaign, tests, file)
    skipped = [t.name for t in campaign.tests if t.record is None and (not tests or t.name in tests)]
    if args.json:
        write_output(args.json, to_json({"campaign": campaign.name, "tests": [r.summary() for r in results],
                                         "skipped": skipped}))
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
