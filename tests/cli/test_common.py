"""Argument types shared by the subcommands: positive numbers, bounded integers and seeds."""

from __future__ import annotations

import argparse
import math

import pytest

from searchtrack.cli.common import float_in, int_at_least, int_in, positive_float, seed_arg
from searchtrack.core.registry import MAX_SEED


@pytest.mark.parametrize(("text", "expected"), [("2.5", 2.5), ("1e-3", 1e-3), ("7", 7.0),
                                                (" 3 ", 3.0), ("inf", math.inf)])
def test_positive_float_parses_positive_numbers(text: str, expected: float) -> None:
    """Decimal, exponent, integer and infinite spellings of a positive number become that float."""
    assert positive_float(text) == expected


@pytest.mark.parametrize(("text", "message"), [
    ("abc", "not a number: 'abc'"),
    ("", "not a number: ''"),
    ("0", "must be positive: '0'"),
    ("-1.5", "must be positive: '-1.5'"),
    ("nan", "must be positive: 'nan'"),
    ("-inf", "must be positive: '-inf'"),
])
def test_positive_float_refuses_the_rest(text: str, message: str) -> None:
    """Text, zero, negatives and NaN raise ArgumentTypeError quoting the text."""
    with pytest.raises(argparse.ArgumentTypeError) as err:
        positive_float(text)
    assert str(err.value) == message


@pytest.mark.parametrize(("low", "text", "expected"), [(1, "1", 1), (1, "40", 40), (0, "0", 0),
                                                       (-2, "-2", -2)])
def test_int_at_least_accepts_its_floor_and_above(low: int, text: str, expected: int) -> None:
    """The parser returns integers ≥ its floor unchanged, the floor itself included."""
    assert int_at_least(low)(text) == expected


@pytest.mark.parametrize(("text", "message"), [
    ("0", "must be ≥ 1: '0'"),
    ("2.5", "not an integer: '2.5'"),
    ("one", "not an integer: 'one'"),
])
def test_int_at_least_refuses_below_and_non_integers(text: str, message: str) -> None:
    """Below the floor, a decimal or a word raises ArgumentTypeError quoting the text."""
    with pytest.raises(argparse.ArgumentTypeError) as err:
        int_at_least(1)(text)
    assert str(err.value) == message


def test_argparse_reports_the_argument_and_the_reason(capsys: pytest.CaptureFixture[str]) -> None:
    """Used as ``type=``, a bad value makes argparse exit 2 naming the option and the reason."""
    parser = argparse.ArgumentParser(prog="searchtrack")
    parser.add_argument("--time-limit", type=positive_float)
    parser.add_argument("--runs", type=int_at_least(1))
    args = parser.parse_args(["--time-limit", "1.5", "--runs", "3"])
    assert (args.time_limit, args.runs) == (1.5, 3)
    with pytest.raises(SystemExit) as done:
        parser.parse_args(["--runs", "0"])
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert "--runs" in err and "must be ≥ 1: '0'" in err


@pytest.mark.parametrize(("text", "expected"), [("0", 0), ("3", 3), ("5", 5)])
def test_int_in_accepts_both_ends(text: str, expected: int) -> None:
    """int_in(0, 5) takes every integer of the closed range, its ends included."""
    assert int_in(0, 5)(text) == expected


@pytest.mark.parametrize(("text", "message"), [
    ("-1", "must be in [0, 5]: '-1'"),
    ("6", "must be in [0, 5]: '6'"),
    ("1.0", "not an integer: '1.0'"),
])
def test_int_in_names_the_range(text: str, message: str) -> None:
    """Outside the range or not an integer: ArgumentTypeError naming the range and the text."""
    with pytest.raises(argparse.ArgumentTypeError) as err:
        int_in(0, 5)(text)
    assert str(err.value) == message


def test_seed_arg_takes_what_every_backend_takes() -> None:
    """Seeds run from 0 to MAX_SEED = 2³¹ − 1; one more or a negative one is refused."""
    assert seed_arg("0") == 0 and seed_arg(str(MAX_SEED)) == 2**31 - 1
    for bad in (str(MAX_SEED + 1), "-1"):
        with pytest.raises(argparse.ArgumentTypeError, match=r"\[0, 2147483647\]"):
            seed_arg(bad)


def test_float_in_takes_its_interval_and_names_it() -> None:
    """Closed and open ends as asked; NaN, out-of-range and non-numbers are refused naming
    the interval (and the unit)."""
    half_open = float_in(0.0, 1.0, high_open=True)
    assert half_open("0") == 0.0 and half_open("0.999") == 0.999
    volts = float_in(0.0, 5.0, low_open=True, unit=" V")
    assert volts("5") == 5.0
    for parse, text, message in ((half_open, "1", r"must be in \[0, 1\)"),
                                 (half_open, "-0.1", r"must be in \[0, 1\)"),
                                 (half_open, "nan", r"must be in \[0, 1\)"),
                                 (volts, "0", r"must be in \(0, 5\] V"),
                                 (volts, "loud", "not a number")):
        with pytest.raises(argparse.ArgumentTypeError, match=message):
            parse(text)
