"""Read campaign files (``campaign.toml``).

:func:`load_campaign` parses a campaign file as docs/formats.md describes
it and builds the frozen model objects of :mod:`stcs_ident.core.model`;
:func:`campaign_to_toml` (:mod:`stcs_ident.io.campaign_toml`) writes a
campaign back in the same format. Units other than SI live only here: the file gives the
inclination in degrees, the model holds radians.

Every problem with the file raises :class:`~stcs_ident.core.errors.CampaignError`
whose text is one line, ``"<file>: field '<field>': <what is wrong>"``.
Fields are named in dotted form: ``cable.length``, ``campaign.name``,
``setup[case2].attachment[W1].position``, ``test[case1-L4].tension``. An
item whose name is missing or invalid is named by its 1-based place in the
file instead, ``setup[#2].name``; a key outside any table by itself.
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from pathlib import Path
from typing import Any

from ..core import kinds
from ..core.errors import CampaignError, ModelError
from ..core.model import Attachment, Boundary, Cable, Campaign, Damper, Published, Setup, Test
from ..core.planes import check_direction
from .campaign_toml import campaign_to_toml
from .records.options import option_problem, option_value

__all__ = ["CAMPAIGN_FILE", "campaign_to_toml", "load_campaign"]

#: Name of the campaign file inside a campaign directory.
CAMPAIGN_FILE = "campaign.toml"

_TOP_KEYS = ("campaign", "cable", "setup", "test", "published", "tolerance", "record_format", "channels",
             "bounds", "structure")
_PUBLISHED_KEYS = ("parameter", "low", "high", "basis", "source")
_CAMPAIGN_KEYS = ("name", "description")
_CABLE_KEYS = ("length", "mass_per_length", "EI", "EA", "inclination", "gravity", "boundary")
_SETUP_KEYS = ("name", "attachment", "damper")
_ATTACHMENT_KEYS = ("name", "position", "mass", "stiffness", "stiffness_out", "damping")
_DAMPER_KEYS = ("name", "position", "coefficient", "stiffness", "mass", "angle")
_TEST_KEYS = ("name", "setup", "tension", "frequencies", "modes", "record", "reference", "channels", "uncertainty",
              "record_format", "planes")
_CHANNEL_KEYS = ("position", "direction")

_BOUNDARY_HELP = '"clamped", "pinned" or a rotational stiffness >= 0 N m/rad'


# --------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------


def load_campaign(path: str | os.PathLike) -> Campaign:
    """Read a campaign from its directory or from its TOML file.

    Parameters
    ----------
    path : str or path-like
        A campaign directory holding ``campaign.toml``, or the TOML file
        itself (its directory is then the campaign directory).

    Returns
    -------
    Campaign
        The validated campaign; ``directory`` is the absolute campaign
        directory, against which a test's ``record`` path is resolved.

    Raises
    ------
    CampaignError
        If the file is missing, unreadable or not TOML, or if a key is
        unknown, a field missing, mistyped, out of range or inconsistent.
        The error carries ``.file`` and ``.field``.
    """
    file = _campaign_file(Path(path))
    data = _read_toml(file)
    try:
        return _parse_campaign(data, directory=str(file.parent.absolute()))
    except CampaignError as err:
        raise err.with_file(str(file)) from err
    except ModelError as err:
        raise CampaignError(err.message, field=err.field, file=str(file)) from err


def campaign_file(path: str | os.PathLike) -> Path:
    """The campaign's TOML file, given its directory or the file itself."""
    return _campaign_file(Path(path))


def _campaign_file(path: Path) -> Path:
    """The TOML file named by ``path`` (a campaign directory or the file)."""
    if "\0" in str(path):
        raise CampaignError("holds a NUL character, which no path can", file=str(path))
    if path.is_dir():
        file = path / CAMPAIGN_FILE
        if not file.is_file():
            raise CampaignError(f"no {CAMPAIGN_FILE} in the campaign directory", file=str(file))
        return file
    return path


