"""``searchtrack radio simulate|track|mission`` fail safe: sizes that would exhaust memory or
overflow are refused up front with one line naming the file and the key (exit status 2, nothing
written), junk scenarios and run files never raise a traceback, and Ctrl-C stops a simulation
between intervals, keeping the intervals done."""

from __future__ import annotations

import functools
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import request_stop
from tests.cli.probes import _radio_track
from tests.cli.probes_radio import npy_header, replace_member
from tests.cli.runs import run_main, run_on_file


def test_run_size_is_bounded() -> None:
    """A run of more spectrogram cells than a run may hold is refused before it is simulated,
    naming ``duration_s`` and the scenario's file."""
    from searchtrack.models.radio import RadioScenario
    from searchtrack.sim.radio.run import check_run_size

    long = RadioScenario.from_dict({"duration_s": 90_000.0})
    with pytest.raises(InvalidInputError, match=r"duration_s.*a run may hold.*\(in s\.toml\)"):
        check_run_size(long, source="s.toml")
    check_run_size(RadioScenario.paper())


# ---- run files whose members are not what they claim, each named


def _member_case(member: str, data: bytes) -> Callable[[Path], list[str]]:
    def build(tmp: Path) -> list[str]:
        argv = _radio_track(lambda a: None)(tmp)
        replace_member(Path(argv[2]), member, data)
        return argv

    return build


MEMBER_CASES = [
    ("object dtype", _member_case("seed.npy", npy_header((), "|O") + bytes(16)),
     ("seed", "objects")),
    ("negative dimension", _member_case("times_s.npy", npy_header((-2,), "<f8")),
     ("times_s", "negative")),
    ("bad magic", _member_case("uav_poses.npy", b"\x93NUMPX" + bytes(100)), ("uav_poses",)),
    ("format 9.9", _member_case("labels.npy", b"\x93NUMPY\x09\x09" + bytes(100)), ("labels",)),
    ("complex frames", _member_case("frames.npy", npy_header((2, 111, 256), "<c8")
                                    + bytes(2 * 111 * 256 * 8)), ("frames", "numbers")),
    ("scenario as numbers", _member_case("scenario.npy", npy_header((2,), "<f8") + bytes(16)),
     ("scenario", "text")),
]


@pytest.mark.parametrize(("build", "words"), [c[1:] for c in MEMBER_CASES],
                         ids=[c[0] for c in MEMBER_CASES])
