"""Outputs written whole or not at all: a file renamed into place, a directory swapped in whole.

Every writer of the package goes through here (JSON and Markdown text,
CSV tables, PNG figures, HDF5 records), so that a failure (or an
interrupted run) never leaves half a file or half a report, what is
written is on disk before it is renamed into place, and it gets the
permissions a plain ``open()`` or ``mkdir`` would give.

A run killed outright (``kill -9``, a power cut) cannot remove its
temporary files; they are hidden (a leading dot) and their names carry
the host and the process (``.<name>.stcs~<host>~<pid>~<random>``), so the
next run that writes into the same directory removes those whose process
is gone (:func:`remove_stale`).

An output path that is not a regular file is never renamed over:

- a symbolic link is written *through*: the link stays, its target (the
  end of the chain, :func:`output_target`) is replaced whole, the
  temporary beside the target;
- a FIFO or a character device (``/dev/null``, a terminal) is written to
  as a stream: the content is made whole in a temporary of the system's
  temporary directory, then copied into it (a FIFO's reader sees one
  whole output or nothing);
- a directory, a block device or a socket is refused.

Every operating-system error on an output (a read-only directory, a full
disk, a directory that vanished) is an :class:`OutputError` naming the path
as the user gave it: one line, never a traceback. :func:`check_outputs`
finds, before any work, the ones that can be known then.
"""

from __future__ import annotations

import os
import re
import shutil
import socket
import stat
import sys
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO

from .errors import InputError, OutputError


def _output_error(err: OSError, path) -> OutputError:
    out = OutputError(f"cannot write: {err.strerror or err or type(err).__name__}", file=str(path))
    out.errno, out.strerror = err.errno, err.strerror
    return out


def _ours(err: OSError, *paths, within: Path | None = None, below: Path | None = None) -> bool:
    """Whether ``err`` is about one of ``paths``, a file directly in ``within`` (a temporary of ours beside
    the output), a file below ``below`` (in the temporary directory being filled), or names no file (a write
    that failed on an open stream)."""
    if err.filename is None:
        return True
    name = os.fspath(err.filename)
    if name in {os.fspath(p) for p in paths}:
        return True
    if within is not None and os.path.dirname(name) == os.fspath(within):
        return True
    return below is not None and name.startswith(os.fspath(below) + os.sep)


def output_target(path: str | os.PathLike) -> tuple[Path, bool]:
    """Where an output given as ``path`` is written, and whether as a stream.

    Returns ``(target, stream)``: a symbolic link resolved to its final target (written through, the link
    kept); ``stream`` True for a FIFO or a character device (opened and written, never renamed over).
    Raises :class:`OutputError` for a directory, a block device or a socket.
    """
    check_path(path, output=True)
    target = Path(os.path.realpath(path))
    try:
        mode = os.stat(target).st_mode
    except FileNotFoundError:
        return target, False
    except OSError as err:
        raise _output_error(err, path) from err
    if stat.S_ISREG(mode):
        return target, False
    if stat.S_ISFIFO(mode) or stat.S_ISCHR(mode):
        return target, True
    kind = "a directory" if stat.S_ISDIR(mode) else "a block device" if stat.S_ISBLK(mode) else "a socket"
    raise OutputError(f"is {kind}: an output is a regular file (replaced whole), a FIFO or a character device "
                      "(written as a stream)", file=str(path))


def umask() -> int:
    """The process's file-creation mask (read without changing it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _host() -> str:
    return re.sub(r"[^A-Za-z0-9_.]", "_", socket.gethostname()) or "host"


def _prefix(name: str) -> str:
    """The prefix of this process's temporary names beside ``name``."""
    return f".{name}.stcs~{_host()}~{os.getpid()}~"


_STALE = re.compile(r"^\.(?P<name>.*)\.stcs~(?P<host>[A-Za-z0-9_.]+)~(?P<pid>\d+)~")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):  # another user's live process; a pid beyond the system's
        return pid < 2**31
    return True


def remove_stale(directory: str | os.PathLike) -> list[Path]:
    """Remove the temporary files and directories that killed runs of this host left in ``directory``
    (their process no longer exists); returns what was removed. Another host's, or a live process's, are
    left alone. An old output moved aside by :func:`replace_directory` whose replacement never arrived is
    put back first."""
    removed = []
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return removed
    host = _host()
    for entry in entries:
        m = _STALE.match(entry.name)
        if not m or m["host"] != host or _alive(int(m["pid"])):
            continue
        path = Path(entry.path)
        previous, target = path / "previous", Path(directory) / m["name"]
        if entry.name.endswith(".old") and previous.exists() and not os.path.lexists(target):
            os.replace(previous, target)  # killed between moving the old output aside and the new one in
        if entry.is_dir(follow_symlinks=False):
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink(missing_ok=True)
        removed.append(path)
    return removed