def _read_toml(file: Path) -> dict[str, Any]:
    """Parse ``file`` as TOML; any failure names the file."""
    try:
        with open(file, "rb") as stream:
            return tomllib.load(stream)
    except FileNotFoundError:
        raise CampaignError("file not found", file=str(file)) from None
    except OSError as err:
        raise CampaignError(f"cannot read the file: {err.strerror or err}", file=str(file)) from err
    except UnicodeDecodeError as err:
        raise CampaignError(f"not a TOML file: not UTF-8 text ({err.reason})", file=str(file)) from err
    except tomllib.TOMLDecodeError as err:
        raise CampaignError(f"not a valid TOML file: {_one_line(err)}", file=str(file)) from err
    except RecursionError:
        raise CampaignError("not a valid TOML file: arrays or tables nested too deeply", file=str(file)) from None
    except ValueError as err:  # an integer literal beyond Python's digit limit, and the like
        raise CampaignError(f"not a valid TOML file: {_one_line(err)}", file=str(file)) from None


def _parse_campaign(data: dict[str, Any], directory: str) -> Campaign:
    """Build the campaign from the parsed TOML document."""
    _check_keys(data, _TOP_KEYS, where="")
    head = _table(_required(data, "campaign", ""), "campaign")
    _check_keys(head, _CAMPAIGN_KEYS, "campaign")
    name = _string(_required(head, "name", "campaign"), "campaign.name")
    description = _string(head.get("description", ""), "campaign.description", empty_ok=True)
    cable = _parse_cable(_table(_required(data, "cable", ""), "cable"))
    found = _tables(data.get("setup", []), "setup")
    setups = [_parse_setup(t, i, cable.length) for i, t in enumerate(found, 1)]
    tests = [_parse_test(t, i) for i, t in enumerate(_tables(data.get("test", []), "test"), 1)]
    published = [_parse_published(t, i) for i, t in enumerate(_tables(data.get("published", []), "published"), 1)]
    tolerance = _parse_tolerance(_table(data.get("tolerance", {}), "tolerance"))
    bounds = _parse_bounds(_table(data.get("bounds", {}), "bounds"))
    channels, directions = _parse_channels(data.get("channels", {}), "channels")
    structure = _table(data.get("structure", {}), "structure")
    _check_keys(structure, ("frequencies",), "structure")
    structural = _numbers(structure.get("frequencies", []), "structure.frequencies")
    return Campaign(name, cable, tuple(setups), tuple(tests), description, directory, tuple(published), tolerance,
                    bounds=bounds, record_format=_parse_record_format(data.get("record_format", {}), "record_format"),
                    channels=channels, channel_directions=directions, structural_frequencies=structural)


def _parse_bounds(table: dict[str, Any]) -> dict[str, Any]:
    """``[bounds]``: default bounds of the identification's variables, by parameter kind (``tension =
    [0.2, 5.0]``, ratios to nominal; see docs/formats.md). The keys are checked here; the values by
    :class:`~stcs_ident.core.model.Campaign` (whose ModelError :func:`load_campaign` names with the file)."""
    _check_keys(table, kinds.names(), "bounds")
    return table


def _parse_tolerance(table: dict[str, Any]) -> tuple[tuple[str, float], ...]:
    """``[tolerance]``: how well the nominal values are known, by the parameter kinds' keys."""
    _check_keys(table, kinds.tolerance_keys(), "tolerance")
    out = []
    for key, value in table.items():
        v = _number(value, f"tolerance.{key}")
        if not math.isfinite(v) or v < 0:
            raise CampaignError(f"must be a finite number >= 0, got {_show(value)}", field=f"tolerance.{key}")
        out.append((key, float(v)))
    return tuple(out)


def _parse_published(table: dict[str, Any], index: int) -> Published:
    """Build one ``[[published]]``: a result published elsewhere, shown beside ours."""
    where = f"published[#{index}]"
    _check_keys(table, _PUBLISHED_KEYS, where)
    basis = table.get("basis")
    return Published(
        parameter=_string(_required(table, "parameter", where), f"{where}.parameter"),
        low=_number(_required(table, "low", where), f"{where}.low"),
        high=_number(table.get("high", table.get("low")), f"{where}.high"),
        basis=None if basis is None else _number(basis, f"{where}.basis"),
        source=_string(table.get("source", ""), f"{where}.source", empty_ok=True),
    )


