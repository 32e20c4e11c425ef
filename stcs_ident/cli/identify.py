"""``stcs-ident identify``: correct tension, EI, attachment positions... from measured frequencies."""

from __future__ import annotations

import argparse
import sys
import warnings

from ..core.errors import BoundError, InputError
from .common import (
    add_campaign_argument,
    add_json_option,
    add_plausibility_option,
    add_tension_model_option,
    command_parser,
    picked_spectra,
    prepare,
    show_warning,
    to_json,
    write_output,
)


def add_parser(sub) -> None:
    """The ``identify`` subcommand and its options."""
    parser = command_parser(sub, "identify")
    add_campaign_argument(parser)
    parser.add_argument("--params", default=None,
                        help="free parameters, e.g. tension,EI or position[W1] (default tension,EI, or tension "
                             "alone when every test has one measured mode)")
    parser.add_argument("--method", choices=("lsq", "contour"), default="lsq",
                        help="weighted least squares (default) or the source paper's contour intersection")
    add_tension_model_option(parser)
    add_plausibility_option(parser)
    add_json_option(parser)
    parser.add_argument("--plot", metavar="DIR", help="write the figures and the tables (parameters.csv, frequencies.csv) into DIR")


def run(args: argparse.Namespace) -> int:
    """Run ``identify``; returns the exit status."""
    from ..identify import identify

    campaign, file, tests = prepare(args)
    picked = {r.name: r for r in picked_spectra(campaign, tests, file)}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = identify(campaign, tests, args.params, method=args.method, picked=picked,
                              tension_model=args.tension_model, check_plausibility=args.plausibility_check)
        except InputError as err:
            raise InputError(err.message, field=err.field, file=err.file or file) from None
        except BoundError as err:
            # No result: the JSON says so (status "failed", the reason, the before/after frequencies),
            # standard output gets nothing, and the one line on standard error comes from main (exit 1).
            if args.json and err.result is not None:
                write_output(args.json, to_json(err.result.summary()))
            raise
    for w in caught:
        show_warning(w.message, w.category, w.filename, w.lineno)
    summary = result.summary()
    if args.json:
        write_output(args.json, to_json(summary))
    if args.plot is not None:
        from ..report.identify_figures import save_identify_figures
        from ..report.identify_tables import write_tables

        save_identify_figures(result, args.plot)
        write_tables(result, args.plot)
    if args.json != "-":
        from ..report.identify_tables import format_result

        sys.stdout.write(format_result(result, "text"))
        for item in summary["published"]:
            sys.stdout.write(f"\nPublished beside ours: {item['statement']}\n")
    return 0
