"""Recorded radio runs: simulation, the RUN.npz round trip, and every bad file refused."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.models.radio import RadioScenario
from searchtrack.sim.radio.run import (
    FIELDS,
    RadioRun,
    read_run,
    simulate_run,
    truth_json,
    write_run,
    write_truth,
)


@pytest.fixture(scope="module")
def short() -> RadioScenario:
    return dataclasses.replace(RadioScenario.paper(), duration_s=8.0)


@pytest.fixture(scope="module")
def recorded(short: RadioScenario) -> tuple[RadioRun, object]:
    return simulate_run(short, 3)


def test_simulated_run_has_one_frame_per_interval_and_no_truth(recorded) -> None:
    run, truth = recorded
    sig = run.scenario.signal
    assert run.frames.shape == (8, sig.frames, sig.fft_size)
    assert run.uav_poses.shape == (8, 3)
    assert run.scenario.tags == ()                     # the truth is written apart
    assert truth.alive.shape == (8, sig.n_labels)
    steps = np.hypot(*np.diff(run.uav_poses[:, :2], axis=0).T)
    assert np.allclose(steps, run.scenario.uav.speed_mps)


def test_simulation_is_deterministic_per_seed(short: RadioScenario) -> None:
    a, _ = simulate_run(short, 5)
    b, _ = simulate_run(short, 5)
    c, _ = simulate_run(short, 6)
    assert np.array_equal(a.frames, b.frames)
    assert not np.array_equal(a.frames, c.frames)


def test_round_trip(recorded, tmp_path: Path) -> None:
    run, truth = recorded
    path = write_run(run, tmp_path / "run.npz")
    back = read_run(path)
    assert np.array_equal(back.frames, run.frames.astype(np.float32))
    assert np.array_equal(back.uav_poses, run.uav_poses)
    assert back.scenario == run.scenario and back.seed == run.seed
    doc = json.loads(write_truth(truth, tmp_path / "truth.json").read_text())
    assert doc == json.loads(json.dumps(truth_json(truth)))
    first = doc["tags"][0]
    assert first["states"][0] is not None and len(first["states"][0]) == 4
    assert doc["tags"][1]["states"][0] is None          # object 1 is born at 50 s


def _rewrite(run: RadioRun, path: Path, **changes: object) -> Path:
    sig = run.scenario.signal
    fields = {"frames": run.frames, "uav_poses": run.uav_poses, "times_s": run.times_s,
              "labels": np.arange(sig.n_labels), "frequencies_hz": np.array(sig.frequencies_hz),
              "scenario": np.array(json.dumps(run.scenario.to_dict())), "seed": np.array(0)}
    fields.update(changes)
    fields = {k: v for k, v in fields.items() if v is not None}
    with path.open("wb") as fh:
        np.savez(fh, **fields)
    return path


@pytest.mark.parametrize(("change", "field"), [
    ({"frames": None}, "frames"),
    ({"extra": np.zeros(2)}, "extra"),
    ({"frequencies_hz": np.array([131e3, 201e3, 401e3, 851e3])}, "frequencies_hz"),
    ({"labels": np.array([0, 1, 2])}, "labels"),
    ({"scenario": np.array("{not json")}, "scenario"),
    ({"scenario": np.array(json.dumps({"signal": {"bogus": 1}}))}, "scenario.signal.bogus"),
])
def test_bad_fields_are_named(recorded, tmp_path: Path, change: dict[str, object],
                              field: str) -> None:
    run, _ = recorded
    with pytest.raises(ParseError) as err:
        read_run(_rewrite(run, tmp_path / "bad.npz", **change))
    assert field in str(err.value)


def test_nan_and_wrong_shape_frames_are_refused(recorded, tmp_path: Path) -> None:
    run, _ = recorded
    nan = run.frames.copy()
    nan[2, 5, 7] = np.nan
    with pytest.raises(ParseError, match=r"frames.*interval 2"):
        read_run(_rewrite(run, tmp_path / "nan.npz", frames=nan))
    with pytest.raises(ParseError, match="frames"):
        read_run(_rewrite(run, tmp_path / "shape.npz", frames=run.frames[:, :, :128]))
    with pytest.raises(ParseError, match="uav_poses"):
        read_run(_rewrite(run, tmp_path / "poses.npz", uav_poses=run.uav_poses[:-1]))


def test_not_an_npz(tmp_path: Path) -> None:
    bad = tmp_path / "x.npz"
    bad.write_text("hello")
    with pytest.raises(ParseError, match="not a readable"):
        read_run(bad)
    with pytest.raises(ParseError):
        read_run(tmp_path / "missing.npz")


def test_direct_construction_checks(recorded) -> None:
    run, _ = recorded
    with pytest.raises(InvalidInputError, match="times_s"):
        RadioRun(run.scenario, run.frames, run.uav_poses, run.times_s[::-1])
    with pytest.raises(InvalidInputError, match="measurement"):
        simulate_run(run.scenario, 0, measurement="radar")
    assert set(FIELDS) >= {"frames", "scenario"}
