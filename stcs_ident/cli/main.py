"""The ``stcs-ident`` command line: the top-level parser, and running one command of the table.

Exit status 0 on success, 2 for bad input (one line on standard error
naming the file, the field and what is wrong; nothing written) and for an
output that cannot be written as given (read-only, full disk, gone: one
line naming the path), 1 for a computation that failed, 130 for Ctrl-C
(one line; the outputs already written whole are kept). ``--debug`` shows
the traceback. Control characters in what the commands print (a test's
name holding an escape sequence) are shown escaped, never sent raw to the
terminal.

Only the command being run is imported (:mod:`stcs_ident.cli.commands`),
so ``--version`` and ``--help`` answer without loading the numerics.
"""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
import threading
import traceback
import warnings
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from types import ModuleType

from ..core.errors import ComputationError, InputError, one_line
from ..core.version import __version__
from .commands import COMMANDS, Command, register_command, unregister_command
from .common import EscapedStream, examples_epilog, os_error_line, show_warning

__all__ = ["COMMANDS", "DESCRIPTION", "EXAMPLES", "Command", "build_parser", "main", "register_command",
           "unregister_command"]

DESCRIPTION = """\
stcs-ident: cable force, bending stiffness and model diagnosis from the
vibration records of stay cables, hangers and suspension cables (exact
dynamic-stiffness model of a tensioned, sagging cable with attachments)."""


class _Examples(Mapping):
    """``{command: its first example}``, read from :data:`COMMANDS` each time (registered commands included)."""

    def _view(self) -> dict[str, str]:
        return {name: c.examples[0] for name, c in COMMANDS.items() if c.examples}

    def __getitem__(self, name: str) -> str:
        return self._view()[name]

    def __iter__(self):
        return iter(self._view())

    def __len__(self) -> int:
        return len(self._view())


#: One real example per command (the shipped campaigns), shown in --help.
EXAMPLES: Mapping[str, str] = _Examples()


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


def command_module(name: str) -> ModuleType:
    """The module of command ``name``, imported now (the first time it is needed)."""
    return importlib.import_module(COMMANDS[name].module)


def build_parser(commands: Iterable[str] | None = None) -> argparse.ArgumentParser:
    """The argument parser of ``stcs-ident``.

    Parameters
    ----------
    commands : iterable of str, optional
        Commands whose options are built (their modules imported); the others are listed by name and
        summary only. Default: all of :data:`COMMANDS`.
    """
    full = set(COMMANDS) if commands is None else set(commands)
    first_examples = [c.examples[0] for c in COMMANDS.values() if c.examples]
    parser = _Parser(prog="stcs-ident", description=DESCRIPTION, epilog=examples_epilog(first_examples),
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"stcs-ident {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, command in COMMANDS.items():
        if name in full:
            command_module(name).add_parser(sub)
            if name not in sub.choices:
                raise RuntimeError(f"{command.module}.add_parser did not add the command {name!r}")
            sub.choices[name].add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                                           help=argparse.SUPPRESS)
        else:  # listed, not built: its module is not imported
            sub.add_parser(name, help=command.summary)
    return parser


def _command_in(argv: list[str]) -> str | None:
    """The command word of ``argv`` (the top-level options take no value, so it is the first non-option)."""
    word = next((a for a in argv if not a.startswith("-")), None)
    return word if word in COMMANDS else None


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    command = _command_in(argv)
    try:
        parser = build_parser([command] if command else [])
        args = parser.parse_args(argv)
    except KeyboardInterrupt:
        return _interrupted()
    stdout = sys.stdout
    sys.stdout = EscapedStream(stdout)  # names from files reach the terminal escaped (one place for every command)
    with _ctrl_c() as pressed:
        try:
            if not args.debug:
                with warnings.catch_warnings():
                    warnings.simplefilter("default")  # whatever the caller's filters: a warning never aborts
                    warnings.showwarning = show_warning
                    status = _run(args, parser)
            else:
                status = _run(args, parser)
        finally:
            sys.stdout = stdout
    # A KeyboardInterrupt raised while Python ran a finaliser (__del__) is printed as "ignored" and lost: the
    # command then ends normally, but Ctrl-C was pressed, and it is said so.
    return _interrupted() if pressed and status != 130 else status


@contextmanager
def _ctrl_c() -> Iterator[list]:
    """While a command runs, Ctrl-C raises KeyboardInterrupt as usual and is also noted in the list yielded
    (in the main thread, with Python's own handler in place; elsewhere the list stays empty)."""
    pressed: list = []
    if threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        yield pressed
        return

    def handler(signum, frame):
        pressed.append(signum)
        raise KeyboardInterrupt

    previous = sys.unraisablehook

    def unraisable(info):
        # Ctrl-C landing while Python runs a finaliser or a weakref callback is "ignored": Python would print
        # its traceback ("Exception ignored in: <function WeakValueDictionary...remove>") beside the one line
        # the interruption gets (tests/test_outputs.py's Ctrl-C test saw it under load). It is noted in
        # ``pressed`` by the handler already, and said once by main().
        if not issubclass(info.exc_type, KeyboardInterrupt):
            previous(info)

    signal.signal(signal.SIGINT, handler)
    sys.unraisablehook = unraisable
    try:
        yield pressed
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        sys.unraisablehook = previous


def _as_option(err: InputError, command: str, parser: argparse.ArgumentParser,
               args: argparse.Namespace | None = None) -> InputError:
    """``err`` naming the command's option when its field is an argument the option gave (the library
    names its own argument: ``params``, ``duration``, ``effects.extra_mass``), in one place for every command;
    a command module may map other fields with ``field_options() -> {field: option}``. An option the user did
    not give (its value the default in ``args``) is never named: the field stays the library's."""
    field = err.field or ""
    if not field or field.startswith("--"):
        return err
    module = command_module(command)
    aliases = module.field_options() if hasattr(module, "field_options") else {}
    option = aliases.get(field, "--" + field.replace("_", "-"))
    actions = {o: action for action in parser._subparsers._group_actions[0].choices[command]._actions
               for o in action.option_strings}
    action = actions.get(option)
    if action is None or (args is not None and getattr(args, action.dest, action.default) == action.default):
        return err
    return InputError(err.message, field=option, file=err.file)


def _run(args: argparse.Namespace, parser: argparse.ArgumentParser) -> int:
    try:
        return command_module(args.command).run(args)
    except InputError as err:
        if args.debug:
            traceback.print_exc()
        print(f"stcs-ident: {_as_option(err, args.command, parser, args)}", file=sys.stderr)
        return 2
    except (ComputationError, FloatingPointError) as err:
        if args.debug:
            traceback.print_exc()
        print(f"stcs-ident: computation failed: {one_line(str(err))}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        if args.debug:
            traceback.print_exc()
        return _interrupted()
    except OSError as err:  # what no writer named (a directory made for --plot, standard output closed): one line
        if args.debug:
            traceback.print_exc()
        print(f"stcs-ident: {os_error_line(err)}", file=sys.stderr)
        return 2


def _interrupted() -> int:
    """Ctrl-C: one line, exit status 130 (128 + SIGINT, as a shell reports it)."""
    print("stcs-ident: interrupted (Ctrl-C); the outputs already written whole are kept", file=sys.stderr)
    return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
