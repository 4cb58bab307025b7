"""PPO training of the road planner and the export of its actor to NumPy."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.sim.road_particles.env import TRAINING_CONFIG, RoadSearchEnv
from searchtrack.sim.road_particles.rl_training import TrainingConfig, export_actor, train_policy

pytest.importorskip("stable_baselines3", reason="the rl extra (make test installs it)")

TINY = dataclasses.replace(TRAINING_CONFIG, duration_s=20.0, histories=1, particles=50)


def test_a_tiny_training_exports_the_actor_sb3_would_fly() -> None:
    """The NumPy actor takes the same greedy actions as the trained PyTorch model."""
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.logger import Logger

    env = RoadSearchEnv(TINY)
    env.reset(seed=0)
    model = PPO("MlpPolicy", env, n_steps=64, batch_size=32, n_epochs=1, seed=0, device="cpu",
                policy_kwargs={"net_arch": {"pi": [16, 8], "vf": [16]},
                               "activation_fn": torch.nn.Tanh})
    model.set_logger(Logger(None, []))
    model.learn(total_timesteps=64)
    policy = export_actor(model, env)
    assert policy.signature == env.features.signature()
    rng = np.random.default_rng(0)
    for _ in range(5):
        obs, _ = env.reset(seed=int(rng.integers(1000)))
        action, _ = model.predict(obs, deterministic=True)
        assert policy.act(obs) == int(action)


def test_train_policy_returns_a_policy_for_the_environments_features(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A policy of the right shape, and no log folder left behind (SB3's default logger would
    make one under ``SB3_LOGDIR``)."""
    monkeypatch.setenv("SB3_LOGDIR", str(tmp_path / "sb3"))
    policy = train_policy(TINY, TrainingConfig(timesteps=64, n_steps=32, batch_size=16,
                                               n_epochs=1, hidden=(8,)), seed=1)
    assert policy.n_inputs == RoadSearchEnv(TINY).features.size and policy.n_actions == 4
    assert len(policy.weights) == 2
    assert not (tmp_path / "sb3").exists()


def test_a_stop_request_ends_training_with_the_policy_so_far() -> None:
    seen: list[int] = []
    request_stop()
    try:
        policy = train_policy(TINY, TrainingConfig(timesteps=10_000, n_steps=32, batch_size=16,
                                                   n_epochs=1, hidden=(8,)),
                              progress=lambda done, total: seen.append(done))
    finally:
        clear_stop()
    assert policy.n_actions == 4 and seen and seen[-1] < 10_000


@pytest.mark.parametrize(("field", "value"), [
    ("timesteps", 0), ("hidden", ()), ("hidden", (0,)), ("learning_rate", -1.0),
    ("gamma", 1.5), ("clip_range", 0.0), ("n_steps", 1), ("batch_size", 1), ("n_epochs", 0),
    ("ent_coef", -0.1)])
def test_bad_settings_name_the_field(field: str, value: object) -> None:
    with pytest.raises(InvalidInputError, match=field):
        TrainingConfig(**{field: value})  # type: ignore[arg-type]
