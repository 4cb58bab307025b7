"""Typed reads from a TOML table: values, defaults, ranges, sub-tables and unknown keys, each
failure naming the file and the dotted key."""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import pytest

from searchtrack.core.errors import ParseError
from searchtrack.sim.toml_fields import Table

PATH = Path("config.toml")

TEXT = """
name = "demo"
count = 3
flag = true
speed = 2.5
whole = 4
huge = inf
[sub]
rows = 2
[sub.deep]
x = 1.0
"""


def table(text: str = TEXT) -> Table:
    """The top-level table of ``text``, read from PATH."""
    return Table(tomllib.loads(text), PATH)


def failure(call: object) -> ParseError:
    """The ParseError ``call()`` raises."""
    with pytest.raises(ParseError) as info:
        call()  # type: ignore[operator]
    assert info.value.path == str(PATH)
    return info.value


def test_values_and_defaults() -> None:
    """Present keys are read with their types; absent ones take the default."""
    t = table()
    assert t.string("name") == "demo" and t.integer("count") == 3 and t.boolean("flag", False)
    assert t.number("speed") == 2.5
    whole = t.number("whole")
    assert whole == 4.0 and isinstance(whole, float)
    assert t.number("missing_number", 7.0) == 7.0 and t.integer("missing_int", 5) == 5
    assert t.string("missing_str", "x") == "x" and t.boolean("missing_flag", True) is True
    assert t.optional_number("missing_optional") is None
    assert t.optional_number("speed", positive=True) == 2.5
    assert t.raw("name") == "demo" and t.raw("nothing", 0) == 0
    assert t.has("name") and not t.has("nothing")


def test_dotted_keys_of_nested_tables() -> None:
    """key() prefixes the table's dotted name; sub-tables read and fail with it."""
    t = table()
    assert t.key("name") == "name"
    sub = t.table("sub")
    assert sub.key("rows") == "sub.rows" and sub.integer("rows") == 2
    deep = sub.table("deep")
    assert deep.number("x") == 1.0
    assert failure(lambda: deep.number("y")).field == "sub.deep.y"
    assert t.fail("name", "bad").field == "name"  # fail returns, does not raise


@pytest.mark.parametrize(("read", "field", "message"), [
    (lambda t: t.number("nothing"), "nothing", "missing number"),
    (lambda t: t.number("flag"), "flag", "must be a number"),
    (lambda t: t.number("name"), "name", "must be a number"),
    (lambda t: t.number("huge"), "huge", "must be finite"),
    (lambda t: t.number("speed", positive=True, maximum=2.0), "speed", "must be ≤ 2.0"),
    (lambda t: t.number("speed", minimum=3.0), "speed", "must be ≥ 3.0"),
    (lambda t: t.number("missing", -1.0, positive=True), "missing", "must be > 0"),
    (lambda t: t.optional_number("speed", maximum=1.0), "speed", "must be ≤ 1.0"),
    (lambda t: t.integer("nothing"), "nothing", "missing integer"),
    (lambda t: t.integer("speed"), "speed", "must be an integer"),
    (lambda t: t.integer("flag"), "flag", "must be an integer"),
    (lambda t: t.integer("count", minimum=4), "count", "must be ≥ 4"),
    (lambda t: t.string("nothing"), "nothing", "missing string"),
    (lambda t: t.string("count"), "count", "must be a string"),
    (lambda t: t.string("name", choices=("a", "b")), "name", r"'demo' is not one of \['a', 'b'\]"),
    (lambda t: t.boolean("count", True), "count", "must be true or false"),
    (lambda t: t.table("nothing", required=True), "nothing", "missing table"),
    (lambda t: t.table("name"), "name", "must be a table, got str"),
])
def test_bad_values_name_the_key(read: object, field: str, message: str) -> None:
    """Missing, mistyped, non-finite and out-of-range values raise a ParseError with the key."""
    err = failure(lambda: read(table()))  # type: ignore[operator]
    assert err.field == field
    assert re.search(message, err.reason), err.reason


def test_absent_optional_table_is_empty() -> None:
    """An absent sub-table that is not required reads as empty, with its own dotted name."""
    empty = table().table("absent")
    assert not empty.has("x") and empty.number("x", 1.5) == 1.5
    empty.done()
    assert empty.key("x") == "absent.x"


def test_done_reports_the_first_unread_key() -> None:
    """done() names the first key (alphabetically) never read and lists the known ones; once
    every key is read it passes."""
    t = table()
    t.string("name")
    t.integer("count")
    err = failure(t.done)
    assert err.field == "flag"
    assert "known here: ['count', 'name']" in err.reason
    for key in ("flag", "speed", "whole", "huge", "sub"):
        t.raw(key)
    t.done()
    assert math.isinf(t.raw("huge"))
