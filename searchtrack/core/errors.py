"""Errors raised at the library's boundary: each names the field (and file and line) at fault."""

from __future__ import annotations

from pathlib import Path


class SearchtrackError(Exception):
    """Base class of every error searchtrack raises on purpose."""


class InvalidInputError(SearchtrackError, ValueError):
    """A value given to a constructor or solver is out of its domain.

    Parameters
    ----------
    field
        The name of the offending field, as the caller wrote it.
    value
        The bad value (shown with ``repr``, shortened).
    reason
        What the value should have been.
    """

    def __init__(self, field: str, value: object, reason: str) -> None:
        shown = repr(value)
        if len(shown) > 80:
            shown = shown[:77] + "..."
        super().__init__(f"{field}={shown}: {reason}")
        self.field = field
        self.value = value
        self.reason = reason


class ParseError(SearchtrackError, ValueError):
    """A file could not be read: names the file, the line (1-based) and the field."""

    def __init__(self, path: str | Path, line: int | None, field: str | None, reason: str) -> None:
        where = str(path)
        if line is not None:
            where += f", line {line}"
        if field is not None:
            where += f", field {field!r}"
        super().__init__(f"{where}: {reason}")
        self.path = str(path)
        self.line = line
        self.field = field
        self.reason = reason