_CLEANED: set[str] = set()


def _clean_once(directory: Path) -> None:
    """:func:`remove_stale` once per directory and process: a run writing thousands of files into one
    directory (the parts of ``track``) does not list it before each of them."""
    key = os.path.realpath(directory)
    if key not in _CLEANED:
        remove_stale(directory)
        _CLEANED.add(key)


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextmanager
def atomic_path(path: str | os.PathLike, suffix: str = "") -> Iterator[Path]:
    """A temporary file beside ``path`` for a writer that wants a file name; when the block ends it is
    flushed to disk, given the mode a plain ``open()`` would give (from the umask) and renamed to
    ``path``; when the block fails it is removed and ``path`` is untouched.

    A symbolic link is written through (its target replaced, the link kept); a FIFO or a character
    device is written to as a stream, never renamed over (:func:`output_target`). An operating-system
    error on the output is an :class:`OutputError` naming ``path``.

    The one way the package puts a file in place: :func:`atomic_file`, :func:`write_atomic`,
    :func:`write_csv` and :func:`write_figure` go through it.
    """
    target, stream = output_target(path)
    if stream:
        with _streamed(target, path, suffix) as tmp:
            yield tmp
        return
    directory = target.parent
    tmp = None
    try:
        _clean_once(directory)
        fd, name = tempfile.mkstemp(prefix=_prefix(target.name), suffix=suffix, dir=directory)
        os.close(fd)
        tmp = Path(name)
        yield tmp
        _fsync(tmp)
        os.chmod(tmp, 0o666 & ~umask())  # mkstemp makes 0600; give the mode a plain open() would
        os.replace(tmp, target)
    except OutputError:
        if tmp is not None:
            _unlink_quietly(tmp)
        raise
    except OSError as err:
        if tmp is not None:
            _unlink_quietly(tmp)
        if not _ours(err, path, target, directory, within=directory):
            raise
        raise _output_error(err, path) from err
    except BaseException:
        if tmp is not None:
            _unlink_quietly(tmp)
        raise


def _unlink_quietly(path: Path) -> None:
    try:
        path.unlink(missing_ok=True)
    except OSError:  # the directory went read-only or away: nothing more to do
        pass


@contextmanager
def _streamed(target: Path, path, suffix: str) -> Iterator[Path]:
    """A temporary file (in the system's temporary directory) whose content is copied into the FIFO or
    device ``target`` when the block ends; removed either way."""
    fd, name = tempfile.mkstemp(prefix=".stcs-stream~", suffix=suffix)
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        with open(tmp, "rb") as source, open(target, "wb") as sink:
            shutil.copyfileobj(source, sink)
    except OutputError:
        raise
    except OSError as err:
        if not _ours(err, path, target, tmp):
            raise
        raise _output_error(err, path) from err
    finally:
        _unlink_quietly(tmp)


@contextmanager
def atomic_file(path: str | os.PathLike, mode: str = "w") -> Iterator[IO]:
    """An open stream (``"w"``: UTF-8 text, ``"wb"``: bytes) whose file replaces ``path`` whole when the
    block ends (:func:`atomic_path`)."""
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' or 'wb', got {mode!r}")
    with atomic_path(path) as tmp, open(tmp, mode, encoding="utf-8" if mode == "w" else None) as stream:
        yield stream