def test_bad_run_members_are_named(build: Callable[[Path], list[str]], words: tuple[str, ...],
                                   tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A member with a bad header or type: status 2, the file and the array named."""
    argv = build(tmp_path)
    code = run_main(argv)
    text = " ".join(capsys.readouterr().err.split())
    assert code == 2, text
    for word in ("run.npz", *words):
        assert word in text, f"{word!r} not in: {text}"
    assert not (tmp_path / "e.json").exists()


# ---- junk


FAST = settings(max_examples=20, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture])

DURATIONS = ["duration_s = 2.0", "duration_s = 1e300", "duration_s = 1e-300", "duration_s = -1",
             "duration_s = 3", "duration_s = nan"]
TOP = ["area_m = [1e300, 1e300]", "area_m = [0.0, 5.0]", "birth_cov_diag = [1e300, 1, 1, 1]",
       "birth_means = []", "birth_probability = 1e-300", "tags = 3", "seed = 5"]
TABLES = {
    "signal": ["fft_size = 100000000", "fft_size = 0", "fft_size = 512", "frames = 100000000",
               "frames = 1", "window_size = 1000000000", "half_width_bins = 1000000000000",
               "sample_rate_hz = 1e300", "sample_rate_hz = 1e-300", "frequencies_hz = [1e300]",
               "frequencies_hz = []", "frequencies_hz = [131e3, 131e3]", "noise_var_v2 = 1e300",
               "receiver_gain_db = 1e300", "receiver_gain_db = -1e300", "amplitude_v = 1e300",
               "front_to_back_db = 1e300", "path_loss_exponent = 1e300", "period_s = 1e-300",
               "reference_distance_m = 1e300", "pulse_width_s = 1e-300", "frames = \"x\""],
    "motion": ["period_s = 1e300", "wd_position_var = 1e300", "wd_velocity_var = 1e300",
               "cv_accel_std = 1e300", "tau_std = 1e300", "mode_transition = [[2, -1], [0, 1]]",
               "initial_mode = [1, 0]", "mode_transition = 4"],
    "uav": ["n_headings = 100000000", "n_headings = 1", "plan_interval_s = 1e300",
            "plan_interval_s = 1e-300", "step_s = 1e-300", "speed_mps = 1e300",
            "max_turn_rate = 1e300", "start_xy = [1e300, 0]", "start_heading = 1e300"],
}
TAGS = ["[[tags]]\nlabel = 0\nbirth_s = 0.0\ndeath_s = 1e300\n"
        "initial_state = [1e300, 1e300, 0, 0]\ntau_s = 0.5",
        "[[tags]]\nlabel = 99\nbirth_s = 0\ndeath_s = 1\ninitial_state = [0, 0, 0, 0]\ntau_s = 0",
        "[[tags]]\nlabel = 0\nbirth_s = 1\ndeath_s = 2\ninitial_state = [1, 1, 1, 1]\n"
        "tau_s = 0.1\nmode_schedule = [[0, 0], [1e300, 1]]"]


@st.composite
def radio_toml(draw: st.DrawFn) -> str:
    """A radio scenario: a duration, top-level keys, tables with extreme values, tags."""
    lines = [draw(st.sampled_from(DURATIONS)), *draw(st.lists(st.sampled_from(TOP), max_size=2))]
    for table, keys in TABLES.items():
        chosen = draw(st.lists(st.sampled_from(keys), max_size=3, unique=True))
        if chosen:
            lines += [f"[{table}]", *chosen]
    lines += draw(st.lists(st.sampled_from(TAGS), max_size=2))
    return "\n".join(lines) + "\n"


junk = st.one_of(st.binary(max_size=300), st.text(max_size=300)).map(
    lambda d: b"duration_s = 2.0\n" + d if isinstance(d, bytes) else f"duration_s = 2.0\n{d}")
"""Bytes or text after a short duration (the duration keeps a file that happens to be valid
fast)."""


def _run(argv: Callable[[Path, Path], list[str]], name: str, data: str | bytes) -> None:
    assert run_on_file(argv, name, data) in (0, 1, 2)


def _simulate(p: Path, t: Path) -> list[str]:
    return ["radio", "simulate", str(p), "--out", str(t / "r.npz")]


@FAST
@given(st.one_of(radio_toml(), junk))
@example("duration_s = 2.0\n[signal]\nreceiver_gain_db = 1e300\n")
@example("duration_s = 2.0\n[signal]\nhalf_width_bins = 1000000000000\n")
def test_scenario_junk(data: str | bytes) -> None:
    """Radio scenarios with huge, tiny, empty or mistyped values, and junk: answered (exit 0, 1
    or 2), never a traceback."""
    _run(_simulate, "s.toml", data)


@functools.cache
def _good_run() -> bytes:
    """The bytes of a valid two-interval RUN.npz of the paper scenario."""
    with tempfile.TemporaryDirectory() as folder:
        argv = _radio_track(lambda a: None)(Path(folder))
        return Path(argv[2]).read_bytes()


@functools.cache
def _header_offsets() -> tuple[int, ...]:
    """Where each member's local zip header starts in :func:`_good_run`."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "r.npz"
        path.write_bytes(_good_run())
        with zipfile.ZipFile(path) as archive:
            return tuple(info.header_offset for info in archive.infolist())


MEMBERS = ["frames", "uav_poses", "times_s", "labels", "frequencies_hz", "scenario", "seed"]
DESCRS = ["<f4", "<f8", "<i8", "|b1", "<c16", "|O", "<U5", "|V0", "<M8[s]", "|S3", ">f8"]

RunCase = tuple[Any, ...]
"""How a run file is made from the valid one: ``("random", bytes)``, ``("truncated", n)``,
``("corrupt", [(member index, offset past its zip header, byte)])``, ``("header", member,
shape, descr, body)`` (the member's ``.npy`` header rewritten over ``body``) or ``("member",
member, bytes)`` (the member replaced by raw bytes)."""

run_cases = st.one_of(
    st.tuples(st.just("random"), st.binary(max_size=400)),
    st.tuples(st.just("truncated"), st.integers(0, 2**20)),
    st.tuples(st.just("corrupt"), st.lists(st.tuples(
        st.integers(0, len(MEMBERS) - 1), st.integers(0, 160), st.integers(0, 255)),
        min_size=1, max_size=6)),
    st.tuples(st.just("header"), st.sampled_from(MEMBERS),
              st.lists(st.one_of(st.integers(-3, 300), st.just(10**12)), max_size=3).map(tuple),
              st.sampled_from(DESCRS), st.binary(max_size=64)),
    st.tuples(st.just("member"), st.sampled_from(MEMBERS),
              st.binary(max_size=120).map(lambda b: b"\x93NUMPY\x01\x00" + b)))


def _run_bytes(case: RunCase) -> bytes:
    """The bytes of run file ``case`` (:data:`RunCase`)."""
    good = _good_run()
    kind = case[0]
    if kind == "random":
        return bytes(case[1])
    if kind == "truncated":
        return good[:case[1] % len(good)]
    if kind == "corrupt":
        data = bytearray(good)
        for member, offset, value in case[1]:
            data[_header_offsets()[member] + offset] = value
        return bytes(data)
    member = case[1]
    raw = case[2] if kind == "member" else npy_header(case[2], case[3]) + case[4]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "r.npz"
        path.write_bytes(good)
        replace_member(path, f"{member}.npy", raw)
        return path.read_bytes()


def _track(p: Path, t: Path) -> list[str]:
    return ["radio", "track", str(p), "--particles", "10", "--out", str(t / "e.json")]


@FAST
@given(run_cases)
@example(("header", "frames", (10**11, 111, 256), "<f4", bytes(4000)))
@example(("member", "seed", b"\x93NUMPY\x01\x00\x0c\x00{'descr': (\n"))
def test_run_file_junk(case: RunCase) -> None:
    """Junk, truncated, corrupted and mislabelled RUN.npz files: answered, never a traceback."""
    _run(_track, "r.npz", _run_bytes(case))


# ---- Ctrl-C


def test_ctrl_c_keeps_the_intervals_simulated(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """A stop request during ``radio simulate`` ends it after the interval in progress: status
    130, a readable run of the intervals done and their truth."""
    import searchtrack.sim.radio.run as radio_run

    spectrogram = radio_run.spectrogram

    def stopping(*args: Any) -> Any:
        out = spectrogram(*args)
        request_stop()
        return out

    monkeypatch.setattr(radio_run, "spectrogram", stopping)
    scenario = tmp_path / "s.toml"
    scenario.write_text("duration_s = 6.0\n", encoding="utf-8")
    out, truth = tmp_path / "run.npz", tmp_path / "truth.json"
    assert run_main(["radio", "simulate", str(scenario), "--out", str(out), "--truth",
                     str(truth)]) == 130
    assert radio_run.read_run(out).n_steps == 1
    assert len(json.loads(truth.read_text(encoding="utf-8"))["times_s"]) == 1


def test_ctrl_c_stops_the_truth_draw(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A stop request while the ground truth of a long mission is drawn ends the draw at once:
    status 130, an empty mission log, one motion step drawn instead of 100 000."""
    from searchtrack.models.radio.motion import propagate

    calls = []

    def stopping(*args: Any) -> Any:
        calls.append(1)
        request_stop()
        return propagate(*args)

    monkeypatch.setattr("searchtrack.models.radio.scenario.propagate", stopping)
    scenario = tmp_path / "s.toml"
    scenario.write_text("duration_s = 100000.0\n", encoding="utf-8")
    folder = tmp_path / "out"
    assert run_main(["radio", "mission", str(scenario), "--planner", "straight", "--particles",
                     "10", "--out", str(folder)]) == 130
    assert len(calls) == 1
    assert (folder / "mission.json").exists()


def _inside_sigint_stops(pid: int, timeout_s: float = 60.0) -> bool:
    """Wait until process ``pid`` has entered :func:`~searchtrack.core.interrupt.sigint_stops`
    (its SIGINT counter holds a socket pair): True then, False on timeout."""
    fds = Path(f"/proc/{pid}/fd")
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        try:
            if any(os.readlink(fd).startswith("socket:") for fd in fds.iterdir()):
                return True
        except OSError:
            pass
        time.sleep(0.05)
    return False


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs /proc")
def test_sigint_stops_a_long_simulation(tmp_path: Path) -> None:
    """A real Ctrl-C (SIGINT) to ``radio simulate`` of 4500 intervals: status 130 within
    seconds (not after the whole run), no traceback, and a readable run of the intervals done
    (none written when the press came before the first)."""
    from searchtrack.sim.radio.run import read_run

    scenario = tmp_path / "long.toml"
    scenario.write_text("duration_s = 4500.0\n", encoding="utf-8")
    out = tmp_path / "run.npz"
    proc = subprocess.Popen([sys.executable, "-m", "searchtrack.cli", "radio", "simulate",
                             str(scenario), "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert _inside_sigint_stops(proc.pid), "the command never started"
        time.sleep(1.0)
        assert proc.poll() is None, f"finished before the interrupt: {proc.communicate()}"
        sent = time.perf_counter()
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    waited = time.perf_counter() - sent
    assert proc.returncode == 130, err
    assert waited < 3.0, f"{waited:.1f} s from SIGINT to exit"
    assert "Traceback" not in err
    if out.exists():
        run = read_run(out)
        assert 0 < run.n_steps < 4500 and np.all(np.isfinite(run.frames))
