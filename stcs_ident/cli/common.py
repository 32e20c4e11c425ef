"""What the commands share: their parser's frame, the common options, the checks before any work, output.

Light on purpose (the standard library and :mod:`stcs_ident.core.errors`
at import): the rest of the toolkit is imported inside the functions
that need it, when a command runs.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
import time
from collections.abc import Callable

from ..core.errors import InputError, StcsWarning, one_line
from .commands import COMMANDS

TENSION_MODELS = ("uniform", "per-segment", "none")
TENSION_MODEL_HELP = ("additional tension from sag-extensibility: uniform (one for the whole cable, default), "
                      "per-segment (the source paper's form, for comparison) or none (a taut beam)")


def command_parser(sub, name: str, **options) -> argparse.ArgumentParser:
    """``sub.add_parser(name, ...)`` with the table's summary and its examples as the epilog."""
    command = COMMANDS[name]
    return sub.add_parser(name, help=command.summary, epilog=examples_epilog(command.examples),
                          formatter_class=argparse.RawDescriptionHelpFormatter, **options)


def examples_epilog(examples) -> str | None:
    """``example:`` (or ``examples:``) and one command line per line; None without examples."""
    examples = list(examples)
    if not examples:
        return None
    return "example" + ("s" if len(examples) > 1 else "") + ":\n" + "\n".join(f"  {e}" for e in examples)


def add_campaign_argument(parser: argparse.ArgumentParser) -> None:
    """The positional CAMPAIGN and the repeatable ``--test NAME``."""
    parser.add_argument("campaign", help="campaign directory or its campaign.toml")
    parser.add_argument("--test", action="append", metavar="NAME", help="only this test (repeatable)")


def add_json_option(parser: argparse.ArgumentParser) -> None:
    """``--json FILE``."""
    parser.add_argument("--json", metavar="FILE", help="write the JSON result ('-' for standard output)")


def add_tension_model_option(parser: argparse.ArgumentParser) -> None:
    """``--tension-model uniform|per-segment|none``."""
    parser.add_argument("--tension-model", choices=TENSION_MODELS, default="uniform", help=TENSION_MODEL_HELP)


def add_plausibility_option(parser: argparse.ArgumentParser) -> None:
    """``--no-plausibility-check``: fit even when the nominal model is implausibly far from the measurement."""
    parser.add_argument("--no-plausibility-check", dest="plausibility_check", action="store_false",
                        help="fit even when the nominal frequency of a test's lowest measured mode is more than "
                             "1.3 times off the measured one (refused by default: a unit slip, such as a tension "
                             "in kN or a mass per length in g/m)")


def worker_count(text: str) -> int:
    """``--workers``: a number of processes 1 … 1024 (argparse reports a refusal as a bad option)."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None
    if not 1 <= n <= 1024:
        raise argparse.ArgumentTypeError(f"must be 1 … 1024, got {n}")
    return n


def progress_line(message: str) -> None:
    """A progress line on standard error (control characters escaped)."""
    print(one_line(message), file=sys.stderr, flush=True)


def step_progress(command: str, unit: str) -> Callable[[int, int, str], None]:
    """Progress of ``total`` steps as ``progress(done, total, label)``: a tqdm bar with the time left on a
    terminal, else one line per step with the elapsed time and the time left (as ``track`` shows it)."""
    if sys.stderr.isatty():
        bar = []

        def on_bar(done: int, total: int, label: str) -> None:
            if not bar:
                from tqdm import tqdm

                bar.append(tqdm(total=total, unit=unit, file=sys.stderr, desc=command, dynamic_ncols=True))
            bar[0].set_postfix_str(one_line(label), refresh=False)
            bar[0].update(done - bar[0].n)
            if done == total:
                bar[0].close()
        return on_bar
    started = time.perf_counter()

    def on_line(done: int, total: int, label: str) -> None:
        elapsed = time.perf_counter() - started
        left = elapsed / done * (total - done) if done else float("nan")
        progress_line(f"{command}: {unit} {done} of {total} ({one_line(label)}), {elapsed:.0f} s, "
                      f"about {left:.0f} s left")
    return on_line


def selected_tests(campaign, names: list[str] | None, file: str) -> list[str] | None:
    """``--test`` names, each checked against the campaign's tests."""
    known = [t.name for t in campaign.tests]
    for name in names or []:
        if name not in known:
            raise InputError(f"no test named {name!r} (known: {', '.join(known)})", field="--test", file=file)
    return names


