"""Typed reads from a parsed JSON document: good values come back, bad ones raise naming the
file and the dotted field."""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from pathlib import Path
from types import MappingProxyType
from typing import Any

import pytest

from searchtrack.core.errors import ParseError
from searchtrack.core.fields import TOP_LEVEL, JsonFields, shown

SOURCE = Path("job.json")


def _refused(call: Callable[[], object], field: str, reason: str) -> ParseError:
    """The ParseError ``call`` raises, checked to name the file, ``field`` and ``reason``."""
    with pytest.raises(ParseError) as err:
        call()
    assert err.value.path == str(SOURCE) and err.value.field == field
    assert reason in err.value.reason, err.value.reason
    return err.value


def test_fail_names_the_source_and_field() -> None:
    """fail() builds a ParseError for the source and field, without a line."""
    err = JsonFields("mission record").fail("map.edges", "bad")
    assert str(err) == "mission record, field 'map.edges': bad" and err.line is None


def test_obj_accepts_objects_and_refuses_the_rest() -> None:
    """obj() returns a dict (a mapping copied into one) and refuses lists and strings."""
    f = JsonFields(SOURCE)
    value = {"a": 1}
    assert f.obj(value, "sensor") is value
    assert f.obj(MappingProxyType(value), "sensor") == value
    for bad in ([1], "a", None):
        _refused(partial(f.obj, bad, "sensor"), "sensor", "must be a JSON object, got")


@pytest.mark.parametrize(("field", "named"), [
    (TOP_LEVEL, "zeta"), ("sensor", "sensor.zeta"), ("frames[2]", "frames[2].zeta")])
def test_unknown_keys_are_named_with_their_dotted_path(field: str, named: str) -> None:
    """The first unknown key (sorted) is named under the object's field, bare at the top."""
    f = JsonFields(SOURCE)
    value = {"pd": 1, "zeta": 2, "zz": 3}
    err = _refused(lambda: f.obj(value, field, ("pd", "sigma")), named,
                   "unknown key; expected one of ['pd', 'sigma']")
    assert err.reason == "unknown key; expected one of ['pd', 'sigma']"
    assert f.obj({"pd": 1}, field, ("pd", "sigma")) == {"pd": 1}
    _refused(lambda: f.check_keys(value, field, ("pd",), unknown="unknown key for model 'cv'"),
             named, "unknown key for model 'cv'; expected one of ['pd']")


def test_get_names_the_missing_key() -> None:
    """get() returns the value, or names the prefixed key that is missing."""
    f = JsonFields(SOURCE)
    assert f.get({"pd": None}, "pd") is None
    _refused(lambda: f.get({}, "pd", "sensor."), "sensor.pd", "missing key")


@pytest.mark.parametrize("value", [0, 2.5, -1e300, 10**20])
def test_number_accepts_finite_numbers(value: float) -> None:
    """Integers and floats come back as floats."""
    out = JsonFields(SOURCE).number(value, "dt")
    assert isinstance(out, float) and out == float(value)


@pytest.mark.parametrize(("value", "reason"), [
    (True, "must be a number, got True"), (False, "must be a number, got False"),
    ("1", "must be a number, got '1'"), (None, "must be a number, got None"),
    ([1.0], "must be a number, got [1.0]"),
    (math.nan, "must be finite, got nan"), (math.inf, "must be finite, got inf"),
    (-math.inf, "must be finite, got -inf"), (10**400, "must be finite, got 1000"),
])
def test_number_refuses_bools_text_and_non_finite_values(value: object, reason: str) -> None:
    """A bool is not a number; NaN, ±inf and integers beyond the float range are not finite."""
    _refused(lambda: JsonFields(SOURCE).number(value, "sensor.pd"), "sensor.pd", reason)


def test_number_bounds_open_and_closed() -> None:
    """Ends are included unless open; the message spells the interval."""
    f = JsonFields(SOURCE)
    assert f.number(0, "x", low=0.0, high=1.0) == 0.0
    assert f.number(1, "x", low=0.0, high=1.0) == 1.0
    _refused(lambda: f.number(0, "x", low=0.0, low_open=True, high=1.0), "x",
             "must be in (0, 1], got 0")
    _refused(lambda: f.number(1, "x", low=0.0, high=1.0, high_open=True), "x",
             "must be in [0, 1), got 1")
    _refused(lambda: f.number(-0.5, "x", low=0.0), "x", "must be in [0, inf], got -0.5")


def test_reader_defaults_and_message_style() -> None:
    """A reader's own bounds apply when a call gives none; finite_in_range joins the reasons;
    shown_chars shortens the value shown."""
    f = JsonFields(SOURCE, low=0.0, high=10.0, finite_in_range=True)
    assert f.number(10, "x") == 10.0
    _refused(lambda: f.number(-1, "x"), "x", "must be a finite number in [0, 10], got -1")
    _refused(lambda: f.number(math.nan, "x"), "x", "must be a finite number in [0, 10], got nan")
    assert f.number(-1, "x", low=-2.0) == -1.0
    short = JsonFields(SOURCE, shown_chars=10)
    err = _refused(lambda: short.number("abcdefghijklmnop", "x"), "x", "must be a number")
    assert err.reason == "must be a number, got 'abcdef..."
    assert shown("abc", 5) == "'abc'" and shown("abcd", 5) == "'a..."


def test_integer_accepts_integers_in_range_only() -> None:
    """integer() refuses bools, floats and values outside [low, high]."""
    f = JsonFields(SOURCE)
    assert f.integer(3, "seed", 0, 3) == 3
    for bad in (True, 2.0, "2", -1, 4, None):
        _refused(partial(f.integer, bad, "seed", 0, 3), "seed",
                 "must be an integer in [0, 3], got")


def test_text_accepts_strings_only() -> None:
    """text() returns a string and names the type of anything else."""
    f = JsonFields(SOURCE)
    assert f.text("cv", "motion.model") == "cv"
    _refused(lambda: f.text(3, "motion.model"), "motion.model", "must be a string, got int")


@pytest.mark.parametrize(("value", "allow_empty", "reason"), [
    ([], False, "must be a non-empty list of scans"),
    ({"a": 1}, False, "must be a non-empty list of scans"),
    ("ab", True, "must be a list of scans"),
])
def test_items_refuses_non_lists_and_empty_lists(value: Any, allow_empty: bool,
                                                 reason: str) -> None:
    """items() returns a list (an empty one only when allowed) and says what it wanted."""
    f = JsonFields(SOURCE)
    assert f.items([1, 2], "scans", "scans") == [1, 2]
    assert f.items([], "scans", "scans", allow_empty=True) == []
    err = _refused(lambda: f.items(value, "scans", "scans", allow_empty=allow_empty), "scans",
                   reason)
    assert err.reason == reason
