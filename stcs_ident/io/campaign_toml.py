"""Write a campaign back in the ``campaign.toml`` format that :mod:`stcs_ident.io.campaign` reads.

The campaign is laid out as the tables and keys of the format (a plain
dict) and written by tomli-w, which owns TOML's quoting, escaping and
number syntax. Units other than SI live only at the file's edge: the file
gives the inclination in degrees, the model holds radians.
"""

from __future__ import annotations

import math
from typing import Any

import tomli_w

from ..core.model import Boundary, Cable, Campaign, Published, Setup, Test

__all__ = ["campaign_tables", "campaign_to_toml"]


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
    comments = "".join(("# " + line).rstrip() + "\n" for line in header.splitlines())
    return (comments + "\n" if comments else "") + tomli_w.dumps(campaign_tables(campaign))


def campaign_tables(campaign: Campaign) -> dict[str, Any]:
    """The campaign as the tables of ``campaign.toml`` (key order as the format lists them), SI units
    except the inclination in degrees."""
    data: dict[str, Any] = {"campaign": {"name": campaign.name}, "cable": _cable_table(campaign.cable)}
    if campaign.description:
        data["campaign"]["description"] = campaign.description
    if campaign.setups:
        data["setup"] = [_setup_table(setup) for setup in campaign.setups]
    if campaign.tests:
        data["test"] = [_test_table(test) for test in campaign.tests]
    if campaign.published:
        data["published"] = [_published_table(item) for item in campaign.published]
    if campaign.tolerance:
        data["tolerance"] = {key: float(value) for key, value in campaign.tolerance}
    if campaign.record_format:
        data["record_format"] = _record_format_table(campaign.record_format)
    if campaign.channels:
        data["channels"] = _channels_table(campaign.channels, campaign.channel_directions)
    if campaign.bounds:
        data["bounds"] = {key: [float(lo), float(hi)] for key, (lo, hi) in campaign.bounds}
    if campaign.structural_frequencies:
        data["structure"] = {"frequencies": [float(f) for f in campaign.structural_frequencies]}
    return data


def _record_format_table(options: tuple[tuple[str, Any], ...]) -> dict[str, Any]:
    """Reader options as TOML values: rows as a list, ``axes`` as a table, numbers as they were read (floats)."""
    return {key: dict(value) if key == "axes" else list(value) if isinstance(value, tuple) else value
            for key, value in options}


def _cable_table(cable: Cable) -> dict[str, Any]:
    table: dict[str, Any] = {"length": cable.length, "mass_per_length": cable.mass_per_length, "EI": cable.EI}
    if cable.EA is not None:
        table["EA"] = cable.EA
    table.update(inclination=_degrees(cable.inclination), gravity=cable.gravity,
                 boundary=_boundary(cable.boundary_a, cable.boundary_b))
    return {key: _number(value) for key, value in table.items()}


def _setup_table(setup: Setup) -> dict[str, Any]:
    table: dict[str, Any] = {"name": setup.name}
    attachments, dampers = [], []
    for a in setup.attachments:
        point = {"name": a.name, "position": float(a.position)}
        if getattr(a, "coefficient", None) is not None:
            point["coefficient"] = float(a.coefficient)
            if a.angle:
                point["angle"] = _degrees(a.angle)
            dampers.append(point)
        else:
            attachments.append(point)
        point.update(mass=float(a.mass), stiffness=float(a.stiffness))
        if getattr(a, "stiffness_out", None) is not None:
            point["stiffness_out"] = float(a.stiffness_out)
    # The reader builds a setup's attachments before its dampers, so this order reads back equal.
    if attachments:
        table["attachment"] = attachments
    if dampers:
        table["damper"] = dampers
    return table


def _test_table(test: Test) -> dict[str, Any]:
    table: dict[str, Any] = {"name": test.name, "setup": test.setup, "tension": float(test.tension)}
    if test.frequencies is not None:
        table["frequencies"] = [float(f) for f in test.frequencies]
        table["modes"] = [int(k) for k in test.modes]
    if test.record is not None:
        table["record"] = test.record
    if test.reference:
        table["reference"] = {label: [float(f) for f in values] for label, values in test.reference}
    if test.channels:
        table["channels"] = _channels_table(test.channels, test.channel_directions)
    if test.planes is not None and "out" in test.planes:
        table["planes"] = list(test.planes)
    if test.uncertainty is not None:
        table["uncertainty"] = [float(u) for u in test.uncertainty]
    if test.record_format:
        table["record_format"] = _record_format_table(test.record_format)
    return table


def _channels_table(channels, directions) -> dict[str, Any]:
    """``name = position``; with a direction given, every channel as ``{position, direction}`` (a table each:
    the writer puts plain values before tables, and the table's order is the column order of a file without
    channel names)."""
    given = dict(directions)
    if not given:
        return {name: float(position) for name, position in channels}
    return {name: {"position": float(position)} | ({} if name not in given else {
        "direction": given[name] if isinstance(given[name], str) else float(given[name])})
        for name, position in channels}


def _published_table(item: Published) -> dict[str, Any]:
    table: dict[str, Any] = {"parameter": item.parameter, "low": float(item.low), "high": float(item.high)}
    if item.basis is not None:
        table["basis"] = float(item.basis)
    if item.source:
        table["source"] = item.source
    return table


def _boundary(a: Boundary, b: Boundary) -> str | float | list[str | float]:
    """One end's value when both ends are alike, else ``[A, B]``."""
    ends = [end.rotational_stiffness if end.kind == "spring" else end.kind for end in (a, b)]
    return ends[0] if a == b else ends


def _number(value):
    """Numbers as floats (TOML integers would read back as int); strings and lists as they are."""
    if isinstance(value, list):
        return [_number(v) for v in value]
    return value if isinstance(value, str) else float(value)


def _degrees(radians: float) -> float:
    """The shortest angle in degrees that reads back as exactly ``radians``."""
    exact = math.degrees(radians)
    for digits in range(1, 18):
        candidate = float(f"{exact:.{digits}g}")
        if math.radians(candidate) == radians:
            return candidate
    return exact
