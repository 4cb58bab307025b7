"""The road search as a Gymnasium environment (paper 000, §4.3)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from searchtrack.sim.road_particles.env import TRAINING_CONFIG, RoadSearchEnv

SHORT = dataclasses.replace(TRAINING_CONFIG, duration_s=20.0, histories=2, particles=50)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_passes_gymnasiums_checker() -> None:
    check_env(RoadSearchEnv(SHORT), skip_render_check=True)


def test_an_action_flies_one_road_and_rewards_minus_the_entropy() -> None:
    env = RoadSearchEnv(SHORT)
    obs, info = env.reset(seed=3)
    assert obs.shape == env.observation_space.shape and env.observation_space.contains(obs)
    node = int(env.sim.uavs.nodes()[0])
    leaving = np.flatnonzero(env.roads.tail == node)
    t0 = info["time_s"]
    obs, reward, terminated, truncated, info = env.step(1)
    road = leaving[1 % leaving.size]
    assert env.sim.uavs.edge[0] == road  # at the end of the chosen road
    assert env.sim.uavs.s[0] == pytest.approx(env.roads.length[road])
    assert info["time_s"] - t0 == pytest.approx(100.0 / 40.0, abs=0.11)
    assert reward < 0.0 and not terminated and not truncated


def test_episodes_end_by_truncation_and_repeat_for_a_seed() -> None:
    def returns(seed: int) -> list[float]:
        env = RoadSearchEnv(SHORT)
        env.reset(seed=seed)
        out, done = [], False
        while not done:
            _, r, term, trunc, _ = env.step(0)
            out.append(r)
            done = term or trunc
        assert trunc and not term and env.sim.time_s == pytest.approx(20.0)
        return out

    a = returns(7)
    assert a == returns(7) and len(a) >= 20.0 * 40.0 / 100.0 - 1
    assert a != returns(8)


def test_bad_actions_and_fleets_are_refused() -> None:
    env = RoadSearchEnv(SHORT)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(0)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="not in"):
        env.step(99)
    with pytest.raises(ValueError, match="one UAV"):
        RoadSearchEnv(dataclasses.replace(SHORT, uavs=2))
