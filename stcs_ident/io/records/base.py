"""Record readers behind one interface, and the registry that picks one for a file.

A format is one module holding a :class:`RecordReader` (its ``name``, its
``suffixes``, ``can_open`` that recognises its content, ``read`` that gives
a :class:`~stcs_ident.core.record.Record`) and one :func:`register` call;
everything that reads a record (spectra, identify, diagnose, track) asks
:func:`read_record`, and the archive of ``track`` lists every registered
suffix (:func:`record_suffixes`). The shape is xarray's
``BackendEntrypoint`` (``open_dataset``, ``guess_can_open``).

:func:`read_record` picks the reader by the file's suffix; where several
readers share the suffix, or none has it, or the suffix is one files of many
formats have (``.dat``, a reader's ``generic_suffixes``), by content (the
first bytes, as each reader's ``can_open`` says). A file no reader takes is
refused with one line naming it.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from ...core.errors import InputError, ModelError
from ...core.planes import check_direction, direction_text
from ...core.record import Record
from .options import check_options
from .validation import overridden

__all__ = [
    "HEAD_BYTES", "RecordReader", "file_head", "read_record", "reader_for", "readers", "record_suffixes", "register",
    "unregister",
]

#: Bytes of a file's beginning that a reader's ``can_open`` may look at.
HEAD_BYTES = 2048

_READERS: dict[str, RecordReader] = {}


class RecordReader:
    """One record format: how to tell its files and how to read one.

    Subclasses set ``name`` and ``suffixes`` and define :meth:`read`; they
    override :meth:`can_open` when the content tells the format (magic bytes).

    Attributes
    ----------
    name : str
        Short name of the format (``"hdf5"``), unique in the registry.
    suffixes : tuple of str
        File name endings, lower case with the dot (``(".h5", ".hdf5")``).
    generic_suffixes : tuple of str
        Those of ``suffixes`` that files of other formats have too (TOA5's ``.dat``): for such a file the
        content decides first (:func:`reader_for`).
    """

    name: str = ""
    suffixes: tuple[str, ...] = ()
    generic_suffixes: tuple[str, ...] = ()

    def can_open(self, path: str | os.PathLike) -> bool:
        """Whether the file's content is of this format (default: cannot tell, False).

        Asked only when the suffix does not decide; should read no more
        than :func:`file_head` gives.
        """
        return False

    def read(self, path: str | os.PathLike, *, positions: Mapping[str, float] | None = None, **options: Any) -> Record:
        """The record in ``path``, checked as every record is (:mod:`~stcs_ident.io.records.validation`).

        Parameters
        ----------
        path : str or path-like
            The record file.
        positions : mapping of str to float, optional
            m from end A, by channel name, for channels whose file gives no position.
        **options
            Reader options (:data:`~stcs_ident.io.records.options.OPTIONS`), checked already; a reader uses
            those of its format and ignores the others. ``start_time`` and ``temperature`` are applied by
            :func:`read_record` to every format.

        Raises
        ------
        InputError
            Naming the file and, where it can be told, the field.
        """
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} {' '.join(self.suffixes)}>"


def register(reader: RecordReader) -> RecordReader:
    """Add ``reader`` to the registry (and return it).

    Raises
    ------
    TypeError
        If it has no name, a suffix is not lower case with a leading dot,
        or it lacks ``read`` or ``can_open``.
    ValueError
        If a reader of that name is registered already.
    """
    name = getattr(reader, "name", None)
    if not isinstance(name, str) or not name:
        raise TypeError(f"a record reader needs a non-empty name, got {name!r}")
    suffixes = getattr(reader, "suffixes", None)
    if (not isinstance(suffixes, tuple)
            or not all(isinstance(s, str) and s.startswith(".") and s == s.lower() and len(s) > 1 for s in suffixes)):
        raise TypeError(f"record reader {name!r}: suffixes must be a tuple of lower-case '.ext', got {suffixes!r}")
    if not callable(getattr(reader, "read", None)) or not callable(getattr(reader, "can_open", None)):
        raise TypeError(f"record reader {name!r} needs read(path, positions=...) and can_open(path)")
    if name in _READERS:
        raise ValueError(f"a record reader named {name!r} is registered already")
    _READERS[name] = reader
    return reader


def unregister(name: str) -> RecordReader:
    """Remove the reader named ``name`` from the registry (and return it); KeyError if there is none."""
    return _READERS.pop(name)


def readers() -> tuple[RecordReader, ...]:
    """The registered readers, in registration order."""
    return tuple(_READERS.values())


def record_suffixes() -> tuple[str, ...]:
    """Every registered suffix, once each, in registration order."""
    return tuple(dict.fromkeys(s for reader in _READERS.values() for s in reader.suffixes))


def reader_for(path: str | os.PathLike) -> RecordReader:
    """The reader of the file at ``path``: by suffix, by content where the suffix does not decide (shared by
    several readers, a generic suffix such as ``.dat``, or none); a file with a generic suffix that no reader
    recognises goes to the reader of that suffix, which says what it expected.

    Raises
    ------
    InputError
        If the file is missing, or no registered reader takes it (no field; the message lists the formats).
    """
    file = os.fspath(path)
    lower = os.path.basename(file).lower()
    by_suffix = [reader for reader in _READERS.values() if any(lower.endswith(s) for s in reader.suffixes)]
    generic = bool(by_suffix) and all(any(lower.endswith(s) for s in getattr(reader, "generic_suffixes", ()))
                                      for reader in by_suffix)
    if len(by_suffix) == 1 and not (generic and os.path.exists(file)):
        return by_suffix[0]
    if not os.path.exists(file):
        raise InputError("file not found", file=file)
    others = [reader for reader in _READERS.values() if reader not in by_suffix] if generic else []
    for reader in [*by_suffix, *others] if by_suffix else _READERS.values():
        if reader.can_open(file):
            return reader
    if by_suffix:  # a shared suffix, and no content recognised: the first reader says what is wrong
        return by_suffix[0]
    known = ", ".join(f"{reader.name} ({' '.join(reader.suffixes)})" for reader in _READERS.values())
    raise InputError(f"not a record format this toolkit reads: no reader for its suffix or content; known: {known}",
                     file=file)


def read_record(path: str | os.PathLike, *, positions: Mapping[str, float] | None = None,
                directions: Mapping[str, Any] | None = None, **options: Any) -> Record:
    """Read an acceleration record in any registered format (:func:`reader_for` picks it).

    Parameters
    ----------
    path : str or path-like
        The record file.
    positions : mapping of str to float, optional
        m from end A, by channel name, for channels whose file gives no position (CSV).
    directions : mapping of str to direction, optional
        By channel name, ``"in"``, ``"out"``, ``"axial"`` or degrees (the campaign's channel table); they
        replace the file's (and ``replaced`` says where they differ); a channel named in neither is in-plane.
        With neither the file's nor these, the record's ``channel_directions`` is None (every channel read as
        in-plane; :func:`~stcs_ident.core.planes.directions_note` says so).
    **options
        Reader options (:data:`~stcs_ident.io.records.options.OPTIONS`: ``unit``, ``sampling_rate``,
        ``override_sampling_rate``, ``time_column``, ``separator``, ``decimal``, ``skip_rows``, ``header_row``,
        ``channels``, ``start_time``, ``temperature``, ``variable``, ``group``, ``axes``), a campaign's
        ``record_format``; None values are ignored. Each reader takes those of its format; ``start_time`` and
        ``temperature`` replace the file's in every format, and the record's ``replaced`` lists where a given
        value differs from the file's; a ``sampling_rate`` that disagrees with the file's is refused unless
        ``override_sampling_rate`` (:mod:`~stcs_ident.io.records.rates`).

    Returns
    -------
    Record
        In m/s², ``source = str(path)``, dead and clipped channels dropped; its ``notes`` say what the reader
        did that a user should know (a header found after a preamble, columns left out).

    Raises
    ------
    InputError
        One line naming the file (and the field): unknown format, missing file, a wrong option, or what the
        reader refuses.
    """
    options = check_options(options, file=os.fspath(path))
    record = reader_for(path).read(path, positions=positions, **options)
    replaced = list(record.replaced)
    changes = {key: overridden(key, getattr(record, key), options, replaced) for key in ("start_time", "temperature")
               if options.get(key) is not None}
    if directions:
        changes["channel_directions"] = given_directions(record, directions, replaced)
    return replace(record, **changes, replaced=tuple(replaced)) if changes else record


def given_directions(record: Record, directions: Mapping[str, Any], replaced: list) -> tuple:
    """The record's channel directions with the campaign's ``directions`` (by channel name) in place of the
    file's; a difference from a file's direction is recorded in ``replaced``."""
    file = record.source
    found = record.channel_directions
    out = []
    for k, name in enumerate(record.channel_names):
        own = None if found is None else found[k]
        if name not in directions:
            out.append("in" if own is None else own)
            continue
        try:
            given = check_direction(directions[name], "channel_direction")
        except ModelError as err:
            raise InputError(f"channel {name!r}: {err.message}", field="channel_direction", file=file) from None
        if own is not None and own != given:
            replaced.append((f"direction of {name}", direction_text(given), direction_text(own)))
        out.append(given)
    return tuple(out)


def file_head(path: str | os.PathLike, size: int = HEAD_BYTES) -> bytes:
    """The first ``size`` bytes of the file (fewer if it is shorter; empty if it cannot be read)."""
    try:
        with open(path, "rb") as stream:
            return stream.read(size)
    except OSError:
        return b""
