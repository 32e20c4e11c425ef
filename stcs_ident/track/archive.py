"""The archive of field records: its cables, their records, and a record's identity by content.

    ARCHIVE/<cable>/campaign.toml      the cable and its setup; its first test (if any) gives the
                                       reference tension that numbers the modes; the channel positions
                                       of records whose files give none ([channels] at the top level, else
                                       the first test's [test.channels]) and the reader options
                                       ([record_format], updated with the first test's)
    ARCHIVE/<cable>/records/**/*       the records, in any registered format (by suffix: *.h5, *.csv, ...;
                                       start_time required, temperature optional)

A record is known by its place (cable and path below the cable's folder)
and the SHA-256 of its bytes: a record rewritten under the same name is
processed again, one copied or renamed within its cable reuses the row of
its content (:mod:`.state`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..core.errors import InputError
from ..core.model import Campaign
from ..io.campaign import load_campaign
from ..io.content import content_id
from ..io.records import record_suffixes
from ..io.test_record import record_reading

__all__ = ["CableSpec", "cable_names", "content_id", "discover", "record_paths"]


@dataclass(frozen=True)
class CableSpec:
    """One cable of an archive: its campaign, the setup its records are of, the reference tension, the
    channel positions (m from end A) of records whose files give none (the campaign's top-level ``channels``,
    else its first test's), the reader options (``record_format``, the first test's over the campaign's) and the
    channel directions of the same channel table (they replace a file's)."""

    name: str
    directory: str
    campaign: Campaign
    setup: str
    reference_tension: float
    channels: tuple[tuple[str, float], ...] = ()
    record_format: tuple[tuple[str, Any], ...] = ()
    directions: tuple[tuple[str, Any], ...] = ()
    #: What shaped the cable's rows (set by the run): its rows of another version are stale.
    version: str = ""


def discover(archive: str | os.PathLike, cables: list[str] | None = None) -> list[CableSpec]:
    """The cables of ``archive`` (folders holding a campaign.toml), all or those named in ``cables``."""
    given, root = str(archive), Path(archive).absolute()  # the records' paths reach other processes whole
    if not root.is_dir():
        raise InputError("is not a directory (an archive holds one folder per cable)", file=given)
    found = cable_names(root)
    if not found:
        raise InputError("holds no cable: expected <cable>/campaign.toml folders", file=given)
    for name in cables or []:
        if name not in found:
            raise InputError(f"no cable named {name!r} (known: {', '.join(found)})", field="--cable", file=given)
    return [_cable(root / name) for name in (cables or found)]


def _cable(directory: Path) -> CableSpec:
    campaign = load_campaign(directory)
    file = str(directory / "campaign.toml")
    if not campaign.tests:
        raise InputError("needs a test: its tension is the reference that numbers the modes of the records, and "
                         "its setup what is attached", field="test", file=file)
    test = campaign.tests[0]
    reading = record_reading(campaign, test)
    return CableSpec(directory.name, str(directory), campaign, test.setup, float(test.tension),
                     tuple((reading.positions or {}).items()), tuple(reading.options.items()),
                     tuple((reading.directions or {}).items()))


def record_paths(spec: CableSpec) -> list[Path]:
    """The cable's records (``records/**/*`` with a registered reader's suffix, any case), in path order."""
    suffixes = record_suffixes()
    found = (Path(spec.directory) / "records").rglob("*")
    return sorted(p for p in found if p.name.lower().endswith(suffixes) and p.is_file())


def cable_names(archive: str | os.PathLike) -> list[str]:
    """The names of every cable of ``archive`` (folders holding a campaign.toml), sorted."""
    return sorted(p.parent.name for p in Path(archive).glob("*/campaign.toml"))
