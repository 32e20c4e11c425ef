"""Command line: ``stcs-ident forward CAMPAIGN ...``.

Exit status 0 on success, 2 for bad input (one line on standard error
naming the file, the field and what is wrong; nothing written), 1 for a
computation that failed. ``--debug`` shows the traceback.
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback

from .errors import ComputationError, InputError


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="stcs-ident", description=__doc__.splitlines()[0])
    parser.add_argument("--debug", action="store_true", help="show tracebacks")
    sub = parser.add_subparsers(dest="command", required=True)
    fwd = sub.add_parser("forward", help="nominal model against measured and published frequencies")
    fwd.add_argument("campaign", help="campaign directory or its campaign.toml")
    fwd.add_argument("--test", action="append", metavar="NAME", help="only this test (repeatable)")
    fwd.add_argument("--modes", type=int, metavar="N", help="modes to compute (default: measured, at least 6)")
    fwd.add_argument("--tension-model", choices=("uniform", "per-segment", "none"), default="uniform",
                     help="additional tension from sag-extensibility (default uniform)")
    fwd.add_argument("--json", metavar="FILE", help="write the JSON result ('-' for standard output)")
    fwd.add_argument("--debug", action="store_true", help=argparse.SUPPRESS)
    spe = sub.add_parser("spectra", help="numbered modal frequencies picked from the acceleration records")
    spe.add_argument("campaign", help="campaign directory or its campaign.toml")
    spe.add_argument("--test", action="append", metavar="NAME", help="only this test (repeatable)")
    spe.add_argument("--json", metavar="FILE", help="write the JSON result ('-' for standard output)")
    spe.add_argument("--plot", metavar="DIR", help="write one PNG per test into DIR")
    spe.add_argument("--debug", action="store_true", help=argparse.SUPPRESS)
    return parser


def _selected_tests(campaign, names, file):
    known = [t.name for t in campaign.tests]
    for name in names or []:
        if name not in known:
            raise InputError(f"no test named {name!r} (known: {', '.join(known)})", field="test", file=file)
    return names


def _check_output(path) -> None:
    """Refuse an output file whose directory does not exist, before any work."""
    if path in (None, "-"):
        return
    parent = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(parent):
        raise InputError(f"directory {parent} does not exist", field="--json", file=str(path))


def _write(path, text) -> None:
    from .report import write_atomic

    try:
        write_atomic(path, text)
    except OSError as err:
        raise InputError(f"cannot write: {err.strerror}", field="--json", file=str(path)) from err


def _progress(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def _picked(campaign, tests, file):
    """Spectra of the selected tests that have records (for forward and spectra)."""
    if not any(t.record is not None for t in campaign.tests if not tests or t.name in tests):
        return []
    from .spectra.pipeline import analyse_campaign

    return analyse_campaign(campaign, tests, progress=_progress)


def _spectra(args) -> int:
    from .campaign_io import campaign_file, load_campaign
    from .report import spectra_text, to_json

    campaign = load_campaign(args.campaign)
    file = str(campaign_file(args.campaign))
    tests = _selected_tests(campaign, args.test, file)
    _check_output(args.json)
    if args.plot is not None and os.path.exists(args.plot) and not os.path.isdir(args.plot):
        raise InputError("exists and is not a directory", field="--plot", file=args.plot)
    results = _picked(campaign, tests, file)
    skipped = [t.name for t in campaign.tests if t.record is None and (not tests or t.name in tests)]
    if args.json:
        _write(args.json, to_json({"campaign": campaign.name, "tests": [r.summary() for r in results],
                                   "skipped": skipped}))
    if args.plot is not None:
        from .plots import plot_test_spectra, save_figure

        os.makedirs(args.plot, exist_ok=True)
        for r in results:
            save_figure(plot_test_spectra(r)["figure"], os.path.join(args.plot, f"{r.name}.png"))
    if args.json != "-":
        sys.stdout.write(spectra_text(campaign.name, results, skipped))
    return 0


def _forward(args) -> int:
    from .campaign_io import campaign_file, load_campaign
    from .compare import compare_forward
    from .report import forward_text, to_json

    campaign = load_campaign(args.campaign)
    file = str(campaign_file(args.campaign))
    if args.modes is not None and args.modes < 1:
        raise InputError(f"must be >= 1, got {args.modes}", field="--modes")
    tests = _selected_tests(campaign, args.test, file)
    _check_output(args.json)
    picked = {r.name: (r.modes, r.frequencies) for r in _picked(campaign, tests, file)}
    result = compare_forward(campaign, tests, args.modes, args.tension_model, picked=picked)
    text = forward_text(result)
    if args.json:
        _write(args.json, to_json(result.summary()))
    if args.json != "-":
        sys.stdout.write(text)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    parser = _parser()
    args = parser.parse_args(argv)
    try:
        return {"forward": _forward, "spectra": _spectra}[args.command](args)
    except InputError as err:
        if args.debug:
            traceback.print_exc()
        print(f"stcs-ident: {err}", file=sys.stderr)
        return 2
    except (ComputationError, FloatingPointError) as err:
        if args.debug:
            traceback.print_exc()
        print(f"stcs-ident: computation failed: {err}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
