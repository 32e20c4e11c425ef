"""The table of commands: only the command run is imported, and a new command is one module plus one line.

This file is itself the module of a toy command, ``stcs-ident tests``
(``add_parser`` and ``run`` below), registered by the ``toy`` fixture
alone: nothing in the package names it.
"""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from stcs_ident.cli import register_command, unregister_command
from stcs_ident.cli.commands import COMMANDS
from stcs_ident.cli.common import add_json_option, command_parser, write_output
from stcs_ident.cli.main import build_parser, main

HAN = Path(__file__).resolve().parents[1] / "campaigns" / "han2020"
HEAVY = ("numpy", "scipy", "pandas", "matplotlib", "h5py", "pyarrow", "tqdm")
TOY_EXAMPLE = "stcs-ident tests campaigns/han2020 --setup case2"


def add_parser(sub) -> None:
    """The toy command's options."""
    parser = command_parser(sub, "tests")
    parser.add_argument("campaign", help="campaign directory or its campaign.toml")
    parser.add_argument("--setup", metavar="NAME", help="only the tests of this setup")
    add_json_option(parser)


def run(args) -> int:
    """Print (or write as JSON) the names of a campaign's tests."""
    from stcs_ident.core.errors import InputError
    from stcs_ident.io.campaign import load_campaign

    campaign = load_campaign(args.campaign)
    if args.setup is not None and args.setup not in {s.name for s in campaign.setups}:
        raise InputError(f"no setup named {args.setup!r}", field="setup")  # shown as the option that gave it
    names = [t.name for t in campaign.tests if args.setup in (None, t.setup)]
    if args.json:
        write_output(args.json, json.dumps({"tests": names}))
    else:
        print("\n".join(names))
    return 0


@pytest.fixture
def toy():
    register_command("tests", __name__, "the names of a campaign's tests", [TOY_EXAMPLE])
    yield COMMANDS["tests"]
    unregister_command("tests")


def test_a_toy_command_registered_from_a_test_file_runs_and_is_listed(toy, capsys):
    assert main(["tests", str(HAN), "--setup", "case2"]) == 0
    names = capsys.readouterr().out.split()
    assert names and all(n.startswith("case2-") for n in names)
    assert main(["tests", str(HAN), "--json", "-"]) == 0
    assert "case1-L4" in json.loads(capsys.readouterr().out)["tests"]
    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    assert "the names of a campaign's tests" in text and TOY_EXAMPLE in text
    assert TOY_EXAMPLE in build_parser()._subparsers._group_actions[0].choices["tests"].format_help()


def test_a_toy_command_gets_the_common_exit_statuses_and_messages(toy, capsys):
    assert main(["tests", str(HAN), "--setup", "case9"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "option '--setup'" in err and "case9" in err
    assert main(["tests", str(HAN / "missing")]) == 2
    assert "missing" in capsys.readouterr().err
    assert main(["tests", "--debug", str(HAN / "missing")]) == 2  # --debug after the command, as for every command
    assert "Traceback" in capsys.readouterr().err


def test_a_removed_command_is_gone_and_a_taken_name_is_refused(capsys):
    register_command("tests", __name__, "the names of a campaign's tests")
    with pytest.raises(ValueError, match="already registered"):
        register_command("tests", __name__, "again")
    unregister_command("tests")
    with pytest.raises(SystemExit) as exit_:
        main(["tests", str(HAN)])
    assert exit_.value.code == 2 and "invalid choice: 'tests'" in capsys.readouterr().err
    with pytest.raises(ValueError, match="one word"):
        register_command("--tests", __name__, "an option, not a command")


def _modules_after(argv: list[str]) -> set[str]:
    """The modules a fresh interpreter holds after ``main(argv)`` (which exits, as --help and --version do)."""
    code = ("import sys\nfrom stcs_ident.cli.main import main\ntry:\n    main(sys.argv[1:])\nexcept SystemExit:\n"
            "    pass\nprint('\\n'.join(sys.modules), file=sys.stderr)")
    done = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, check=True)
    return set(done.stderr.split())


@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["-h"], ["--debug", "--help"]])
def test_version_and_help_import_no_command_and_no_numerics(argv):
    modules = _modules_after(argv)
    assert not {m.split(".")[0] for m in modules} & set(HEAVY), sorted(m for m in modules if m in HEAVY)
    assert not {c.module for c in COMMANDS.values()} & modules


def test_a_command_imports_its_own_module_only():
    modules = _modules_after(["forward", "--help"])
    assert "stcs_ident.cli.forward" in modules
    assert not {c.module for name, c in COMMANDS.items() if name != "forward"} & modules
