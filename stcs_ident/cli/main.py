"""The ``stcs-ident`` command line (forward, spectra, simulate, identify, diagnose).

Exit status 0 on success, 2 for bad input (one line on standard error
naming the file, the field and what is wrong; nothing written), 1 for a
computation that failed. ``--debug`` shows the traceback.
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback
import warnings

from .. import effects
from ..core.errors import ComputationError, InputError, StcsWarning, one_line
from ..core.version import __version__
from .track import ARCHIVE_EXAMPLE, TRACK_EXAMPLE, add_archive_options, add_track_parser, run_track

DESCRIPTION = """\
stcs-ident: cable force, bending stiffness and model diagnosis from the
vibration records of stay cables, hangers and suspension cables (exact
dynamic-stiffness model of a tensioned, sagging cable with attachments)."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose help starts with what the tool is, then the usage."""

    def format_help(self) -> str:
        formatter = self._get_formatter()
        formatter.add_text(self.description)
        formatter.add_usage(self.usage, self._actions, self._mutually_exclusive_groups)
        for group in self._action_groups:
            formatter.start_section(group.title)
            formatter.add_text(group.description)
            formatter.add_arguments(group._group_actions)
            formatter.end_section()
        formatter.add_text(self.epilog)
        return formatter.format_help()

    def error(self, message: str):
        """A bad option: one line on standard error (what is wrong and where help is), exit status 2."""
        self.exit(2, f"{self.prog}: error: {one_line(message)} (see {self.prog} --help)\n")

#: One real example per command (the shipped campaigns), shown in --help.
EXAMPLES = {
    "forward": "stcs-ident forward campaigns/han2020 --test case1-L4 --modes 8",
    "spectra": "stcs-ident spectra campaigns/hanger-hidden-mass --json picked.json --plot spectra/",
    "simulate": "stcs-ident simulate campaigns/han2020 --out sim/ --test case1-L4 --extra-mass 5@6.0 --seed 1",
    "identify": "stcs-ident identify campaigns/han2020 --test case1-L4 --params tension,EI --method contour --plot figures/",
    "diagnose": "stcs-ident diagnose campaigns/han2020 --out report/",
    "track": TRACK_EXAMPLE,
}


#: Option strings of each command (to name an option in a message about its value).
_OPTIONS: dict[str, set[str]] = {}


def _mode_count(text: str) -> int:
    """``--modes``: a mode number 1 … MAX_MODE (argparse reports a refusal as a bad option)."""
    from ..core.model import mode_number

    try:
        return mode_number(int(text), "--modes")
    except ValueError as err:  # not an integer, or out of range (ModelError is a ValueError)
        raise argparse.ArgumentTypeError(getattr(err, "message", f"must be an integer, got {text!r}")) from None


