"""Exceptions and warnings of stcs-ident, in one place.

Every error a user can cause carries what they need to fix it: the file,
the field and what is wrong. The command line turns them into one line on
standard error and exit status 2.
"""

from __future__ import annotations


class InputError(ValueError):
    """Bad input: a file, a field or a value the toolkit cannot accept.

    Parameters
    ----------
    message : str
        What is wrong, in plain words.
    field : str, optional
        Dotted name of the offending field (``"cable.length"``,
        ``"setup[case2].attachment[W1].position"``), or the command-line
        option (``"--duration"``), shown as ``option '--duration'``.
    file : str, optional
        The file that holds the field.
    """

    def __init__(self, message: str, *, field: str | None = None, file: str | None = None):
        self.message = message
        self.field = field
        self.file = file
        super().__init__(self._text())

    def _text(self) -> str:
        parts = []
        if self.file:
            parts.append(str(self.file))
        if self.field:  # a command-line option is named as one
            parts.append(f"{'option' if self.field.startswith('--') else 'field'} '{self.field}'")
        head = ": ".join(parts)
        return one_line(f"{head}: {self.message}" if head else self.message)

    def with_file(self, file: str) -> InputError:
        """Return the same error, attributed to ``file``."""
        return type(self)(self.message, field=self.field, file=file)


def one_line(text: str, limit: int = 2000) -> str:
    """``text`` as one printable line: control characters (a newline in a test's name, an escape
    sequence) shown escaped, and at most ``limit`` characters (the rest elided)."""
    out = "".join(c if c.isprintable() or c == " " else c.encode("unicode_escape").decode("ascii") for c in text)
    return out if len(out) <= limit else out[:limit - 3] + "..."


class OutputError(InputError, OSError):
    """An output that cannot be written as given: a read-only directory or file system, a full disk, a
    directory gone during the run, a path that is a directory or a socket. ``file`` is the path as the user
    gave it; the command line says it in one line, exit status 2 (:mod:`stcs_ident.core.files`). Also an
    :class:`OSError` (``errno`` and ``strerror`` those of the system's error, when there was one), so that a
    caller catching the system's errors of a write still does."""

    def __str__(self) -> str:
        return self._text()


class CampaignError(InputError):
    """A campaign file that is unreadable, incomplete or inconsistent."""


class ModelError(InputError):
    """A model object built with an invalid value (names the field)."""


class ComputationError(RuntimeError):
    """A computation that failed, for example a root that did not converge."""


class StcsWarning(UserWarning):
    """Base class of the toolkit's warnings."""


class RecordWarning(StcsWarning):
    """Something in an acceleration record was handled (a channel dropped, say)."""


class NumberingWarning(StcsWarning):
    """A mode-number assignment is doubtful."""


class TrackWarning(StcsWarning):
    """Something in the state of ``track``'s output was handled (an unreadable part rebuilt from the records)."""


class BoundError(ComputationError):
    """A fit that stopped at a bound of a parameter: not a result.

    Attributes
    ----------
    result : object
        The failed result (an :class:`~stcs_ident.identify.result.IdentificationResult` whose ``failure``
        names the parameter and the bound): its before/after frequencies stay printable, its parameters have
        no uncertainty.
    """

    def __init__(self, message: str, result=None):
        super().__init__(message)
        self.result = result