def check_output(path) -> None:
    """Refuse an output file whose directory does not exist, before any work."""
    if path in (None, "-"):
        return
    parent = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(parent):
        raise InputError(f"directory {parent} does not exist", field="--json", file=str(path))


def to_json(data) -> str:
    """``data`` as standard JSON: a value that is not a finite number (a σ the data cannot give, an error
    against a reference of 0) is written as null, never as NaN or Infinity, which JSON does not have."""
    return json.dumps(_finite_or_null(data), indent=2, allow_nan=False, default=_json_default) + "\n"


def _finite_or_null(value):
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite_or_null(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite_or_null(v) for v in value]
    if hasattr(value, "tolist") and not isinstance(value, str):
        return _finite_or_null(value.tolist())
    return value


def _json_default(value):
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def write_output(path, text: str) -> None:
    """The JSON result, whole or not at all (``-``: standard output; a symbolic link written through, a FIFO
    or a device as a stream: :mod:`stcs_ident.core.files`); a failure names ``--json`` and the path."""
    from ..core.errors import OutputError
    from ..core.files import write_atomic

    if str(path) == "-":  # JSON escapes its control characters itself; DEL, which it keeps, must stay valid JSON
        getattr(sys.stdout, "unescaped", sys.stdout).write(text)
        return
    try:
        write_atomic(path, text)
    except OutputError as err:
        raise OutputError(err.message, field="--json", file=str(path)) from err
    except OSError as err:
        raise OutputError(f"cannot write: {err.strerror or err}", field="--json", file=str(path)) from err


def os_error_line(err: OSError) -> str:
    """An operating-system error as one line naming its path(s): ``<path>: <what>``."""
    what = err.strerror or str(err) or type(err).__name__
    paths = [str(p) for p in (err.filename, err.filename2) if p is not None]
    return one_line(f"{' -> '.join(paths)}: {what}" if paths else what)


_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")  # C0 and C1 control characters but newline and tab


def printable(text: str) -> str:
    """``text`` with its control characters escaped (an escape sequence shown as ``\\x1b[31m``), lines and
    tabs kept: what a file names (a test, a cable) never reaches the terminal raw."""
    return _CONTROL.sub(lambda m: m[0].encode("unicode_escape").decode("ascii"), text)


class EscapedStream:
    """A text stream that writes through :func:`printable` to ``stream`` (the command line's standard output:
    tables and ``--json -``, whose JSON escapes control characters itself)."""

    def __init__(self, stream):
        self._stream = stream
        self.unescaped = stream  # for what must reach standard output as written (``--json -``)

    def write(self, text: str) -> int:
        self._stream.write(printable(text))
        return len(text)

    def __getattr__(self, name):
        return getattr(self._stream, name)


def campaign_inputs(campaign, file: str) -> list[str]:
    """The files a command on ``campaign`` reads: its campaign file and every test's record."""
    from ..io.test_record import record_path

    return [file] + [record_path(campaign, t) for t in campaign.tests if t.record is not None]


def prepare(args):
    """Load the campaign and check the selection and the outputs before any work.

    Returns
    -------
    campaign : Campaign
    file : str
        The campaign file, for messages.
    tests : list of str or None
        The ``--test`` selection.
    """
    from ..core.files import check_outputs
    from ..io.campaign import campaign_file, load_campaign

    campaign = load_campaign(args.campaign)
    file = str(campaign_file(args.campaign))
    tests = selected_tests(campaign, args.test, file)
    check_outputs([("--json", args.json, False), ("--plot", getattr(args, "plot", None), True),
                   ("--out", getattr(args, "out", None), True)], campaign_inputs(campaign, file))
    check_output(args.json)
    return campaign, file, tests


def picked_spectra(campaign, tests, file):
    """Spectra of the selected tests that have records (for forward, spectra, identify and diagnose)."""
    if not any(t.record is not None for t in campaign.tests if not tests or t.name in tests):
        return []
    from ..spectra.pipeline import analyse_campaign

    return analyse_campaign(campaign, tests, progress=progress_line)


def show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one line on standard error: the toolkit's own as ``stcs-ident: warning: ...``; numerical
    ones from the libraries (overflow in a square, a division by zero on a dead channel) are internal and
    shown only with --debug."""
    if not issubclass(category, StcsWarning):
        return
    print(f"stcs-ident: warning: {one_line(str(message))}", file=sys.stderr)