def _epilog(*commands: str) -> str:
    return "example" + ("s" if len(commands) > 1 else "") + ":\n" + "\n".join(f"  {EXAMPLES[c]}" for c in commands)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``stcs-ident`` (its subcommands and options)."""
    raw = argparse.RawDescriptionHelpFormatter
    parser = _Parser(prog="stcs-ident", description=DESCRIPTION, epilog=_epilog(*EXAMPLES), formatter_class=raw)
    parser.add_argument("--version", action="version", version=f"stcs-ident {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks")
    sub = parser.add_subparsers(dest="command", required=True)
    fwd = sub.add_parser("forward", epilog=_epilog("forward"), formatter_class=argparse.RawDescriptionHelpFormatter, help="nominal model against measured and published frequencies")
    fwd.add_argument("campaign", help="campaign directory or its campaign.toml")
    fwd.add_argument("--test", action="append", metavar="NAME", help="only this test (repeatable)")
    fwd.add_argument("--modes", type=_mode_count, metavar="N",
                     help="modes to compute (default: measured, at least 6)")
    fwd.add_argument("--tension-model", choices=("uniform", "per-segment", "none"), default="uniform",
                     help="additional tension from sag-extensibility (default uniform)")
    fwd.add_argument("--json", metavar="FILE", help="write the JSON result ('-' for standard output)")
    fwd.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS)
    spe = sub.add_parser("spectra", epilog=_epilog("spectra"), formatter_class=argparse.RawDescriptionHelpFormatter, help="numbered modal frequencies picked from the acceleration records")
    spe.add_argument("campaign", help="campaign directory or its campaign.toml")
    spe.add_argument("--test", action="append", metavar="NAME", help="only this test (repeatable)")
    spe.add_argument("--json", metavar="FILE", help="write the JSON result ('-' for standard output)")
    spe.add_argument("--plot", metavar="DIR", help="write one PNG per test into DIR")
    spe.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS)
    _simulate_parser(sub)
    idf = sub.add_parser("identify", epilog=_epilog("identify"), formatter_class=argparse.RawDescriptionHelpFormatter, help="correct tension, EI, attachment positions... from measured frequencies")
    idf.add_argument("campaign", help="campaign directory or its campaign.toml")
    idf.add_argument("--test", action="append", metavar="NAME", help="only this test (repeatable)")
    idf.add_argument("--params", default="tension,EI",
                     help="free parameters, e.g. tension,EI or position[W1] (default tension,EI)")
    idf.add_argument("--method", choices=("lsq", "contour"), default="lsq",
                     help="weighted least squares (default) or the source paper's contour intersection")
    idf.add_argument("--tension-model", choices=("uniform", "per-segment", "none"), default="uniform")
    idf.add_argument("--json", metavar="FILE", help="write the JSON result ('-' for standard output)")
    idf.add_argument("--plot", metavar="DIR", help="write the figures into DIR")
    idf.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS)
    dia = sub.add_parser("diagnose", epilog=_epilog("diagnose"), formatter_class=argparse.RawDescriptionHelpFormatter, help="what the model gets wrong, its cause among physical effects, and the gain")
    dia.add_argument("campaign", help="campaign directory or its campaign.toml")
    dia.add_argument("--test", action="append", metavar="NAME", help="only this test (repeatable)")
    dia.add_argument("--effects", metavar="LIST",
                     help=f"effects to consider, comma-separated (default all: {', '.join(effects.names())})")
    dia.add_argument("--max-effects", type=int, choices=(1, 2), default=2,
                     help="largest number of effects in one hypothesis, besides the baseline (tension + EI) "
                          "plus max-effects - 1 further ones (default 2)")
    dia.add_argument("--all-hypotheses", action="store_true",
                     help="fit every pair of effects even when the nominal model explains the data")
    dia.add_argument("--tension-model", choices=("uniform", "per-segment", "none"), default="uniform")
    dia.add_argument("--json", metavar="FILE", help="write the JSON result ('-' for standard output)")
    dia.add_argument("--out", metavar="DIR", help="write the report (report.md, figures, CSV tables) into DIR")
    dia.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS)
    add_track_parser(sub, _epilog("track"))
    for name, command in sub.choices.items():
        _OPTIONS[name] = {o for action in command._actions for o in action.option_strings}
    return parser


def _simulate_parser(sub) -> None:
    sim = sub.add_parser("simulate", epilog=f"examples:\n  {EXAMPLES['simulate']}\n  {ARCHIVE_EXAMPLE}", formatter_class=argparse.RawDescriptionHelpFormatter, help="simulated records of a campaign's tests, with optional hidden effects",
                         description="Writes OUT/campaign.toml (the nominal cable only), OUT/records/<test>.h5 "
                                     "and OUT/truth.json (the true model and frequencies).")
    sim.add_argument("campaign", help="campaign directory or its campaign.toml")
    sim.add_argument("--out", required=True, metavar="DIR", help="output directory (new or empty)")
    sim.add_argument("--test", action="append", metavar="NAME", help="only this test (repeatable)")
    sim.add_argument("--sensors", default="0.23,0.5,0.71", metavar="X,...",
                     help="sensor positions as fractions of the length (default 0.23,0.5,0.71)")
    sim.add_argument("--duration", type=float, default=60.0, metavar="S", help="record length, s (default 60)")
    sim.add_argument("--sampling-rate", type=float, default=200.0, metavar="HZ", help="default 200 Hz")
    sim.add_argument("--damping", type=float, default=0.005, metavar="ZETA", help="modal damping ratio (0.005)")
    sim.add_argument("--impulses", type=int, default=1, metavar="N",
                     help="hand-excitation events from t = 1 s, duration/N s apart (at least 1 s; default 1; "
                          "0 for none)")
    sim.add_argument("--ambient", type=float, default=None, metavar="PA",
                     help="ambient random pressure, RMS N/m per metre (default off)")
    sim.add_argument("--snr", type=float, default=30.0, metavar="DB", help="sensor noise, dB (default 30)")
    sim.add_argument("--seed", type=int, default=0)
    sim.add_argument("--overwrite", action="store_true", help="replace a non-empty output directory")
    fld = sim.add_argument_group("field conditions (what field records carry besides the cable's response)")
    fld.add_argument("--lowpass", type=float, metavar="HZ",
                     help="colour the ambient loading with a 2nd-order low-pass at HZ (wind; needs --ambient)")
    fld.add_argument("--drift", metavar="REL[@S]",
                     help="slow tension drift within each record: a sinusoid of relative amplitude REL and "
                          "period S s (default 300); truth.json then holds the time-averaged frequencies")
    fld.add_argument("--pink-noise", type=float, metavar="REL", help="1/f sensor noise, rms relative to the signal")
    fld.add_argument("--hum", metavar="HZ:A1[,A2...]",
                     help="mains hum at HZ and its harmonics, amplitudes relative to the signal rms")
    fld.add_argument("--dc-offset", type=float, metavar="REL", help="a DC offset in every channel, relative to "
                                                                    "the signal rms")
    fld.add_argument("--float32", action="store_true", help="write single-precision samples")
    fld.add_argument("--field-random", action="store_true",
                     help="random field-like conditions per test (each part on with probability 0.75; from --seed)")
    eff = sim.add_argument_group("hidden effects (in the records, not in the written campaign)")
    for effect in effects.effects():
        if effect.option is not None:
            o = effect.option
            eff.add_argument(o.flag, dest=f"effect_{effect.name}", metavar=o.metavar,
                             action="append" if o.repeatable else "store", help=f"{effect.name}: {o.help}")
    add_archive_options(sim)
    sim.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS)


def _simulate(args) -> int:
    from ..core.files import check_outputs
    from ..io.campaign import campaign_file, load_campaign
    from ..simulate.effects import Effects
    from ..simulate.simulate import Ambient, Impulse
    from ..simulate.simulate_campaign import simulate_campaign

    campaign = load_campaign(args.campaign)
    file = str(campaign_file(args.campaign))
    check_outputs([("--out", args.out, True)], _inputs(campaign, file))
    if args.archive is not None:
        if os.path.exists(args.out) and os.listdir(args.out) and not args.overwrite:
            raise InputError("exists and is not empty (use --overwrite to replace it)", field="--out", file=args.out)
        from .track import simulate_archive_from_args

        return simulate_archive_from_args(args, campaign)
    try:
        fractions = [float(x) for x in args.sensors.split(",")]
    except ValueError:
        raise InputError(f"expected fractions like 0.2,0.5, got {args.sensors!r}", field="--sensors") from None
    if not all(0 < x < 1 for x in fractions):
        raise InputError("fractions of the length must lie in (0, 1)", field="--sensors")
    length = campaign.cable.length
    hidden = {}
    for effect in effects.effects():
        given = getattr(args, f"effect_{effect.name}", None)
        if effect.option is not None and given is not None:
            hidden[effect.truth_key] = effect.parse_option(given)
    impulses = (Impulse(1.0 + i * max(args.duration / max(args.impulses, 1), 1.0), 0.17 * length, 50.0)
                for i in range(args.impulses))  # lazily: simulate refuses more than it can take
    ambient = Ambient(args.ambient) if args.ambient else None
    if os.path.exists(args.out) and os.listdir(args.out) and not args.overwrite:
        raise InputError("exists and is not empty (use --overwrite to replace it)", field="--out", file=args.out)
    effect = Effects(**hidden) if hidden else None  # a refusal names effects.<key>, shown as its option
    field = _field_conditions(args, campaign, len(fractions))
    out = simulate_campaign(campaign, args.out, positions=[f * length for f in fractions],
                            duration=args.duration, sampling_rate=args.sampling_rate, tests=args.test,
                            damping=args.damping, impulses=impulses, ambient=ambient, snr_db=args.snr,
                            effects=effect, seed=args.seed, overwrite=args.overwrite, field=field,
                            progress=lambda k, n: _progress(f"simulate: test {k} of {n}"))
    print(f"wrote {out}")
    return 0


def _field_conditions(args, campaign, n_channels: int):
    """``simulate``'s field-condition options as FieldConditions (per test with --field-random), or None."""
    import numpy as np

    from ..simulate import (
        DcOffsets,
        FieldConditions,
        LowPassLoading,
        MainsHum,
        PinkNoise,
        TensionDrift,
        random_field_conditions,
    )

    if args.field_random:
        rng = np.random.default_rng([args.seed, 17])
        return {t.name: random_field_conditions(rng, args.sampling_rate, args.duration, n_channels,
                                                ambient=args.ambient is not None) for t in campaign.tests}
    def drift(text):
        amplitude, _, period = text.partition("@")
        return TensionDrift(amplitude=float(amplitude), period=float(period) if period else 300.0)

    def hum(text):
        frequency, _, amplitudes = text.partition(":")
        return MainsHum(float(frequency), tuple(float(a) for a in amplitudes.split(",")), relative=True)

    builders = (("ambient_lowpass", "--lowpass", args.lowpass, LowPassLoading),
                ("drift", "--drift", args.drift, drift),
                ("pink_noise", "--pink-noise", args.pink_noise, lambda v: PinkNoise(v, relative=True)),
                ("hum", "--hum", args.hum, hum),
                ("dc_offsets", "--dc-offset", args.dc_offset, lambda v: DcOffsets(v, relative=True)))
    if args.lowpass is not None and args.ambient is None:
        raise InputError("colours the ambient loading: give --ambient too", field="--lowpass")
    parts = {}
    for key, flag, given, build in builders:
        if given is None:
            continue
        try:
            parts[key] = build(given)
        except ValueError as err:  # a number that does not parse, or a ModelError naming the condition's field
            raise InputError(" ".join(str(getattr(err, "message", err)).split()), field=flag) from None
    if args.float32:
        parts["float32"] = True
    return FieldConditions(**parts) if parts else None


