"""Opening a test's record: the one way every command finds, configures and reads it.

A test's ``record`` is a path relative to the campaign's directory; its
channel table (positions, directions) and reader options are the test's,
else the campaign's top-level ones (a ``track`` archive gives them once per
cable). :func:`record_reading` gathers them, :func:`record_path` resolves the
path, and :func:`open_test_record` reads the file through the record readers
(:func:`~stcs_ident.io.records.read_record`). ``spectra``, ``identify``,
``diagnose``, ``track`` and the quick ``tension --record`` all come here.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from ..core.model import Campaign, Test
from ..core.record import Record
from .records import read_record

__all__ = ["RecordReading", "open_record", "open_test_record", "record_path", "record_reading"]


@dataclass(frozen=True)
class RecordReading:
    """How to read a record: what a campaign (or the command line) says beside the file.

    Attributes
    ----------
    positions : dict or None
        m from end A, by channel name (None: the file's own).
    options : dict
        Reader options (:data:`~stcs_ident.io.records.options.OPTIONS`).
    directions : dict or None
        ``"in"``, ``"out"``, ``"axial"`` or degrees, by channel name (None: the file's, else in-plane).
    """

    positions: dict[str, float] | None = None
    options: dict[str, Any] = field(default_factory=dict)
    directions: dict[str, Any] | None = None


def record_reading(campaign: Campaign, test: Test) -> RecordReading:
    """The channel table and reader options of ``test``'s record: the test's, else the campaign's (reader
    options: the campaign's ``record_format`` updated with the test's)."""
    return RecordReading(
        positions=dict(test.channels or campaign.channels) or None,
        options={**dict(campaign.record_format), **dict(test.record_format)},
        directions=dict(test.channel_directions or campaign.channel_directions) or None,
    )


def record_path(campaign: Campaign, test: Test) -> str:
    """The path of ``test``'s record, a relative one taken from the campaign's directory."""
    if os.path.isabs(test.record) or campaign.directory is None:
        return test.record
    return os.path.join(campaign.directory, test.record)


def open_record(path: str | os.PathLike, reading: RecordReading | Mapping[str, Any] | None = None) -> Record:
    """Read the record at ``path`` as ``reading`` says (a :class:`RecordReading`, or its fields as a mapping)."""
    if reading is None:
        reading = RecordReading()
    elif not isinstance(reading, RecordReading):
        reading = RecordReading(**dict(reading))
    return read_record(path, positions=reading.positions, directions=reading.directions, **reading.options)


def open_test_record(campaign: Campaign, test: Test) -> tuple[str, Record]:
    """(path, record) of ``test``: its path resolved and the file read with its campaign's channel table and
    reader options (:func:`record_reading`)."""
    path = record_path(campaign, test)
    return path, open_record(path, record_reading(campaign, test))
