"""Generated junk in every file format the commands read: a one-line answer and exit status 2
(or a plan when the junk happens to be valid), never a traceback."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.cli.runs import run_on_file

C101 = Path(__file__).parents[2] / "searchtrack" / "data" / "optw" / "c101.txt"

# Junk: raw bytes, text, text that resembles each format (numbers and its separators).
numberish = st.text(alphabet="0123456789.-e \n\tnaif", max_size=300)
junk = st.one_of(st.binary(max_size=300), st.text(max_size=300), numberish)
json_junk = st.one_of(junk, st.recursive(
    st.none() | st.booleans() | st.floats(allow_nan=False) | st.text(max_size=5),
    lambda kids: st.lists(kids, max_size=4) | st.dictionaries(
        st.sampled_from(["area", "dt", "sensor", "motion", "scans", "pd", "sigma", "q",
                         "model", "clutter_rate", "x"]), kids, max_size=5),
    max_leaves=20).map(json.dumps))
toml_junk = st.one_of(junk, st.lists(st.sampled_from(
    ["[map]", "grid = { rows = 3, cols = 3 }", "[uavs]", "count = 0", "count = 2", "[sensor]",
     "pd = 2", "duration_s = -1", "dt_s = 1e400", "osm = \"x\"", "seed = -4", "[targets]",
     "name = 3", "mode = \"fly\"", "x = ["]), max_size=8).map("\n".join))
csv_junk = st.one_of(junk, st.lists(st.sampled_from(
    ["instance,optimum", "c101,320", "c101,", "c101,abc", "c101,nan", ",,", "a,b,c"]),
    max_size=5).map("\n".join))


def _run(argv: Callable[[Path, Path], list[str]], name: str, data: str | bytes) -> None:
    assert run_on_file(argv, name, data) in (0, 1, 2)


FAST = settings(max_examples=40, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture])


@FAST
@given(junk)
def test_optw_instance_junk(data: str | bytes) -> None:
    """Junk as an OPTW instance file."""
    _run(lambda p, t: ["optw", "solve", str(p), "--time-limit", "0.05", "--backend", "ils"],
         "x.txt", data)


@FAST
@given(toml_junk)
def test_scenario_junk(data: str | bytes) -> None:
    """Junk as a mission scenario (TOML)."""
    _run(lambda p, t: ["mission", "run", str(p), "--out", str(t / "o"), "--duration", "0.6"],
         "s.toml", data)


@FAST
@given(json_junk)
def test_scans_junk(data: str | bytes) -> None:
    """Junk as a SCANS.json recording."""
    _run(lambda p, t: ["track", str(p), "--out", str(t / "e.json"), "--particles", "200"],
         "s.json", data)


def _optima_argv(p: Path, t: Path) -> list[str]:
    (t / "c101.txt").write_text(C101.read_text(encoding="utf-8"), encoding="utf-8")
    p.rename(t / "optima.csv")
    return ["optw", "bench", str(t), "--time-limit", "0.05", "--backend", "ils"]


@FAST
@given(csv_junk)
def test_optima_junk(data: str | bytes) -> None:
    """Junk as the optima table beside a benchmark set."""
    _run(_optima_argv, "optima.tmp", data)


@pytest.mark.parametrize("data", ["\r0", "instance,optimum\rc101,1\r", "a,\"b\rc\"\n\r"])
def test_optima_with_bare_carriage_returns(data: str) -> None:
    """Carriage returns inside or between fields (found by the fuzzer above): a clean answer,
    never the CSV module's error."""
    _run(_optima_argv, "optima.tmp", data)


@pytest.mark.parametrize("data", [b"", b"\x00" * 50, "\ufeff" + C101.read_text(encoding="utf-8")])
def test_edge_bytes(data: bytes | str) -> None:
    """Empty, NUL-filled and BOM-prefixed instance files are answered, not crashed on."""
    _run(lambda p, t: ["optw", "solve", str(p), "--time-limit", "0.05"], "x.txt", data)