def _parse_cable(table: dict[str, Any]) -> Cable:
    """Build the cable from the ``[cable]`` table (inclination in degrees)."""
    _check_keys(table, _CABLE_KEYS, "cable")
    EA = table.get("EA")
    boundary_a, boundary_b = _parse_boundary(table.get("boundary", "clamped"))
    return Cable(
        length=_number(_required(table, "length", "cable"), "cable.length"),
        mass_per_length=_number(_required(table, "mass_per_length", "cable"), "cable.mass_per_length"),
        EI=_number(_required(table, "EI", "cable"), "cable.EI"),
        EA=None if EA is None else _number(EA, "cable.EA"),
        inclination=math.radians(_inclination(table.get("inclination", 0.0))),
        gravity=_number(table.get("gravity", 9.81), "cable.gravity"),
        boundary_a=boundary_a,
        boundary_b=boundary_b,
    )


def _inclination(value: Any) -> float:
    """Check the chord angle in degrees, |value| <= 90 (±90: a vertical cable, a hanger)."""
    degrees = _number(value, "cable.inclination")
    if not abs(degrees) <= 90:
        raise CampaignError(
            f"must satisfy |inclination| <= 90 degrees, got {value!r}", field="cable.inclination"
        )
    return degrees


def _parse_boundary(value: Any) -> tuple[Boundary, Boundary]:
    """Boundaries at ends A and B from one value or a list ``[A, B]``."""
    if isinstance(value, list):
        if len(value) != 2:
            raise CampaignError(
                f"must be {_BOUNDARY_HELP}, or a list [A, B] of two such values; got a list of {len(value)}",
                field="cable.boundary",
            )
        return _boundary_end(value[0], "end A: "), _boundary_end(value[1], "end B: ")
    end = _boundary_end(value, "")
    return end, end


def _boundary_end(value: Any, which: str) -> Boundary:
    """One end's boundary: ``"clamped"``, ``"pinned"`` or a stiffness >= 0."""
    if value == "clamped" and isinstance(value, str):
        return Boundary.clamped()
    if value == "pinned" and isinstance(value, str):
        return Boundary.pinned()
    if _is_number(value) and value >= 0:
        try:
            _in_float_range(value, "cable.boundary")
        except CampaignError as err:
            raise CampaignError(which + err.message, field=err.field) from None
        return Boundary(value)
    raise CampaignError(f"{which}must be {_BOUNDARY_HELP}, got {_show(value)}", field="cable.boundary")


def _parse_setup(table: dict[str, Any], index: int, length: float) -> Setup:
    """Build one ``[[setup]]`` with its attachments on a span of ``length`` m."""
    name = _item_name(table, "setup", index)
    where = f"setup[{name}]"
    _check_keys(table, _SETUP_KEYS, where)
    points = []
    for noun, keys in (("attachment", _ATTACHMENT_KEYS), ("damper", _DAMPER_KEYS)):
        kind = f"{where}.{noun}"
        found = _tables(table.get(noun, []), kind)
        points += [_parse_point(t, i, kind, keys, length) for i, t in enumerate(found, 1)]
    try:
        return Setup(name, tuple(points))
    except ModelError as err:
        raise CampaignError(err.message, field=err.field) from err


