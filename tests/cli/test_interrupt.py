"""Ctrl-C (SIGINT) on a running command: it stops within seconds with status 130 and keeps what
was done — the best plan so far, the finished bench rows, the mission flown so far — written
whole; a second Ctrl-C aborts at once."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from searchtrack.plan.optw import OPTWInstance, write_optw

DATA = Path(__file__).parents[2] / "searchtrack" / "data"
OPTW = DATA / "optw"

#: Seconds a command may take to exit after SIGINT (the solvers stop within about a second; the
#: rest is writing output on a busy machine).
STOP_S = 15.0


def _wide_instance(path: Path) -> Path:
    """A wide-window instance the labelling DP cannot prove in a minute."""
    rng = np.random.default_rng(0)
    n = 200
    inst = OPTWInstance.from_coordinates(
        np.round(rng.uniform(0.0, 100.0, (n, 2)), 1),
        np.concatenate([[0.0], rng.integers(1, 10, n - 1)]), np.zeros(n), np.zeros(n),
        np.full(n, 400.0), decimals=1, start=0, end=0, tmax=400.0, name="wide")
    write_optw(inst, path)
    return path


def _interrupt(argv: list[str], after_s: float, signals: int = 1,
               gap_s: float = 0.2) -> tuple[int, float, str]:
    """Run ``searchtrack argv``, send SIGINT ``signals`` times (``gap_s`` apart) after
    ``after_s`` seconds; the exit status, the seconds from the first SIGINT to exit, and
    stderr."""
    proc = subprocess.Popen([sys.executable, "-m", "searchtrack.cli", *argv],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(after_s)
    assert proc.poll() is None, f"finished before the interrupt: {proc.communicate()}"
    sent = time.perf_counter()
    for _ in range(signals):
        proc.send_signal(signal.SIGINT)
        time.sleep(gap_s)
    try:
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    return proc.returncode, time.perf_counter() - sent, err


SOLVES = [("labelling", "wide", 1), ("cpsat", "c101", 3), ("mip", "rc101", 1),
          ("auto", "wide", 2), ("bp", "wide", 2)]


@pytest.mark.slow
@pytest.mark.parametrize(("backend", "name", "vehicles"), SOLVES,
                         ids=[f"{b}-{n}-m{m}" for b, n, m in SOLVES])
def test_optw_solve_stops_and_writes_the_best_plan(tmp_path: Path, backend: str, name: str,
                                                   vehicles: int) -> None:
    """``optw solve`` on SIGINT: status 130 within seconds, JSON with status INTERRUPTED (or a
    proof found in time) and valid routes."""
    path = _wide_instance(tmp_path / "wide.txt") if name == "wide" else OPTW / f"{name}.txt"
    out = tmp_path / "r.json"
    code, waited, err = _interrupt(["optw", "solve", str(path), "--backend", backend,
                                    "--vehicles", str(vehicles), "--time-limit", "120",
                                    "--json", str(out)], after_s=4.0)
    assert code == 130, err
    assert waited < STOP_S, f"{backend}: {waited:.1f} s from SIGINT to exit"
    record = json.loads(out.read_text(encoding="utf-8"))
    assert record["status"] in ("INTERRUPTED", "OPTIMAL")
    assert len(record["routes"]) in (0, vehicles)
    assert "Traceback" not in err


@pytest.mark.slow
def test_optw_bench_keeps_the_finished_rows(tmp_path: Path) -> None:
    """``optw bench`` on SIGINT: status 130, the rows finished so far in the JSON."""
    folder = tmp_path / "set"
    folder.mkdir()
    for name in ("c101", "pr01", "r101", "rc101"):
        (folder / f"{name}.txt").write_text((OPTW / f"{name}.txt").read_text(encoding="utf-8"),
                                            encoding="utf-8")
    out = tmp_path / "bench.json"
    code, waited, err = _interrupt(["optw", "bench", str(folder), "--backend", "ils",
                                    "--time-limit", "3", "--json", str(out)], after_s=7.5)
    assert code == 130 and waited < STOP_S, err
    rows = json.loads(out.read_text(encoding="utf-8"))
    assert 1 <= len(rows) < 4
    assert all(r["routes"] for r in rows)


@pytest.mark.slow
def test_mission_keeps_the_log_up_to_the_interrupt(tmp_path: Path) -> None:
    """``mission run`` on SIGINT: status 130, mission.json and both figures written for the
    steps flown."""
    scenario = tmp_path / "long.toml"
    scenario.write_text('name = "long"\nduration_s = 3000.0\nseed = 1\n[map]\n'
                        'grid = { rows = 6, cols = 6, block_m = 100.0 }\n[uavs]\ncount = 2\n'
                        '[targets]\ncount = 2\n', encoding="utf-8")
    out = tmp_path / "out"
    code, waited, err = _interrupt(["mission", "run", str(scenario), "--out", str(out)],
                                   after_s=6.0)
    assert code == 130 and waited < STOP_S, err
    record = json.loads((out / "mission.json").read_text(encoding="utf-8"))
    assert 0 < record["summary"]["steps"] < 10000 and record["summary"]["interrupted"]
    for png in ("map.png", "moc.png"):
        assert (out / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(out.glob("*.part"))


@pytest.mark.slow
def test_second_sigint_aborts_at_once(tmp_path: Path) -> None:
    """Two SIGINTs 0.4 s apart (beyond one press delivered twice), inside the native solver:
    status 130 at once, no traceback, no half-written output. (Signals do not queue: when the
    first press has already ended the solve, the run stops cleanly instead of aborting.)"""
    out = tmp_path / "r.json"
    code, waited, err = _interrupt(["optw", "solve", str(OPTW / "c101.txt"), "--backend",
                                    "cpsat", "--vehicles", "3", "--time-limit", "120",
                                    "--json", str(out)], after_s=4.0, signals=2, gap_s=0.4)
    assert code == 130 and waited < STOP_S, err
    assert ("aborted" in err or "interrupted" in err) and "Traceback" not in err
    assert not out.exists() or json.loads(out.read_text(encoding="utf-8"))["status"]