def _selected_tests(campaign, names, file):
    known = [t.name for t in campaign.tests]
    for name in names or []:
        if name not in known:
            raise InputError(f"no test named {name!r} (known: {', '.join(known)})", field="--test", file=file)
    return names


def _check_output(path) -> None:
    """Refuse an output file whose directory does not exist, before any work."""
    if path in (None, "-"):
        return
    parent = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(parent):
        raise InputError(f"directory {parent} does not exist", field="--json", file=str(path))


def _write(path, text) -> None:
    from ..core.files import write_atomic

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
    from ..spectra.pipeline import analyse_campaign

    return analyse_campaign(campaign, tests, progress=_progress)


def _inputs(campaign, file: str) -> list[str]:
    """The files a command on ``campaign`` reads: its campaign file and every test's record."""
    from ..spectra.pipeline import record_path

    return [file] + [record_path(campaign, t) for t in campaign.tests if t.record is not None]


def _prepare(args):
    """Load the campaign and check the selection and the outputs before any work."""
    from ..core.files import check_outputs
    from ..io.campaign import campaign_file, load_campaign

    campaign = load_campaign(args.campaign)
    file = str(campaign_file(args.campaign))
    tests = _selected_tests(campaign, args.test, file)
    check_outputs([("--json", args.json, False), ("--plot", getattr(args, "plot", None), True),
                   ("--out", getattr(args, "out", None), True)], _inputs(campaign, file))
    _check_output(args.json)
    return campaign, file, tests


