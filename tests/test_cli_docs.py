"""Every command and option of the command line appears in the user documentation.

docs/formats.md has the command table and a section per command that
names each option (``track``'s section sends the reader to docs/track.md,
whose options table then counts); the README's Commands section has a
synopsis per command naming all of its options.
"""

import re
from pathlib import Path

import pytest

from stcs_ident.cli.commands import COMMANDS
from stcs_ident.cli.main import build_parser

ROOT = Path(__file__).resolve().parents[1]
FORMATS = ROOT / "docs" / "formats.md"
#: Commands whose section in docs/formats.md defers to a page of their own.
OWN_PAGE = {"track": "track.md"}
BUILT_IN = [name for name, c in COMMANDS.items() if c.module.startswith("stcs_ident.cli.")]


def _options(command: str) -> list[str]:
    """The long options of ``command`` a user may type (not --help, not the hidden --debug)."""
    parser = build_parser([command])._subparsers._group_actions[0].choices[command]
    return [o for action in parser._actions if action.help != "==SUPPRESS==" and action.option_strings
            for o in action.option_strings if o.startswith("--") and o != "--help"]


def _section(text: str, heading: str) -> str:
    """The text under ``heading`` up to the next heading of the same or a higher level."""
    level = len(heading) - len(heading.lstrip("#"))
    start = text.index(heading + "\n")
    end = re.search(rf"^#{{1,{level}}} ", text[start + len(heading):], flags=re.MULTILINE)
    return text[start:start + len(heading) + end.start()] if end else text[start:]


def _mentions(text: str, option: str) -> bool:
    return re.search(rf"(?<![\w-]){re.escape(option)}(?![\w-])", text) is not None


def _formats_section(command: str) -> str:
    """The command's section of docs/formats.md, with its own page if it has one."""
    section = _section(FORMATS.read_text(encoding="utf-8"), f"### `{command}`")
    if command in OWN_PAGE:
        assert f"]({OWN_PAGE[command]})" in section, f"the section `{command}` should link {OWN_PAGE[command]}"
        section += (FORMATS.parent / OWN_PAGE[command]).read_text(encoding="utf-8")
    return section


def test_the_command_table_of_the_docs_lists_every_command():
    table = _section(FORMATS.read_text(encoding="utf-8"), "## Command line")
    for name in BUILT_IN:
        assert f"| `{name}` |" in table, f"docs/formats.md: `{name}` missing from the command table"


@pytest.mark.parametrize("command", BUILT_IN)
def test_every_option_is_documented_in_the_commands_section(command):
    section = _formats_section(command)
    missing = [o for o in _options(command) if not _mentions(section, o)]
    assert not missing, f"docs/formats.md, section `{command}`: {missing} not described"


@pytest.mark.parametrize("command", BUILT_IN)
def test_the_readme_synopsis_names_every_option(command):
    section = _section((ROOT / "README.md").read_text(encoding="utf-8"), "## Commands")
    lines = section.splitlines()
    start = next(i for i, line in enumerate(lines) if line.strip().startswith(f"stcs-ident {command} "))
    synopsis = lines[start]
    for line in lines[start + 1:]:  # continuation lines of the synopsis: indented, no new command
        if not line.startswith("    ") or line.strip().startswith("stcs-ident "):
            break
        synopsis += line
    missing = [o for o in _options(command) if not _mentions(synopsis, o)]
    assert not missing, f"README, synopsis of `{command}`: {missing} missing"


def test_a_missing_option_would_be_seen():
    """The checks can fail: an option the docs do not name is not mentioned (nor a longer one's prefix)."""
    section = _formats_section("forward")
    assert not _mentions(section, "--no-such-option")
    assert _mentions("[--modes N]", "--modes") and not _mentions("[--modes-of N]", "--modes")