def write_atomic(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` whole or not at all; ``-`` is standard output."""
    if str(path) == "-":
        sys.stdout.write(text)
        return
    with atomic_file(path) as stream:
        stream.write(text)


def write_csv(frame, path: str | os.PathLike, **options) -> None:
    """A DataFrame as CSV (``options`` as for :meth:`pandas.DataFrame.to_csv`), whole or not at all."""
    write_atomic(path, frame.to_csv(**options))


def write_figure(fig, path: str | os.PathLike, dpi: int = 110) -> None:
    """A matplotlib figure as PNG, whole or not at all."""
    with atomic_file(path, "wb") as stream:
        fig.savefig(stream, dpi=dpi, format="png")


def replace_directory(tmp: Path, out: Path) -> None:
    """Rename the finished directory ``tmp`` to ``out``; an old ``out`` is replaced only as a whole
    (moved aside, then removed once the new one is in place; put back if the rename fails)."""
    if not out.exists():
        os.replace(tmp, out)
        return
    old = Path(tempfile.mkdtemp(prefix=_prefix(out.name), suffix=".old", dir=out.parent))
    os.replace(out, old / "previous")
    try:
        os.replace(tmp, out)
    except BaseException:
        os.replace(old / "previous", out)
        raise
    finally:
        shutil.rmtree(old, ignore_errors=True)


@contextmanager
def whole_directory(out: Path) -> Iterator[Path]:
    """A new directory beside ``out`` to fill; when the block ends it replaces ``out`` as a whole
    (:func:`replace_directory`), and when the block fails it is removed and ``out`` is untouched.

    ``out`` a symbolic link to a directory: the directory it points to is replaced, the link kept.
    An operating-system error on the output is an :class:`OutputError` naming ``out`` (or the file inside
    it, by its final name)."""
    given = Path(out)
    out = Path(os.path.realpath(out))
    tmp = None
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        _clean_once(out.parent)
        tmp = Path(tempfile.mkdtemp(prefix=_prefix(out.name), suffix=".tmp", dir=out.parent))
        os.chmod(tmp, 0o777 & ~umask())  # mkdtemp makes 0700; give the mode a plain mkdir would
        yield tmp
        replace_directory(tmp, out)
    except OutputError as err:
        _remove_tree(tmp)
        inside = str(err.file or "")
        if tmp is not None and inside.startswith(str(tmp) + os.sep):  # name the file by its final path
            raise OutputError(err.message, field=err.field, file=str(given / inside[len(str(tmp)) + 1:])) from err
        raise
    except OSError as err:
        _remove_tree(tmp)
        if not _ours(err, given, out, out.parent, *([tmp] if tmp else []), within=out.parent, below=tmp):
            raise
        raise _output_error(err, given) from err
    except BaseException:
        _remove_tree(tmp)
        raise


def _remove_tree(path: Path | None) -> None:
    if path is not None:
        shutil.rmtree(path, ignore_errors=True)


def writable_problem(path: str | os.PathLike, is_directory: bool) -> str | None:
    """What keeps the output ``path`` from being written, as far as it can be known before any work
    (None: nothing known): a file output's directory must exist and be writable, a stream writable; a
    directory output's first existing ancestor (or itself) writable. Permissions as the system checks them
    (``os.access``: a read-only file system refuses even root)."""
    real = Path(os.path.realpath(path))
    if not is_directory:
        target, stream = output_target(path)
        if stream:
            return None if os.access(target, os.W_OK) else "cannot write: Permission denied"
        if not target.parent.is_dir():
            return None  # said by the checks of the directory (check_output)
        if not os.access(target.parent, os.W_OK | os.X_OK):
            return f"cannot write: the directory {target.parent} is not writable"
        return None
    for above in (real, *real.parents):
        if above.exists():
            ok = os.access(above, os.W_OK | os.X_OK)  # written into, or the new directory made in it
            return None if ok else f"cannot write: {above} is not writable"
    return None


def check_path(path, option: str | None = None, *, output: bool = False) -> None:
    """Refuse a path holding a NUL character, which the system refuses (``stat``, ``open`` and ``realpath``
    raise ValueError, not OSError): :class:`InputError` (:class:`OutputError` with ``output``) naming the path
    and ``option`` (None: the path alone). Paths from a shell never hold one; a campaign's ``record``, a path
    given through the API or a command line run in-process may."""
    text = os.fsdecode(path) if isinstance(path, (str, bytes, os.PathLike)) else str(path)
    if "\0" in text:
        raise (OutputError if output else InputError)("holds a NUL character, which no path can", field=option,
                                                      file=text)


def check_outputs(outputs: Iterable[tuple[str, str | os.PathLike | None, bool]],
                  inputs: Iterable[str | os.PathLike]) -> None:
    """Refuse, before any work, an output that would replace or be written inside an input.

    ``outputs`` are (option, path, is_directory) (a path None or "-" is skipped); ``inputs`` the files
    the command reads. A file output may not be an input (also through a link); a directory output may not
    be an input, hold one (it is replaced as a whole, or written into), or lie below a file; an output must
    be writable (:func:`writable_problem`). Raises :class:`~stcs_ident.core.errors.InputError` naming the
    option.
    """
    read = []
    for p in inputs:
        check_path(p)
        read.append(os.path.realpath(p))
    for option, path, is_directory in outputs:
        if path is None or str(path) == "-":
            continue
        check_path(path, option, output=True)
        real = os.path.realpath(path)
        for file in read:
            if real == file:
                raise InputError(f"is an input of this command ({file}): outputs never replace inputs",
                                 field=option, file=str(path))
            if is_directory and file.startswith(real.rstrip(os.sep) + os.sep):
                raise InputError(f"holds an input of this command ({file}): outputs are never written where "
                                 "inputs are", field=option, file=str(path))
        parent = Path(real)
        if os.path.exists(real) and is_directory and not os.path.isdir(real):
            raise InputError("exists and is not a directory", field=option, file=str(path))
        for above in (parent, *parent.parents) if is_directory else parent.parents:
            if above.exists():
                if not above.is_dir():
                    raise InputError(f"lies below {above}, which is a file", field=option, file=str(path))
                break
        try:
            problem = writable_problem(path, is_directory)
        except OutputError as err:
            problem = err.message
        if problem is not None:
            raise OutputError(problem, field=option, file=str(path))