def _spectra(args) -> int:
    from ..report.forward import spectra_text, to_json

    campaign, file, tests = _prepare(args)
    results = _picked(campaign, tests, file)
    skipped = [t.name for t in campaign.tests if t.record is None and (not tests or t.name in tests)]
    if args.json:
        _write(args.json, to_json({"campaign": campaign.name, "tests": [r.summary() for r in results],
                                   "skipped": skipped}))
    if args.plot is not None:
        from ..report.plots import plot_test_spectra, save_figure

        os.makedirs(args.plot, exist_ok=True)
        for r in results:
            save_figure(plot_test_spectra(r)["figure"], os.path.join(args.plot, f"{r.name}.png"))
    if args.json != "-":
        sys.stdout.write(spectra_text(campaign.name, results, skipped))
    return 0


def _identify(args) -> int:
    import warnings

    from ..identify import identify
    from ..report.forward import to_json

    campaign, file, tests = _prepare(args)
    picked = {r.name: r for r in _picked(campaign, tests, file)}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = identify(campaign, tests, args.params, method=args.method, picked=picked,
                              tension_model=args.tension_model)
        except InputError as err:
            raise InputError(err.message, field=err.field, file=err.file or file) from None
    for w in caught:
        _show_warning(w.message, w.category, w.filename, w.lineno)
    from ..identify.published import published_comparison

    summary = result.summary()
    summary["published"] = published_comparison(campaign, summary)
    if args.json:
        _write(args.json, to_json(summary))
    if args.plot is not None:
        from ..report.identify_figures import save_identify_figures

        save_identify_figures(result, args.plot)
    if args.json != "-":
        from ..report.identify_tables import format_result

        sys.stdout.write(format_result(result, "text"))
        for item in summary["published"]:
            sys.stdout.write(f"\nPublished beside ours: {item['statement']}\n")
    return 0


