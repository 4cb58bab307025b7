"""A filter over a recorded radio run: EST.json, determinism, interruption."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.models.radio import RadioScenario
from searchtrack.sim.radio.run import simulate_run
from searchtrack.sim.radio.track_job import run_radio_track, write_radio_estimates


@pytest.fixture(scope="module")
def run():  # type: ignore[no-untyped-def]
    scenario = dataclasses.replace(RadioScenario.paper(noise_var_v2=0.01**2), duration_s=6.0)
    return simulate_run(scenario, 1)[0]


@pytest.mark.parametrize("name", ["tbd", "dtt"])
def test_estimates_file(run, name: str, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    result = run_radio_track(run, name, 100, 4)
    doc = json.loads(write_radio_estimates(result, tmp_path / "est.json").read_text())
    assert len(doc["estimates"]) == len(doc["cardinality"]) == run.n_steps
    assert len(doc["existence"][0]) == run.scenario.signal.n_labels
    assert doc["filter"] == name and doc["ms_per_step"] > 0 and not doc["interrupted"]
    for row in doc["estimates"]:
        for est in row:
            assert set(est) == {"label", "xy"} and len(est["xy"]) == 2
    again = run_radio_track(run, name, 100, 4)
    assert again.estimates == result.estimates and again.existence == result.existence


def test_a_stop_keeps_the_steps_done(run) -> None:  # type: ignore[no-untyped-def]
    def stop_after_two(done: int, _total: int) -> None:
        if done == 2:
            request_stop()

    try:
        result = run_radio_track(run, "tbd", 50, 0, stop_after_two)
    finally:
        clear_stop()
    assert result.steps == 2 and result.interrupted
    assert result.to_json()["interrupted"] is True


def test_bad_arguments(run) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(InvalidInputError, match="filter"):
        run_radio_track(run, "kalman", 100, 0)
    with pytest.raises(InvalidInputError, match="seed"):
        run_radio_track(run, "tbd", 100, -1)
