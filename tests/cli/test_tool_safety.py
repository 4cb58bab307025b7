"""``fleet-size``, ``rl evaluate``, ``mission view`` and ``plan trajectory --backend nmpc`` fail
safe: the probes of :mod:`tests.cli.probes_tools` are answered with one line and the right
status; the first Ctrl-C stops ``fleet-size`` and an NMPC flight within a couple of seconds
(status 130, the result so far written as interrupted), and Ipopt stops at its next iteration;
junk policy files, plan problems, road detections and mission records never raise a traceback.
"""

from __future__ import annotations

import copy
import io
import json
import signal
import subprocess
import sys
import time
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from searchtrack.cli.plan import available_families
from searchtrack.core.interrupt import request_stop
from searchtrack.core.result import Status
from tests.cli.probes_tools import SHIPPED_POLICY, shipped_meta
from tests.cli.runs import run_main, run_on_file

EXAMPLES = Path(__file__).parents[2] / "examples" / "problems"

#: Seconds from SIGINT to exit: the loops check the stop flag within a fraction of a second,
#: the rest is writing the result and leaving the interpreter on a busy machine.
STOP_S = 3.0


# ---- Ctrl-C


def _interrupt(argv: list[str], after_s: float) -> tuple[int, float, str]:
    """Run ``searchtrack argv``, send one SIGINT after ``after_s`` seconds; the exit status,
    the seconds from SIGINT to exit, and stderr (the run is killed when it ignores SIGINT)."""
    proc = subprocess.Popen([sys.executable, "-m", "searchtrack.cli", *argv],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        time.sleep(after_s)
        assert proc.poll() is None, f"finished before the interrupt: {proc.communicate()}"
        sent = time.perf_counter()
        proc.send_signal(signal.SIGINT)
        try:
            _, err = proc.communicate(timeout=STOP_S + 5.0)
        except subprocess.TimeoutExpired:
            pytest.fail(f"still running {STOP_S + 5.0:g} s after SIGINT: {argv}")
        return proc.returncode, time.perf_counter() - sent, err
    finally:
        proc.kill()
        proc.communicate()


def test_fleet_size_stops_on_the_first_ctrl_c(tmp_path: Path) -> None:
    """A 100 × 100 grid sized up to 1000 UAVs runs for many seconds; one SIGINT ends it with
    status 130 within seconds, its JSON (if the map was measured) marked interrupted."""
    out = tmp_path / "fleet.json"
    code, waited, err = _interrupt(["fleet-size", "--map", "grid:100x100", "--targets", "10",
                                    "--max-variance", "16", "--max-uavs", "1000", "--json",
                                    str(out)], after_s=4.0)
    assert code == 130, err
    assert waited < STOP_S, f"{waited:.1f} s from SIGINT to exit"
    assert "Traceback" not in err and "interrupted" in err
    record = json.loads(out.read_text(encoding="utf-8"))
    assert record["interrupted"] is True and len(record["rows"]) < 1000


def _long_course(path: Path) -> Path:
    """A unicycle course of about 1250 control steps (NMPC flies it in about ten seconds)."""
    legs = [[0, 0], [400, 0], [400, 300], [0, 300], [0, 600], [400, 600], [400, 900], [0, 900]]
    path.write_text(json.dumps({
        "vehicle": "unicycle", "waypoints": legs + [[x, y + 900] for x, y in legs[1:]],
        "speed_mps": 10.0, "dt_s": 0.2, "horizon": 30,
        "obstacles": [{"center": [200, 3], "radius_m": 8}, {"center": [200, 303], "radius_m": 8}],
    }), encoding="utf-8")
    return path


def test_nmpc_flight_stops_on_the_first_ctrl_c(tmp_path: Path) -> None:
    """``plan trajectory --backend nmpc`` on SIGINT: status 130 within seconds and PLAN.json
    INTERRUPTED with the flight so far."""
    out = tmp_path / "plan.json"
    code, waited, err = _interrupt(["plan", "trajectory", str(_long_course(tmp_path / "c.json")),
                                    "--backend", "nmpc", "--time-limit", "600", "--out",
                                    str(out)], after_s=5.0)
    assert code == 130, err
    assert waited < STOP_S, f"{waited:.1f} s from SIGINT to exit"
    record = json.loads(out.read_text(encoding="utf-8"))
    assert record["status"] == "INTERRUPTED" and "interrupted after" in record["message"]
    assert record["plan"]["flown"] and 1 < len(record["plan"]["times_s"]) < 2500


def test_ipopt_stops_at_its_next_iteration() -> None:
    """A stop request ends an NMPC solve inside Ipopt (its iteration callback): INTERRUPTED
    after no iteration, with the feasible starting iterate as the plan."""
    from searchtrack.plan.trajectory import TrackingProblem, solve_nmpc
    from searchtrack.sim.jobs.trajectory import read_problem

    job = read_problem(EXAMPLES / "trajectory.json")
    problem = TrackingProblem(job.model, job.start, job.reference, obstacles=job.obstacles,
                              horizon=job.horizon, dt_s=job.dt_s)
    assert solve_nmpc(problem, time_limit_s=5.0).status is Status.FEASIBLE
    request_stop()
    result = solve_nmpc(problem, time_limit_s=5.0)
    assert result.status is Status.INTERRUPTED and "stopped on request" in result.message
    assert result.stats["iterations"] == 0 and result.plan is not None


# ---- junk

FAST = settings(max_examples=12, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture])