def _parse_point(table: dict[str, Any], index: int, kind: str, keys, length: float) -> Attachment:
    """Build one ``[[setup.attachment]]`` or ``[[setup.damper]]``; ``kind`` is ``setup[<name>].<noun>``."""
    name = _item_name(table, kind, index)
    where = f"{kind}[{name}]"
    _check_keys(table, keys, where)
    if "damping" in table:
        raise CampaignError("an attachment has no damping; give a damper as a [[setup.damper]] with its "
                            "coefficient (N s/m)", field=f"{where}.damping")
    position = _number(_required(table, "position", where), f"{where}.position")
    if not 0 < position < length:
        message = f"position {position} m is outside the span (0, {length}) m"
        raise CampaignError(message, field=f"{where}.position")
    mass = _number(table.get("mass", 0.0), f"{where}.mass")
    stiffness = _number(table.get("stiffness", 0.0), f"{where}.stiffness")
    try:
        if kind.endswith(".damper"):
            coefficient = _number(_required(table, "coefficient", where), f"{where}.coefficient")
            angle = math.radians(_number(table.get("angle", 0.0), f"{where}.angle"))  # degrees in the file
            return Damper(name, position, mass, stiffness, coefficient=coefficient, angle=angle)
        stiffness_out = table.get("stiffness_out")
        if stiffness_out is not None:
            stiffness_out = _number(stiffness_out, f"{where}.stiffness_out")
        return Attachment(name, position, mass, stiffness, stiffness_out=stiffness_out)
    except ModelError as err:
        # The model names the field from the attachment down; add the setup.
        setup_where = kind.rsplit(".", 1)[0]
        raise CampaignError(err.message, field=f"{setup_where}.{err.field}") from err


def _parse_test(table: dict[str, Any], index: int) -> Test:
    """Build one ``[[test]]``."""
    name = _item_name(table, "test", index)
    where = f"test[{name}]"
    _check_keys(table, _TEST_KEYS, where)
    frequencies = table.get("frequencies")
    modes = table.get("modes")
    record = table.get("record")
    reference = _table(table.get("reference", {}), f"{where}.reference")
    uncertainty = table.get("uncertainty")
    if uncertainty is not None:  # one number for all the frequencies, or one per frequency
        uncertainty = (_numbers(uncertainty, f"{where}.uncertainty") if isinstance(uncertainty, list)
                       else _number(uncertainty, f"{where}.uncertainty"))
    planes = table.get("planes")
    if planes is not None and frequencies is None:
        raise CampaignError("given without frequencies", field=f"{where}.planes")
    if planes is not None:  # one plane for all the frequencies, or one per frequency
        planes = (tuple(_string(p, f"{where}.planes") for p in planes) if isinstance(planes, list)
                  else _string(planes, f"{where}.planes"))
        if isinstance(planes, str):
            planes = (planes,) * len(frequencies) if isinstance(frequencies, list) else (planes,)
    channels, directions = _parse_channels(table.get("channels", {}), f"{where}.channels")
    return Test(
        name=name,
        setup=_string(_required(table, "setup", where), f"{where}.setup"),
        tension=_number(_required(table, "tension", where), f"{where}.tension"),
        frequencies=None if frequencies is None else _numbers(frequencies, f"{where}.frequencies"),
        modes=None if modes is None else _integers(modes, f"{where}.modes"),
        record=None if record is None else _string(record, f"{where}.record"),
        reference=tuple((k, _numbers(v, f"{where}.reference.{k}")) for k, v in reference.items()),
        channels=channels, channel_directions=directions,
        uncertainty=uncertainty, planes=planes,
        record_format=_parse_record_format(table.get("record_format", {}), f"{where}.record_format"),
    )


def _parse_channels(value: Any, field: str) -> tuple[tuple[tuple[str, float], ...], tuple[tuple[str, Any], ...]]:
    """A channel table: ``name = position`` (m from end A) or ``name = {position = .., direction = "out"}``
    (``"in"``, ``"out"``, ``"axial"`` or degrees). Returns the positions and the directions given."""
    out, directions = [], []
    for name, entry in _table(value, field).items():
        where = f"{field}.{name}"
        if isinstance(entry, dict):
            _check_keys(entry, _CHANNEL_KEYS, where)
            if "direction" in entry:
                try:
                    directions.append((name, check_direction(entry["direction"], f"{where}.direction")))
                except ModelError as err:
                    raise CampaignError(err.message, field=err.field) from None
            entry = _required(entry, "position", where)
        out.append((name, _number(entry, where)))
    return tuple(out), tuple(directions)


