"""``--export``: optw solve and mission run write autopilot missions and GeoJSON; a problem
without a geographic frame needs --origin, asked for before any work."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from searchtrack.cli import main
from searchtrack.cli.export import parse_origin
from searchtrack.core.errors import InvalidInputError

DATA = Path(__file__).parents[2] / "searchtrack" / "data"


def test_optw_solve_exports_with_an_origin(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "ex"
    assert main(["optw", "solve", str(DATA / "optw" / "c101.txt"), "--vehicles", "2",
                 "--time-limit", "1", "--export", str(out), "--origin", "21.88,-102.29",
                 "--unit-m", "10", "--altitude", "90"]) == 0
    assert "wrote" in capsys.readouterr().out
    assert sorted(p.name for p in out.iterdir()) == [
        "plan.geojson", "plan.html", "route0.plan", "route0.waypoints", "route1.plan",
        "route1.waypoints"]
    plan = json.loads((out / "route0.plan").read_text(encoding="utf-8"))
    assert plan["mission"]["items"][1]["Altitude"] == 90.0
    assert (out / "route0.waypoints").read_text(encoding="utf-8").startswith("QGC WPL 110\n")


@pytest.mark.parametrize(("extra", "said"), [
    ([], "--origin is needed"),
    (["--origin", "200,0"], "--origin"),
    (["--origin", "21.88,-102.29", "--altitude", "-5"], "--altitude"),
])
def test_optw_export_refuses_before_solving(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                            extra: list[str], said: str) -> None:
    out = tmp_path / "ex"
    code = _exit(["optw", "solve", str(DATA / "optw" / "c101.txt"), "--time-limit", "5",
                  "--export", str(out), *extra])
    captured = capsys.readouterr()
    assert code == 2 and said in captured.err and "objective" not in captured.out
    assert not out.exists()


def test_mission_on_an_osm_map_exports_in_its_own_frame(tmp_path: Path) -> None:
    out = tmp_path / "m"
    assert main(["mission", "run", str(DATA / "scenarios" / "demo.toml"), "--duration", "3",
                 "--out", str(out), "--export", str(out / "export")]) == 0
    names = sorted(p.name for p in (out / "export").iterdir())
    assert "plan.geojson" in names and "uav0.plan" in names and "uav0.waypoints" in names
    home = json.loads((out / "export" / "uav0.plan").read_text(encoding="utf-8"))
    lat, lon, _ = home["mission"]["plannedHomePosition"]
    assert 21.7 < lat < 22.0 and -102.4 < lon < -102.2      # Aguascalientes


def _exit(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exc:   # argparse refuses bad option values itself
        return int(exc.code or 0)


def test_radio_mission_needs_an_origin_before_flying(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    scenario = tmp_path / "s.toml"
    scenario.write_text("duration_s = 3.0\n", encoding="utf-8")
    code = _exit(["radio", "mission", str(scenario), "--particles", "50", "--out",
                  str(tmp_path / "m"), "--export", str(tmp_path / "x")])
    assert code == 2 and "--origin is needed" in capsys.readouterr().err
    assert not (tmp_path / "m" / "mission.json").exists()
    assert main(["radio", "mission", str(scenario), "--particles", "50", "--plan-particles",
                 "20", "--horizon", "1", "--out", str(tmp_path / "m"), "--export",
                 str(tmp_path / "x"), "--origin=-35,149"]) == 0
    assert sorted(p.name for p in (tmp_path / "x").iterdir()) == [
        "plan.geojson", "plan.html", "uav0.plan", "uav0.waypoints"]


def _flown_altitudes(folder: Path) -> set[float]:
    """The altitudes of the exported UAV's flown items: those of ``uav0.plan`` with one, and
    column 11 of ``uav0.waypoints`` in the mission frame (3, relative to home)."""
    plan = json.loads((folder / "uav0.plan").read_text(encoding="utf-8"))
    heights = {item["Altitude"] for item in plan["mission"]["items"] if item["Altitude"]}
    rows = [line.split("\t") for line in
            (folder / "uav0.waypoints").read_text(encoding="utf-8").splitlines()[1:]]
    return heights | {float(row[10]) for row in rows if row[2] == "3"}


def test_radio_mission_exports_at_the_scenarios_height(tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    """Without --altitude the radio UAV's path is exported at the height the scenario flies it
    above the tags; --altitude overrides it, and the help says so."""
    scenario = tmp_path / "s.toml"
    scenario.write_text("duration_s = 3.0\n[signal]\nheight_difference_m = 37.0\n",
                        encoding="utf-8")
    base = ["radio", "mission", str(scenario), "--particles", "50", "--plan-particles", "20",
            "--horizon", "1", "--origin=-35,149"]
    assert main([*base, "--out", str(tmp_path / "m"), "--export", str(tmp_path / "own")]) == 0
    assert _flown_altitudes(tmp_path / "own") == {37.0}
    assert main([*base, "--out", str(tmp_path / "n"), "--export", str(tmp_path / "given"),
                 "--altitude", "45"]) == 0
    assert _flown_altitudes(tmp_path / "given") == {45.0}
    capsys.readouterr()
    assert _exit(["radio", "mission", "--help"]) == 0
    assert "height_difference_m" in " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize("family", ["assign", "route", "trajectory", "search"])
def test_plan_families_export_their_paths(tmp_path: Path, family: str) -> None:
    """Each family that moves vehicles exports one mission per vehicle that pymavlink reads and
    a valid GeoJSON; its first waypoint after home lies where the path goes next."""
    mavwp = pytest.importorskip("pymavlink.mavwp", reason="pymavlink (the test extra)")
    geojson = pytest.importorskip("geojson", reason="the geojson library (the test extra)")
    out = tmp_path / "x"
    problem = Path(__file__).parents[2] / "examples" / "problems" / f"{family}.json"
    assert main(["plan", family, str(problem), "--out", str(tmp_path / "p.json"), "--export",
                 str(out), "--origin", "21.88,-102.29", "--time-limit", "5"]) == 0
    plans = sorted(out.glob("*.waypoints"))
    assert plans and (out / "plan.geojson").is_file()
    for path in plans:
        loader = mavwp.MAVWPLoader()
        assert loader.load(str(path)) >= 4       # home, take-off, a waypoint, return
        assert all(21.0 < loader.wp(k).x < 23.0 for k in range(loader.count() - 1))
    assert geojson.loads((out / "plan.geojson").read_text(encoding="utf-8")).is_valid


def test_an_association_exports_nothing(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    problem = Path(__file__).parents[2] / "examples" / "problems" / "associate.json"
    assert main(["plan", "associate", str(problem), "--out", str(tmp_path / "p.json"),
                 "--export", str(tmp_path / "x"), "--origin", "21.88,-102.29"]) == 0
    assert "nothing to export" in capsys.readouterr().out
    assert not (tmp_path / "x").exists() or not any((tmp_path / "x").iterdir())


def test_plan_export_asks_for_an_origin_before_solving(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    problem = Path(__file__).parents[2] / "examples" / "problems" / "assign.json"
    out = tmp_path / "p.json"
    assert _exit(["plan", "assign", str(problem), "--out", str(out), "--export",
                  str(tmp_path / "x")]) == 2
    assert "--origin is needed" in capsys.readouterr().err and not out.exists()


def test_parse_origin() -> None:
    assert parse_origin("21.88,-102.29") == (21.88, -102.29)
    for bad in ("21.88", "a,b", "91,0", "0,181", "nan,0", "1,2,3"):
        with pytest.raises(InvalidInputError, match="--origin"):
            parse_origin(bad)