junk = st.one_of(st.binary(max_size=200), st.text(max_size=200))
LEAVES = [None, True, False, -1, 0, 1, 2.5, 1e300, -1e300, float("nan"), float("inf"), "", "x",
          [], {}, [1, 2], [[1e300, 0]], {"x": 1}, 10**30]


def _paths(doc: Any, here: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Paths to the nodes of a JSON document (the first two items of each list)."""
    out = [here] if here else []
    if isinstance(doc, dict):
        for key, value in doc.items():
            out += _paths(value, (*here, key))
    elif isinstance(doc, list):
        for i, value in enumerate(doc[:2]):
            out += _paths(value, (*here, i))
    return out


@st.composite
def mutated(draw: st.DrawFn, base: Any) -> Any:
    """``base`` with one to three nodes replaced by odd values, deleted, or given an unknown
    neighbour."""
    doc = copy.deepcopy(base)
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(doc)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent: Any = doc
        for key in path[:-1]:
            parent = parent[key]
        action = draw(st.sampled_from(["set", "set", "delete", "add"]))
        leaf = copy.deepcopy(draw(st.sampled_from(LEAVES)))
        if action == "set":
            parent[path[-1]] = leaf
        elif action == "delete":
            del parent[path[-1]]
        elif isinstance(parent, dict):
            parent["bogus"] = leaf
        else:
            parent.append(leaf)
    return doc


def _document(base: Any) -> st.SearchStrategy[str | bytes]:
    """Junk, or ``base`` mutated, as JSON text."""
    return st.one_of(junk, mutated(base).map(json.dumps))


def _run(argv: Callable[[Path, Path], list[str]], name: str, data: str | bytes) -> None:
    assert run_on_file(argv, name, data) in (0, 1, 2)


@st.composite
def policy_archive(draw: st.DrawFn) -> bytes:
    """An ``.npz`` archive: the shipped policy with a mutated meta or odd arrays, sometimes
    cut short."""
    with np.load(SHIPPED_POLICY, allow_pickle=False) as data:
        arrays: dict[str, Any] = {name: data[name] for name in data.files}
    arrays["meta"] = np.array(json.dumps(draw(mutated(shipped_meta()))))
    for _ in range(draw(st.integers(0, 2))):
        name = draw(st.sampled_from(["meta", "w0", "b1", "w2", "w3", "x"]))
        shape = tuple(draw(st.lists(st.integers(0, 4), max_size=3)))
        dtype = draw(st.sampled_from(["<f8", "<f4", "|i1", "|b1", "<c8", "<U3"]))
        if draw(st.booleans()):
            arrays.pop(name, None)
        else:
            arrays[name] = np.zeros(shape, dtype=dtype)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as archive:  # np.savez's layout
        for name, value in arrays.items():
            member = io.BytesIO()
            np.save(member, value, allow_pickle=False)
            archive.writestr(f"{name}.npy", member.getvalue())
    packed = buf.getvalue()
    return packed[:draw(st.integers(0, len(packed)))] if draw(st.booleans()) else packed


def _evaluate(p: Path, t: Path) -> list[str]:
    return ["rl", "evaluate", "--policy", str(p), "--episodes", "1", "--duration", "1"]


@FAST
@given(st.one_of(junk.map(lambda d: d.encode("utf-8", "surrogatepass")
                          if isinstance(d, str) else d), policy_archive()))
def test_policy_file_junk(data: bytes) -> None:
    """Junk and damaged policy files (meta fields and arrays): answered, never a traceback."""
    _run(_evaluate, "p.npz", data)


PROBLEMS = {family: json.loads((EXAMPLES / f"{family}.json").read_text(encoding="utf-8"))
            for family in available_families()}


@pytest.mark.parametrize("family", sorted(PROBLEMS))
def test_plan_problem_junk(family: str) -> None:
    """Junk and mutated PROBLEM.json files of every ``plan`` family: answered, never a
    traceback."""
    backend = "closed_form" if family == "trajectory" else "auto"

    @settings(max_examples=8, deadline=None)
    @given(_document(PROBLEMS[family]))
    def check(data: str | bytes) -> None:
        _run(lambda p, t: ["plan", family, str(p), "--out", str(t / "plan.json"), "--backend",
                           backend, "--time-limit", "0.2"], "p.json", data)

    check()


def _short_detections() -> dict[str, Any]:
    """The example road detections cut to 20 steps with a small filter (a valid mutation
    runs in a moment)."""
    doc: dict[str, Any] = json.loads((EXAMPLES / "road_detections.json").read_text("utf-8"))
    doc["uav_xy"], doc["detections"] = doc["uav_xy"][:20], doc["detections"][:20]
    doc["filter"] = {"histories": 2, "particles": 50}
    return doc


@FAST
@given(_document(_short_detections()))
def test_road_detections_junk(data: str | bytes) -> None:
    """Junk and mutated DETECTIONS.json files for ``track-roads``: answered, never a
    traceback."""
    _run(lambda p, t: ["track-roads", str(p), "--out", str(t / "e.json")], "d.json", data)


#: The smallest mission record ``mission view`` draws: one step on a one-road map.
RECORD = {"scenario": {"name": "x", "strategy": "s", "map": "m"}, "summary": {}, "time_s": [0.1],
          "moc": [0.5], "trackers": [1], "valid_trackers": [1], "valid_associations": [0],
          "false_associations": [0], "map": {"nodes_xy_m": [[0, 0], [1, 0]], "edges": [[0, 1]]},
          "uav_xy_m": [[[0, 0]], [[1, 0]]], "target_xy_m": [[[0, 0]], [[1, 0]]],
          "tracks": [[[0, 1, 0.5]]],
          "heat": {"frames": [{"step": 0, "llr": {"nodes": [0], "values": [1.0]},
                               "trackers": {"nodes": [1], "values": [0.5]}}]}}


def test_the_smallest_record_is_drawn(tmp_path: Path) -> None:
    """The record the junk below mutates is a valid one."""
    path = tmp_path / "m.json"
    path.write_text(json.dumps(RECORD), encoding="utf-8")
    assert run_main(["mission", "view", str(path), "--out", str(tmp_path / "r.html")]) == 0


@FAST
@given(_document(RECORD))
def test_mission_record_junk(data: str | bytes) -> None:
    """Junk and mutated mission records for ``mission view``: answered, never a traceback."""
    _run(lambda p, t: ["mission", "view", str(p), "--out", str(t / "r.html")], "m.json", data)
