"""Write a campaign back in the ``campaign.toml`` format that :mod:`stcs_ident.io.campaign` reads.

Units other than SI live only at the file's edge: the file gives the
inclination in degrees, the model holds radians.
"""

from __future__ import annotations

import math

from ..core.model import Boundary, Cable, Campaign, Published, Setup, Test

__all__ = ["campaign_to_toml"]

# Numbers from this size up are written in exponent form (1.2487e6 N).
_EXPONENT_FROM = 1e6



def campaign_to_toml(campaign: Campaign, header: str = "") -> str:
    """Write a campaign in the ``campaign.toml`` format.

    Reading the text back with :func:`load_campaign` gives an equal
    campaign (apart from ``directory``, which is where the file is put).
    Every field is written out, defaults included, so the file shows what
    the toolkit will use.

    Parameters
    ----------
    campaign : Campaign
    header : str, optional
        Text put first as TOML comments, one ``#`` line per line.

    Returns
    -------
    str
        The TOML text, ending with a newline.
    """
    lines = [("# " + line).rstrip() for line in header.splitlines()]
    if lines:
        lines.append("")
    lines += _campaign_lines(campaign)
    lines += ["", *_cable_lines(campaign.cable)]
    for setup in campaign.setups:
        lines += ["", *_setup_lines(setup)]
    for test in campaign.tests:
        lines += ["", *_test_lines(test)]
    for item in campaign.published:
        lines += ["", *_published_lines(item)]
    if campaign.tolerance:
        lines += ["", "[tolerance]", *(f"{key} = {_toml_float(value)}" for key, value in campaign.tolerance)]
    return "\n".join(lines) + "\n"


def _campaign_lines(campaign: Campaign) -> list[str]:
    lines = ["[campaign]", f"name = {_toml_string(campaign.name)}"]
    if campaign.description:
        lines.append(f"description = {_toml_string(campaign.description)}")
    return lines


def _cable_lines(cable: Cable) -> list[str]:
    lines = [
        "[cable]",
        f"length = {_toml_float(cable.length)}",
        f"mass_per_length = {_toml_float(cable.mass_per_length)}",
        f"EI = {_toml_float(cable.EI)}",
    ]
    if cable.EA is not None:
        lines.append(f"EA = {_toml_float(cable.EA)}")
    lines += [
        f"inclination = {_toml_float(_degrees(cable.inclination))}",
        f"gravity = {_toml_float(cable.gravity)}",
        f"boundary = {_toml_boundary(cable.boundary_a, cable.boundary_b)}",
    ]
    return lines


def _setup_lines(setup: Setup) -> list[str]:
    lines = ["[[setup]]", f"name = {_toml_string(setup.name)}"]
    for a in setup.attachments:
        damper = getattr(a, "coefficient", None) is not None
        lines += [
            "",
            "  [[setup.damper]]" if damper else "  [[setup.attachment]]",
            f"  name = {_toml_string(a.name)}",
            f"  position = {_toml_float(a.position)}",
        ]
        if damper:
            lines.append(f"  coefficient = {_toml_float(a.coefficient)}")
        lines += [
            f"  mass = {_toml_float(a.mass)}",
            f"  stiffness = {_toml_float(a.stiffness)}",
        ]
    return lines


def _published_lines(item: Published) -> list[str]:
    lines = ["[[published]]", f"parameter = {_toml_string(item.parameter)}",
             f"low = {_toml_float(item.low)}", f"high = {_toml_float(item.high)}"]
    if item.basis is not None:
        lines.append(f"basis = {_toml_float(item.basis)}")
    if item.source:
        lines.append(f"source = {_toml_string(item.source)}")
    return lines


def _test_lines(test: Test) -> list[str]:
    lines = [
        "[[test]]",
        f"name = {_toml_string(test.name)}",
        f"setup = {_toml_string(test.setup)}",
        f"tension = {_toml_float(test.tension)}",
    ]
    if test.frequencies is not None:
        lines.append(f"frequencies = [{', '.join(_toml_float(f) for f in test.frequencies)}]")
        lines.append(f"modes = [{', '.join(str(k) for k in test.modes)}]")
    if test.record is not None:
        lines.append(f"record = {_toml_string(test.record)}")
    if test.reference:
        lines.append("  [test.reference]")
        for label, values in test.reference:
            lines.append(f"  {_toml_key(label)} = [{', '.join(_toml_float(f) for f in values)}]")
    if test.channels:
        lines.append("  [test.channels]")
        for name, position in test.channels:
            lines.append(f"  {_toml_key(name)} = {_toml_float(position)}")
    return lines


def _toml_key(key: str) -> str:
    """A bare TOML key when possible, else a quoted one."""
    bare = key and all(c.isalnum() or c in "-_" for c in key) and key.isascii()
    return key if bare else _toml_string(key)


def _toml_boundary(a: Boundary, b: Boundary) -> str:
    if a == b:
        return _toml_boundary_end(a)
    return f"[{_toml_boundary_end(a)}, {_toml_boundary_end(b)}]"


def _toml_boundary_end(end: Boundary) -> str:
    if end.kind == "spring":
        return _toml_float(end.rotational_stiffness)
    return _toml_string(end.kind)


def _degrees(radians: float) -> float:
    """The shortest angle in degrees that reads back as exactly ``radians``."""
    exact = math.degrees(radians)
    for digits in range(1, 18):
        candidate = float(f"{exact:.{digits}g}")
        if math.radians(candidate) == radians:
            return candidate
    return exact


def _toml_float(value: float) -> str:
    """A TOML float with the fewest digits that read back exactly."""
    value = float(value)
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    if abs(value) < _EXPONENT_FROM:
        return repr(value)
    for digits in range(17):
        text = f"{value:.{digits}e}"
        if float(text) == value:
            mantissa, exponent = text.split("e")
            return f"{mantissa}e{int(exponent)}"
    return repr(value)


_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


def _toml_string(text: str) -> str:
    """A TOML basic string, escaped."""
    out = []
    for ch in text:
        if ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'
