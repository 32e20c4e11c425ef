"""``stcs-ident forward``: the nominal model against measured and published frequencies."""

from __future__ import annotations

import argparse
import sys

from .common import (
    add_campaign_argument,
    add_json_option,
    add_tension_model_option,
    command_parser,
    picked_spectra,
    prepare,
    to_json,
    write_output,
)


def _mode_count(text: str) -> int:
    """``--modes``: a mode number 1 … MAX_MODE (argparse reports a refusal as a bad option)."""
    from ..core.model import mode_number

    try:
        return mode_number(int(text), "--modes")
    except ValueError as err:  # not an integer, or out of range (ModelError is a ValueError)
        raise argparse.ArgumentTypeError(getattr(err, "message", f"must be an integer, got {text!r}")) from None


def add_parser(sub) -> None:
    """The ``forward`` subcommand and its options."""
    parser = command_parser(sub, "forward")
    add_campaign_argument(parser)
    parser.add_argument("--modes", type=_mode_count, metavar="N", help="modes to compute (default: measured, at least 6)")
    add_tension_model_option(parser)
    parser.add_argument("--plane", choices=("in", "out", "both"), default=None,
                        help="families of modes: in-plane, out-of-plane or both (default: both when a test has "
                             "out-of-plane frequencies, else in)")
    add_json_option(parser)


def run(args: argparse.Namespace) -> int:
    """Run ``forward``; returns the exit status."""
    from ..forward.compare import compare_forward
    from ..report.forward import forward_text

    campaign, file, tests = prepare(args)
    picked = {r.name: (r.modes, r.frequencies, r.mode_planes) for r in picked_spectra(campaign, tests, file)}
    result = compare_forward(campaign, tests, args.modes, args.tension_model, picked=picked, plane=args.plane)
    text = forward_text(result)
    if args.json:
        write_output(args.json, to_json(result.summary()))
    if args.json != "-":
        sys.stdout.write(text)
    warning = plausibility_warning(campaign, tests, picked, args.tension_model)
    if warning:
        print(f"stcs-ident: warning: {warning}", file=sys.stderr)
    return 0


def plausibility_warning(campaign, tests, picked, tension_model: str) -> str | None:
    """What ``identify`` and ``diagnose`` would refuse the campaign for (a unit slip, most likely), or None:
    ``forward`` only says it. ``picked``: {test: (modes, frequencies, planes)}; the in-plane frequencies are
    assessed."""
    import numpy as np

    from ..identify.plausibility import assess
    from ..identify.problem import Measurement

    measurements = []
    for t in campaign.tests:
        if tests and t.name not in tests:
            continue
        modes, freqs, planes = picked.get(t.name, (t.modes, t.frequencies, t.planes))
        if freqs is not None and planes is not None:  # the in-plane ones: what identify checks
            kept = [i for i, p in enumerate(planes) if p == "in"]
            modes, freqs = [modes[i] for i in kept], [freqs[i] for i in kept]
        if freqs is not None and len(freqs):
            measurements.append(Measurement(t, np.asarray(modes, int), np.asarray(freqs, float),
                                            np.ones(len(freqs)), "measured"))
    found = assess(campaign, measurements, tension_model) if measurements else None
    return None if found is None else f"field '{found[0]}': {found[1]} (identify and diagnose refuse it)"
