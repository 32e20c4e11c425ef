"""The archive of field records: its cables, their records, and a record's identity by content.

    ARCHIVE/<cable>/campaign.toml      the cable and its setup; its first test (if any) gives the
                                       reference tension that numbers the modes; the channel positions
                                       of records whose files give none ([channels] at the top level, else
                                       the first test's [test.channels]) and the reader options
                                       ([record_format], updated with the first test's)
    ARCHIVE/<cable>/records/**/*       the records, in any registered format (by suffix: *.h5, *.csv, ...;
                                       start_time required, temperature optional)

A record is known by the SHA-256 of its bytes, not by its name: a rerun
skips what it processed before even when records were moved or renamed,
and a record rewritten under the same name is processed again.
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

__all__ = ["CableSpec", "content_id", "discover", "record_paths"]


@dataclass(frozen=True)
class CableSpec:
    """One cable of an archive: its campaign, the setup its records are of, the reference tension, the
    channel positions (m from end A) of records whose files give none (the campaign's top-level ``channels``,
    else its first test's) and the reader options (``record_format``, the first test's over the campaign's)."""

    name: str
    directory: str
    campaign: Campaign
    setup: str
    reference_tension: float
    channels: tuple[tuple[str, float], ...] = ()
    record_format: tuple[tuple[str, Any], ...] = ()


def discover(archive: str | os.PathLike, cables: list[str] | None = None) -> list[CableSpec]:
    """The cables of ``archive`` (folders holding a campaign.toml), all or those named in ``cables``."""
    root = Path(archive)
    if not root.is_dir():
        raise InputError("is not a directory (an archive holds one folder per cable)", file=str(root))
    found = sorted(p.parent.name for p in root.glob("*/campaign.toml"))
    if not found:
        raise InputError("holds no cable: expected <cable>/campaign.toml folders", file=str(root))
    for name in cables or []:
        if name not in found:
            raise InputError(f"no cable named {name!r} (known: {', '.join(found)})", field="--cable", file=str(root))
    return [_cable(root / name) for name in (cables or found)]


def _cable(directory: Path) -> CableSpec:
    campaign = load_campaign(directory)
    file = str(directory / "campaign.toml")
    if not campaign.tests:
        raise InputError("needs a test: its tension is the reference that numbers the modes of the records, and "
                         "its setup what is attached", field="test", file=file)
    test = campaign.tests[0]
    positions, options = campaign.record_reading(test)
    return CableSpec(directory.name, str(directory), campaign, test.setup, float(test.tension),
                     tuple((positions or {}).items()), tuple(options.items()))


def record_paths(spec: CableSpec) -> list[Path]:
    """The cable's records (``records/**/*`` with a registered reader's suffix, any case), in path order."""
    suffixes = record_suffixes()
    found = (Path(spec.directory) / "records").rglob("*")
    return sorted(p for p in found if p.name.lower().endswith(suffixes) and p.is_file())
