"""``searchtrack fleet-size``: the table, the answer, ``--json``, and exit statuses 0 / 1 / 2."""

from __future__ import annotations

import argparse
import io
import json
from pathlib import Path

import pytest
from rich.console import Console

from searchtrack.cli import fleet
from searchtrack.sim.roads.scenario import MapSpec


def _console() -> tuple[Console, io.StringIO]:
    text = io.StringIO()
    return Console(file=text, width=200), text


def test_three_by_three_needs_three_uavs(tmp_path: Path) -> None:
    """10 targets and 16 m² on the 3 × 3 map with 100 m blocks: 3 UAVs, status 0, JSON whole."""
    console, text = _console()
    out = tmp_path / "sub" / "fleet.json"
    assert fleet.run(["--map", "grid:3x3", "--targets", "10", "--max-variance", "16", "--json",
                      str(out)], console) == 0
    shown = text.getvalue()
    assert "3 UAVs" in shown and "B_L" in shown and "177.78" in shown
    record = json.loads(out.read_text(encoding="utf-8"))
    assert record["uavs"] == 3
    assert [row["meets"] for row in record["rows"][:3]] == [False, False, True]
    assert record["rows"][0]["bound"] == pytest.approx(3.54, abs=0.01)
    assert record["required_entropy"] == pytest.approx(2.805, abs=1e-3)
    assert record["config"]["targets"] == 10


def test_no_fleet_meets_the_requirement(tmp_path: Path) -> None:
    """With at most 2 UAVs nothing meets 16 m²: status 1, and the JSON says ``null``."""
    console, text = _console()
    out = tmp_path / "f.json"
    assert fleet.run(["--map", "grid:3x3:100", "--targets", "10", "--max-variance", "16",
                      "--max-uavs", "2", "--json", str(out)], console) == 1
    assert "no fleet of up to 2 UAVs" in text.getvalue()
    assert json.loads(out.read_text(encoding="utf-8"))["uavs"] is None


def test_options_reach_the_bound() -> None:
    """Speeds, noise, step and binning options change the table."""
    base, text_a = _console()
    other, text_b = _console()
    args = ["--map", "grid:2x3:50", "--targets", "3", "--max-variance", "30"]
    assert fleet.run(args, base) == 0
    assert fleet.run([*args, "--uav-speed", "20", "--target-speed", "5", "--sigma-v", "2",
                      "--R", "3", "--dt", "0.2", "--binning", "mass"], other) == 0
    assert text_a.getvalue() != text_b.getvalue()


def test_bundled_map_by_name() -> None:
    """A bundled OpenStreetMap extract is sized by name."""
    console, text = _console()
    code = fleet.run(["--map", "West-Oakland", "--targets", "2", "--max-variance", "1000",
                      "--max-uavs", "3"], console)
    assert code in (0, 1)
    assert "West-Oakland" in text.getvalue()


@pytest.mark.parametrize("argv", [
    ["--map", "grid:3x", "--targets", "3", "--max-variance", "16"],
    ["--map", "grid:1x3", "--targets", "3", "--max-variance", "16"],
    ["--map", "grid:3x3:-5", "--targets", "3", "--max-variance", "16"],
    ["--map", "grid:3x3:nan", "--targets", "3", "--max-variance", "16"],
    ["Atlantis", "--targets", "3", "--max-variance", "16"],
    ["--map", "grid:3x3", "--targets", "1", "--max-variance", "16"],
    ["--map", "grid:3x3", "--targets", "0", "--max-variance", "16"],
    ["--map", "grid:3x3", "--targets", "x", "--max-variance", "16"],
    ["--map", "grid:3x3", "--targets", "3", "--max-variance", "0"],
    ["--map", "grid:3x3", "--targets", "3", "--max-variance", "nan"],
    ["--map", "grid:3x3", "--targets", "3", "--max-variance", "inf"],
    ["--map", "grid:3x3", "--targets", "3", "--max-variance", "0.1"],
    ["--map", "grid:3x3", "--targets", "3", "--max-variance", "16", "--max-uavs", "0"],
    ["--map", "grid:3x3", "--targets", "3", "--max-variance", "16", "--dt", "-1"],
    ["--map", "grid:3x3", "--targets", "3", "--max-variance", "16", "--dt", "1e9"],
    ["--map", "grid:3x3", "--targets", "3", "--max-variance", "16", "--R", "0.001"],
    ["--map", "grid:3x3", "--targets", "3", "--max-variance", "16", "--binning", "pdf"],
    ["--map", "grid:3x3", "--targets", "3"],
])
def test_bad_input_exits_2(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """Bad maps, counts, requirements and options exit with status 2 and a message."""
    console, _ = _console()
    assert fleet.run(argv, console) == 2
    assert "error" in capsys.readouterr().err


def test_json_path_checked_before_work(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                       ) -> None:
    """``--json`` naming a folder fails at once with status 2, naming the option."""
    console, text = _console()
    assert fleet.run(["--map", "grid:3x3", "--targets", "3", "--max-variance", "16", "--json",
                      str(tmp_path)], console) == 2
    assert "--json" in capsys.readouterr().err
    assert "UAV" not in text.getvalue()


def test_registers_as_a_subcommand() -> None:
    """``add_parser`` registers ``fleet-size`` whose handler the top-level command calls."""
    parser = argparse.ArgumentParser(prog="searchtrack")
    sub = parser.add_subparsers(dest="group", required=True)
    fleet.add_parser(sub)
    args = parser.parse_args(["fleet-size", "--map", "grid:3x3", "--targets", "10",
                              "--max-variance", "16"])
    console, text = _console()
    assert args.run(args, console) == 0
    assert "3 UAVs" in text.getvalue()


def test_map_argument() -> None:
    """``grid:RxC[:BLOCK]`` puts nodes at the intersections only; names give OSM maps."""
    spec = fleet.map_arg("grid:4x5:65")
    assert (spec.kind, spec.rows, spec.cols, spec.block_m, spec.spacing_m) == (
        "grid", 4, 5, 65.0, 65.0)
    assert fleet.map_arg("grid:3x3").block_m == 100.0
    assert fleet.map_arg("aguascalientes").kind == "osm"
    assert isinstance(fleet.map_arg("grid:2x2"), MapSpec)
    for bad in ("grid:3", "grid:0x3", "grid:3x3:0", "grid:3x3:1e400", "grid:3x3:x", "osm"):
        with pytest.raises(argparse.ArgumentTypeError):
            fleet.map_arg(bad)


def test_a_stop_request_exits_130_and_writes_what_was_done(tmp_path: Path) -> None:
    from searchtrack.core.interrupt import clear_stop, request_stop

    console, text = _console()
    out = tmp_path / "fleet.json"
    request_stop()
    try:
        code = fleet.run(["--map", "grid:3x3", "--targets", "10", "--max-variance", "16",
                          "--json", str(out)], console)
    finally:
        clear_stop()
    assert code == 130 and "stopped after 0 fleet sizes" in text.getvalue()
    assert json.loads(out.read_text(encoding="utf-8"))["rows"] == []
