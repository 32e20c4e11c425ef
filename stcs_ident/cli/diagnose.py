"""``stcs-ident diagnose``: what the model gets wrong, its cause among physical effects, and the gain."""

from __future__ import annotations

import argparse
import os
import sys

from .. import effects
from ..core.errors import InputError
from .common import (
    add_campaign_argument,
    add_json_option,
    add_plausibility_option,
    add_tension_model_option,
    command_parser,
    picked_spectra,
    prepare,
    step_progress,
    to_json,
    worker_count,
    write_output,
)

#: Largest default number of processes (:data:`stcs_ident.diagnose.api.MAX_WORKERS`, which imports the solver).
DEFAULT_MAX_WORKERS = 8


def add_parser(sub) -> None:
    """The ``diagnose`` subcommand and its options (the effect vocabulary from the registry)."""
    parser = command_parser(sub, "diagnose")
    add_campaign_argument(parser)
    parser.add_argument("--effects", metavar="LIST",
                        help=f"effects to consider, comma-separated (default all: {', '.join(effects.names())})")
    parser.add_argument("--max-effects", type=int, choices=(1, 2), default=2,
                        help="largest number of effects in one hypothesis, besides the baseline (tension + EI) "
                             "plus max-effects - 1 further ones (default 2)")
    parser.add_argument("--all-hypotheses", action="store_true",
                        help="fit every pair of effects even when the nominal model explains the data")
    add_tension_model_option(parser)
    add_plausibility_option(parser)
    parser.add_argument("--workers", type=worker_count, metavar="N",
                        help="processes fitting hypotheses in parallel (default: the processors this process may "
                             f"use, at most {DEFAULT_MAX_WORKERS}; 1 fits them in this process)")
    add_json_option(parser)
    parser.add_argument("--out", metavar="DIR", help="write the report (report.md, figures, CSV tables) into DIR")


def run(args: argparse.Namespace) -> int:
    """Run ``diagnose``; returns the exit status."""
    from ..diagnose import diagnose

    campaign, file, tests = prepare(args)
    if args.out is not None:  # before any work: a report directory that would be refused after it
        from ..report.diagnose import check_report_directory

        check_report_directory(args.out, field="--out")
    picked = {r.name: r for r in picked_spectra(campaign, tests, file)}
    try:
        result = diagnose(campaign, tests, effects=args.effects, picked=picked, max_effects=args.max_effects,
                          tension_model=args.tension_model, all_hypotheses=args.all_hypotheses,
                          workers=args.workers, progress=step_progress("diagnose", "hypothesis"),
                          check_plausibility=args.plausibility_check)
    except InputError as err:
        raise InputError(err.message, field=err.field, file=err.file or file) from None
    if args.json:
        write_output(args.json, to_json(result.summary()))
    if args.out is not None:
        from ..report.diagnose import write_report

        write_report(result, args.out)
    if args.json != "-":
        from ..report.diagnose import diagnosis_text

        sys.stdout.write(diagnosis_text(result))
        if args.out is not None:
            sys.stdout.write(f"report: {os.path.join(args.out, 'report.md')}\n")
    return 0