def _diagnose(args) -> int:
    from ..diagnose import diagnose
    from ..report.forward import to_json

    campaign, file, tests = _prepare(args)
    picked = {r.name: r for r in _picked(campaign, tests, file)}
    try:
        result = diagnose(campaign, tests, effects=args.effects, picked=picked, max_effects=args.max_effects,
                          tension_model=args.tension_model, all_hypotheses=args.all_hypotheses,
                          progress=lambda k, n, label: _progress(f"diagnose: hypothesis {k} of {n} ({label})"))
    except InputError as err:
        raise InputError(err.message, field=err.field, file=err.file or file) from None
    if args.json:
        _write(args.json, to_json(result.summary()))
    if args.out is not None:
        from ..report.diagnose import write_report

        write_report(result, args.out)
    if args.json != "-":
        from ..report.diagnose import diagnosis_text

        sys.stdout.write(diagnosis_text(result))
        if args.out is not None:
            sys.stdout.write(f"report: {os.path.join(args.out, 'report.md')}\n")
    return 0


def _forward(args) -> int:
    from ..forward.compare import compare_forward
    from ..report.forward import forward_text, to_json

    campaign, file, tests = _prepare(args)
    picked = {r.name: (r.modes, r.frequencies) for r in _picked(campaign, tests, file)}
    result = compare_forward(campaign, tests, args.modes, args.tension_model, picked=picked)
    text = forward_text(result)
    if args.json:
        _write(args.json, to_json(result.summary()))
    if args.json != "-":
        sys.stdout.write(text)
    return 0


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one line on standard error: the toolkit's own as ``stcs-ident: warning: ...``; numerical
    ones from the libraries (overflow in a square, a division by zero on a dead channel) are internal and
    shown only with --debug."""
    if not issubclass(category, StcsWarning):
        return
    print(f"stcs-ident: warning: {one_line(str(message))}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not args.debug:
        with warnings.catch_warnings():
            warnings.simplefilter("default")  # whatever the caller's filters: a warning never aborts a command
            warnings.showwarning = _show_warning
            return _run(args)
    return _run(args)


def _as_option(err: InputError, command: str) -> InputError:
    """``err`` naming the command's option when its field is an argument the option gave (the library
    names its own argument: ``params``, ``duration``, ``effects.extra_mass``), in one place for every command."""
    field = err.field or ""
    hidden = {f"effects.{e.truth_key}": e.option.flag for e in effects.effects() if e.option is not None}
    option = {**hidden, "excitation": "--impulses"}.get(field, "--" + field.replace("_", "-"))
    if field and not field.startswith("--") and option in _OPTIONS.get(command, ()):
        return InputError(err.message, field=option, file=err.file)
    return err


def _run(args) -> int:
    try:
        return {"forward": _forward, "spectra": _spectra, "simulate": _simulate, "identify": _identify,
                "diagnose": _diagnose, "track": lambda a: run_track(a, _write)}[args.command](args)
    except InputError as err:
        if args.debug:
            traceback.print_exc()
        print(f"stcs-ident: {_as_option(err, args.command)}", file=sys.stderr)
        return 2
    except (ComputationError, FloatingPointError) as err:
        if args.debug:
            traceback.print_exc()
        print(f"stcs-ident: computation failed: {one_line(str(err))}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
