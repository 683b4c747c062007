"""Sylva's exceptions.

``SylvaError`` is the base of every error Sylva raises. ``InputError`` (also a
``ValueError``) is bad input: a malformed file, dict or value; it says where, as the
command line does. ``LimitError`` is legal input that asks for more work or memory than a
limit or the memory budget allows. ``ArchiveError`` is a studio archive that cannot be
opened, read or written; it names the file.
"""

from __future__ import annotations


class SylvaError(Exception):
    """Something Sylva was asked to do failed; the message names every cause."""


class InputError(SylvaError, ValueError):
    """Bad input.

    Attributes:
        message: the whole message, as the command line prints it.
        location: ``path:line:column``, the path alone, or the field or argument.
        path: the file, when the input was one (else ``None``).
        line, column: 1-based position in the file (0 when unknown).
        detail: what is wrong and what was expected, without the location.
    """

    def __init__(
        self,
        message: str,
        *,
        location: str = "",
        path: str | None = None,
        line: int = 0,
        column: int = 0,
        detail: str | None = None,
    ) -> None:
        super().__init__(message)
        self.message = message
        self.location = location
        self.path = path
        self.line = line
        self.column = column
        self.detail = message if detail is None else detail


class LimitError(InputError):
    """Legal input that asks for more than a limit or the memory budget allows."""


class ArchiveError(SylvaError):
    """A studio archive (``sylva studio --db FILE``) that cannot be opened, read or written:
    not found, not an archive, of a schema newer than this Sylva knows, without the plant
    asked for, closed, or refused by SQLite (the file locked by another program past the
    busy timeout of five seconds, a full disk).

    Attributes:
        message: the whole message, naming the file.
        path: the archive's file.
    """

    def __init__(self, message: str, *, path: str | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.path = path


__all__ = ["SylvaError", "InputError", "LimitError", "ArchiveError"]
