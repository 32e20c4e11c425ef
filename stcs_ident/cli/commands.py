"""The table of ``stcs-ident`` commands: name → module, one-line summary and examples.

The table is plain data, so ``stcs-ident --help`` and ``--version`` list
the commands without importing any of them (nor numpy, scipy, pandas or
matplotlib); only the command being run is imported, by
:func:`importlib.import_module`. A command is one module with two
functions::

    def add_parser(sub: argparse._SubParsersAction) -> None: ...   # sub.add_parser(name, ...) and its options
    def run(args: argparse.Namespace) -> int: ...                  # the exit status

and one registration: a row of :data:`COMMANDS` for the built-in ones, or
:func:`register_command` from anywhere else (a plug-in, a test).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Command:
    """One command of the table.

    Parameters
    ----------
    module : str
        Importable name of the module with ``add_parser(sub)`` and ``run(args) -> int``.
    summary : str
        One line for ``stcs-ident --help`` (shown without importing the module).
    examples : tuple of str
        Real command lines; the first is shown by ``stcs-ident --help``, all of them by the command's own ``--help``.
    """

    module: str
    summary: str
    examples: tuple[str, ...] = ()


ARCHIVE_EXAMPLE = ("stcs-ident simulate campaigns/han2020 --out archive/ --archive 3 --cables 3 "
                   "--tension-change C2,2026-03-02T12:00:00+00:00,-0.015")
DAMPED_ARCHIVE_EXAMPLE = ("stcs-ident simulate campaigns/damped-stay --out archive/ --archive 7 --cables 3 "
                          "--sampling-rate 50 --duration 600 --damper-change C1,leak,2026-03-04T12:00:00+00:00,0.3 "
                          "--damper-change C3,loss,2026-03-02T00:00:00+00:00,0.5,3")

#: The commands, in the order ``--help`` lists them.
COMMANDS: dict[str, Command] = {
    "forward": Command("stcs_ident.cli.forward", "nominal model against measured and published frequencies",
                       ("stcs-ident forward campaigns/han2020 --test case1-L4 --modes 8",
                        "stcs-ident forward campaigns/han2020 --test case1-L4 --plane both --json forward.json")),
    "spectra": Command("stcs_ident.cli.spectra", "numbered modal frequencies picked from the acceleration records",
                       ("stcs-ident spectra campaigns/hanger-hidden-mass --json picked.json --plot spectra/",)),
    "simulate": Command("stcs_ident.cli.simulate",
                        "simulated records of a campaign's tests, with optional hidden effects",
                        ("stcs-ident simulate campaigns/han2020 --out sim/ --test case1-L4 --extra-mass 5@6.0 --seed 1",
                         ("stcs-ident simulate campaigns/han2020 --out sim3d/ --test case1-L4 --ambient 2 --triaxial "
                          "--deck-modes 1.9:0.05 --traffic 60:0.02 --misalignment 3"),
                         ARCHIVE_EXAMPLE, DAMPED_ARCHIVE_EXAMPLE)),
    "identify": Command("stcs_ident.cli.identify",
                        "correct tension, EI, attachment positions... from measured frequencies",
                        (("stcs-ident identify campaigns/han2020 --test case1-L4 --params tension,EI "
                          "--method contour --plot figures/"),)),
    "tension": Command("stcs_ident.cli.tension", "the quick answer: tension from a length, a mass and frequencies "
                       "or one record",
                       ("stcs-ident tension --length 19.715 --mass 16.6 --frequencies 7.24,14.42,21.77 --EA 4.1382e8",
                        ("stcs-ident tension --record campaigns/hanger-hidden-mass/records/T1.h5 --length 8 --mass 30 "
                         "--EI 2e5"))),
    "diagnose": Command("stcs_ident.cli.diagnose",
                        "what the model gets wrong, its cause among physical effects, and the gain",
                        ("stcs-ident diagnose campaigns/han2020 --out report/",)),
    "track": Command("stcs_ident.cli.track", "an archive of field records into tension histories, with lasting changes",
                     ("stcs-ident track archive/ --out histories/ --workers 2",)),
}


def register_command(name: str, module: str, summary: str, examples: tuple[str, ...] | list[str] = ()) -> None:
    """Add a command to :data:`COMMANDS` (listed last by ``--help``).

    Parameters
    ----------
    name : str
        The command word, ``stcs-ident NAME ...``.
    module : str
        Importable module name with ``add_parser(sub)`` and ``run(args) -> int``; imported only when the
        command is run or its help is asked for.
    summary : str
        One line for ``stcs-ident --help``.
    examples : sequence of str
        Real command lines, shown in the help.

    Raises
    ------
    ValueError
        If ``name`` is taken or is not a single word that cannot be mistaken for an option.
    """
    if name in COMMANDS:
        raise ValueError(f"command {name!r} is already registered (by {COMMANDS[name].module})")
    if not name or name.startswith("-") or name.split() != [name]:
        raise ValueError(f"a command name is one word not starting with '-', got {name!r}")
    COMMANDS[name] = Command(module, summary, tuple(examples))


def unregister_command(name: str) -> None:
    """Remove a command added by :func:`register_command` (a built-in one too).

    Raises
    ------
    KeyError
        If no command is called ``name``.
    """
    del COMMANDS[name]