def _parse_record_format(value: Any, field: str) -> tuple[tuple[str, Any], ...]:
    """A ``record_format`` table: every key and value checked (:data:`~stcs_ident.io.records.options.OPTIONS`)."""
    out = []
    for key, option in _table(value, field).items():
        problem = option_problem(key, option)
        if problem is not None:
            raise CampaignError(problem, field=f"{field}.{key}")
        out.append((key, option_value(key, option)))
    return tuple(out)


# --------------------------------------------------------------------------
# Field checks: each raises CampaignError naming the field
# --------------------------------------------------------------------------


def _field(where: str, key: str) -> str:
    return f"{where}.{key}" if where else key


def _check_keys(table: dict[str, Any], allowed: tuple[str, ...], where: str) -> None:
    """Refuse any key of ``table`` not in ``allowed``."""
    for key in table:
        if key not in allowed:
            raise CampaignError(
                f"unknown key {key!r}; expected one of: {', '.join(allowed)}", field=_field(where, key)
            )


def _required(table: dict[str, Any], key: str, where: str) -> Any:
    if key not in table:
        raise CampaignError("is required but missing", field=_field(where, key))
    return table[key]


def _item_name(table: dict[str, Any], kind: str, index: int) -> str:
    """The ``name`` of the ``index``-th item of ``kind``, checked."""
    field = f"{kind}[#{index}].name"
    return _string(_required(table, "name", f"{kind}[#{index}]"), field)


def _table(value: Any, field: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise CampaignError(f"must be a table [{field}], got {_show(value)}", field=field)
    return value


def _tables(value: Any, field: str) -> list[dict[str, Any]]:
    """An array of tables, ``[[setup]]`` and the like."""
    header = re.sub(r"\[[^\]]*\]", "", field)  # setup[case2].attachment -> setup.attachment
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise CampaignError(f"must be an array of tables [[{header}]], got {_show(value)}", field=field)
    return value


def _string(value: Any, field: str, empty_ok: bool = False) -> str:
    if not isinstance(value, str) or not (value or empty_ok):
        kind = "a string" if empty_ok else "a non-empty string"
        raise CampaignError(f"must be {kind}, got {_show(value)}", field=field)
    return value


def _is_number(value: Any) -> bool:
    """True for TOML integers and floats; booleans are not numbers."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _number(value: Any, field: str) -> int | float:
    if not _is_number(value):
        raise CampaignError(f"must be a number, got {_show(value)}", field=field)
    _in_float_range(value, field)
    return value


def _in_float_range(value: float, field: str) -> None:
    """Refuse an integer too large for a float (TOML integers are unbounded)."""
    if isinstance(value, int):
        try:
            float(value)
        except OverflowError:
            raise CampaignError(f"is too large: an integer of {len(str(abs(value)))} digits is beyond the range "
                                "of a float (about 1.8e308)", field=field) from None


def _numbers(value: Any, field: str) -> tuple[int | float, ...]:
    if not isinstance(value, list) or not all(_is_number(v) for v in value):
        raise CampaignError(f"must be a list of numbers, got {_show(value)}", field=field)
    for v in value:
        _in_float_range(v, field)
    return tuple(value)


def _integers(value: Any, field: str) -> tuple[int, ...]:
    if not isinstance(value, list) or not all(isinstance(v, int) and not isinstance(v, bool) for v in value):
        raise CampaignError(f"must be a list of integers, got {_show(value)}", field=field)
    return tuple(value)


def _show(value: Any) -> str:
    """A short, one-line description of a TOML value for a message."""
    if isinstance(value, dict):
        return "a table"
    text = repr(value)
    kind = {str: "string", bool: "boolean", list: "list"}.get(type(value), type(value).__name__)
    text = text if len(text) <= 40 else text[:37] + "..."
    return f"{kind} {_one_line(text)}"


def _one_line(message: Any) -> str:
    return " ".join(str(message).split())
