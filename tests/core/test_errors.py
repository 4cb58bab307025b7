"""Boundary errors: each names the field (and for files the path and line) in its message."""

from __future__ import annotations

from pathlib import Path

import pytest

from searchtrack.core.errors import InvalidInputError, ParseError, SearchtrackError


def test_invalid_input_names_field_value_and_reason() -> None:
    """The message reads ``field=repr(value): reason`` and the parts stay available."""
    err = InvalidInputError("speed_mps", -3.0, "must be positive")
    assert str(err) == "speed_mps=-3.0: must be positive"
    assert (err.field, err.value, err.reason) == ("speed_mps", -3.0, "must be positive")


def test_invalid_input_shortens_long_values() -> None:
    """A value whose repr passes 80 characters is cut to 77 and an ellipsis; the value is kept."""
    value = "x" * 200
    err = InvalidInputError("name", value, "too long")
    shown = str(err).removeprefix("name=").removesuffix(": too long")
    assert len(shown) == 80 and shown == repr(value)[:77] + "..."
    assert err.value is value
    exact = "y" * 78  # repr adds two quotes: exactly 80 characters, kept whole
    assert str(InvalidInputError("name", exact, "ok")) == f"name={exact!r}: ok"


@pytest.mark.parametrize(("line", "field", "expected"), [
    (None, None, "roads.osm: no such file"),
    (12, None, "roads.osm, line 12: bad number"),
    (None, "nodes", "roads.osm, field 'nodes': missing"),
    (3, "lat", "roads.osm, line 3, field 'lat': bad number"),
])
def test_parse_error_names_file_line_and_field(line: int | None, field: str | None,
                                               expected: str) -> None:
    """The message starts with the file, then the line and the field when they are known."""
    reason = expected.rsplit(": ", 1)[1]
    err = ParseError(Path("roads.osm"), line, field, reason)
    assert str(err) == expected
    assert (err.path, err.line, err.field, err.reason) == ("roads.osm", line, field, reason)


def test_errors_are_value_errors_of_one_family() -> None:
    """Both errors are ValueErrors (callers may catch either) and SearchtrackErrors."""
    for err in (InvalidInputError("f", 1, "r"), ParseError("a.txt", None, None, "r")):
        assert isinstance(err, ValueError) and isinstance(err, SearchtrackError)
    with pytest.raises(ValueError, match="f=1: r"):
        raise InvalidInputError("f", 1, "r")
