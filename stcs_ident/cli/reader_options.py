"""The reader options of a record given on the command line (``tension --record FILE``, ``spectra FILE``).

Each is the ``record_format`` key of its name (``--header-row`` is ``header_row``), read into a
:class:`~stcs_ident.io.test_record.RecordReading`; a message of the readers that names a ``record_format`` key
as the fix is said with the option instead (:func:`as_options`), so that the user is told what to type.
"""

from __future__ import annotations

import argparse
import re

from ..core.errors import InputError

__all__ = ["READER_OPTIONS", "add_reader_options", "as_options", "reading_from_args"]

#: (option, metavar, help) of every reader option.
READER_OPTIONS = (
    ("--sampling-rate", "HZ", "Hz, where the file has none (or with --override-sampling-rate)"),
    ("--unit", "UNIT", "m/s^2, g, mg, mm/s^2 (default: the file's, else m/s^2)"),
    ("--channels", "NAME[=POS],...", ("the acceleration channels to use (a text file's other columns ignored); "
                                      "positions (m from end A) optional")),
    ("--directions", "NAME=DIR,...", "channel directions: in, out, axial or degrees (default: the file's, else in)"),
    ("--time-column", "NAME", "a text file's time column (default time)"),
    ("--separator", "CHAR", "a text file's column separator (default ,)"),
    ("--decimal", "CHAR", "a text file's decimal mark (default .)"),
    ("--header-row", "N", "a text file's header line, 0-based (default: found after any preamble)"),
    ("--skip-rows", "N,...", "a text file's lines after the header to skip (a units row: 1)"),
    ("--variable", "NAME", "a MATLAB file's matrix (rec.acc for a struct's field)"),
    ("--group", "NAME", "a TDMS file's group"),
)


def add_reader_options(parser: argparse.ArgumentParser, record: str) -> None:
    """The reader options, in a group saying they read ``record`` (``"--record"``, ``"a RECORD file"``)."""
    group = parser.add_argument_group(f"reading {record} (as a campaign's record_format)")
    for option, metavar, text in READER_OPTIONS:
        group.add_argument(option, metavar=metavar, help=text)
    group.add_argument("--override-sampling-rate", action="store_true",
                       help="use --sampling-rate even where the file's own rate disagrees")


def _given(args: argparse.Namespace) -> list[str]:
    given = [o for o, _, _ in READER_OPTIONS if getattr(args, o[2:].replace("-", "_")) is not None]
    return given + (["--override-sampling-rate"] if args.override_sampling_rate else [])


def reading_from_args(args: argparse.Namespace, has_record: bool, record: str):
    """The :class:`~stcs_ident.io.test_record.RecordReading` of the reader options given (None without a
    record); a reader option given without a record is refused naming it and ``record``."""
    given = _given(args)
    if not has_record:
        if given:
            raise InputError(f"is a reader option: it goes with {record}", field=given[0])
        return None
    from ..io.test_record import RecordReading  # the readers (pandas) only where there is a record

    options, positions, directions = {}, {}, {}
    for option in given:
        key = option[2:].replace("-", "_")
        value = getattr(args, key)
        if key == "sampling_rate":
            options[key] = _number(value, option)
        elif key == "override_sampling_rate":
            options[key] = True
        elif key in ("header_row", "skip_rows"):
            numbers = _integers(value, option)
            options[key] = numbers[0] if key == "header_row" else numbers
        elif key == "channels":
            names = []
            for item in value.split(","):
                name, _, where = item.partition("=")
                names.append(name.strip())
                if where:
                    positions[name.strip()] = _number(where, option)
            options[key] = names
        elif key == "directions":
            for item in value.split(","):
                name, _, where = item.partition("=")
                if not where:
                    raise InputError(f"must be NAME=DIR pairs, got {item!r}", field=option)
                try:
                    directions[name.strip()] = float(where)
                except ValueError:
                    directions[name.strip()] = where.strip()
        else:
            options[key] = value
    return RecordReading(positions=positions or None, options=options, directions=directions or None)


_KEY = re.compile(r"\b(?P<verb>give |remove |with )?(?P<key>"
                  + "|".join(o[2:].replace("-", "_") for o, _, _ in READER_OPTIONS) + r"|override_sampling_rate)"
                  + r"( = (?P<value>\[[^\]]*\]|\"[^\"]*\"|'[^']*'|<[^>]*>|[^\s,;)]+))?(?P<where> in record_format)?")


def as_options(err: InputError) -> InputError:
    """``err`` with each ``record_format`` key it names as a fix said as its command-line option
    (``give header_row = 3 in record_format`` → ``give --header-row 3``)."""
    def option(match: re.Match) -> str:
        verb, key, value = match.group("verb") or "", match.group("key"), match.group("value")
        if not verb and not match.group("where"):  # a word of the prose, not a key named as a fix
            return match.group(0)
        flag = "--" + key.replace("_", "-")
        if key == "override_sampling_rate":
            return f"{verb}{flag}"
        if value is None:
            return f"{verb}{flag}"
        return f"{verb}{flag} {value.strip(chr(34) + chr(39)).strip('[]')}"

    message = re.sub(r"record_format gives (\w+)", lambda m: "--" + m.group(1).replace("_", "-") + " gives",
                     err.message)
    return InputError(_KEY.sub(option, message), field=err.field, file=err.file)


def _number(text: str, option: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise InputError(f"must be a number, got {text!r}", field=option) from None


def _integers(text: str, option: str) -> list[int]:
    try:
        return [int(t) for t in text.split(",")]
    except ValueError:
        raise InputError(f"must be comma-separated integers, got {text!r}", field=option) from None
