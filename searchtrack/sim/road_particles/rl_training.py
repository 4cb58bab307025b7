"""Training the deep-RL road planner (Moore et al. 2021, §4.3) with PPO, exported for NumPy.

The paper trains PPO (Schulman et al. 2017) on a flat feature vector; here Stable-Baselines3's
PPO trains an actor-critic MLP on :class:`~searchtrack.sim.road_particles.env.RoadSearchEnv`, and
the actor is exported as a :class:`~searchtrack.plan.road_rl.RoadPolicy` (plain arrays in an
``.npz``), so flying it needs neither PyTorch nor Stable-Baselines3. Those two are the ``rl``
extra (``pip install 'searchtrack[rl]'``); this module imports them when training starts.

The network is smaller than the authors' (their 574 → 344 → … → 10 → |A| stack, trained for about
580 epochs of 100 rollouts): two ``tanh`` layers of ``hidden`` units, trained for ``timesteps``
agent steps (one step = one road). A stop request (Ctrl-C) ends training early and the policy
learnt so far is returned.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.registry import check_seed
from searchtrack.plan.road_rl.policy import RoadPolicy
from searchtrack.sim.road_particles.env import TRAINING_CONFIG, RoadSearchEnv
from searchtrack.sim.road_particles.episode import RoadTrackingConfig

log = logging.getLogger("searchtrack.sim.road_particles.rl_training")

Progress = Callable[[int, int], None]
"""Called with (agent steps done, steps asked for)."""


@dataclass(frozen=True)
class TrainingConfig:
    """PPO settings.

    Parameters
    ----------
    timesteps
        Agent steps (roads flown) to train for, ≥ 1.
    hidden
        Units of the actor's and critic's hidden layers.
    learning_rate, gamma, clip_range
        Adam step, discount (0.8 in the authors' code) and PPO clip ε (0.2).
    n_steps, batch_size, n_epochs
        Rollout length per update, minibatch size and epochs per update.
    ent_coef
        Entropy bonus (exploration).
    """

    timesteps: int = 100_000
    hidden: tuple[int, ...] = (256, 128)
    learning_rate: float = 3e-4
    gamma: float = 0.9
    clip_range: float = 0.2
    n_steps: int = 1024
    batch_size: int = 128
    n_epochs: int = 10
    ent_coef: float = 0.01

    def __post_init__(self) -> None:
        checks.count("timesteps", self.timesteps, 1)
        if not self.hidden or any(not isinstance(h, int) or h < 1 for h in self.hidden):
            raise InvalidInputError("hidden", self.hidden, "must be positive layer sizes")
        checks.positive("learning_rate", self.learning_rate)
        checks.real("gamma", self.gamma, low=0.0, high=1.0)
        checks.real("clip_range", self.clip_range, low=0.0, high=1.0, low_open=True)
        checks.count("n_steps", self.n_steps, 2)
        checks.count("batch_size", self.batch_size, 2)
        checks.count("n_epochs", self.n_epochs, 1)
        checks.non_negative("ent_coef", self.ent_coef)


def export_actor(model: Any, env: RoadSearchEnv) -> RoadPolicy:
    """The actor of a Stable-Baselines3 PPO ``model`` (MLP, ``tanh``) as a :class:`RoadPolicy`
    with ``env``'s feature signature."""
    import torch

    layers = [m for m in model.policy.mlp_extractor.policy_net if isinstance(m, torch.nn.Linear)]
    layers.append(model.policy.action_net)
    weights = tuple(layer.weight.detach().cpu().numpy().astype(np.float64) for layer in layers)
    biases = tuple(layer.bias.detach().cpu().numpy().astype(np.float64) for layer in layers)
    return RoadPolicy(weights, biases, "tanh", env.features.signature())


def train_policy(config: RoadTrackingConfig = TRAINING_CONFIG,
                 training: TrainingConfig | None = None, *, seed: int = 0,
                 progress: Progress | None = None) -> RoadPolicy:
    """Train a road-search policy on episodes of ``config`` (one UAV) and export its actor.

    Raises
    ------
    ModuleNotFoundError
        The ``rl`` extra (PyTorch, Stable-Baselines3) is not installed.
    """
    settings = training or TrainingConfig()
    seed = check_seed(seed)
    try:
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.callbacks import BaseCallback
        from stable_baselines3.common.logger import Logger
    except ModuleNotFoundError as exc:
        raise ModuleNotFoundError(f"training needs the rl extra (pip install "
                                  f"'searchtrack[rl]'): {exc}") from None

    torch.set_num_threads(1)
    env = RoadSearchEnv(config)
    env.reset(seed=seed)

    class _Watch(BaseCallback):  # type: ignore[misc]
        def _on_step(self) -> bool:
            if progress is not None and self.num_timesteps % 256 == 0:
                progress(self.num_timesteps, settings.timesteps)
            return not stop_requested()

    model = PPO("MlpPolicy", env, learning_rate=settings.learning_rate, n_steps=settings.n_steps,
                batch_size=settings.batch_size, n_epochs=settings.n_epochs,
                gamma=settings.gamma, clip_range=settings.clip_range,
                ent_coef=settings.ent_coef, seed=seed, device="cpu", verbose=0,
                policy_kwargs={"net_arch": {"pi": list(settings.hidden),
                                            "vf": list(settings.hidden)},
                               "activation_fn": torch.nn.Tanh})
    model.set_logger(Logger(None, []))  # SB3's default logger makes a /tmp/SB3-<date> folder
    model.learn(total_timesteps=settings.timesteps, callback=_Watch())
    if progress is not None:
        progress(int(model.num_timesteps), settings.timesteps)
    log.info("trained %d steps", model.num_timesteps)
    return export_actor(model, env)
