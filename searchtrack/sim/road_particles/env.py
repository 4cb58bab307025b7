"""The road search as a Gymnasium environment, to train the deep-RL planner of Moore et al.
2021 (§4.3).

One agent step is one road: the UAV stands at a node, the action ``k`` picks the ``k``-th road
leaving it (modulo the node's degree, so every action is valid), and the episode
(:class:`~searchtrack.sim.road_particles.episode.RoadTrackingSim`: targets, the RBPF, scans)
runs until the UAV reaches the next node. The observation is that of
:class:`~searchtrack.plan.road_rl.RoadFeatures` (Eq. 22–26), the one the trained policy reads in
flight. The paper's reward, ``exp(γ_max − γ_k)``, is left undefined there; here the reward of a
step is minus the combined entropy summed over the scans it flew, over ``reward_scale`` scans, so
the return is minus the episode's entropy (the quantity of Fig. 11) and the planner that keeps
it lowest earns the most. The episode ends (truncation) when ``config.duration_s`` is flown.

The distance a UAV would fly past a node in the step it arrives is dropped (the agent decides
between filter steps): at most ``V_a · δt`` (4 m at 40 m/s and 0.1 s) per road.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import gymnasium as gym
import numpy as np

from searchtrack.core.registry import MAX_SEED
from searchtrack.core.types import FloatArray
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.plan.road_rl.features import RoadFeatures
from searchtrack.sim.road_particles.episode import WAIT, RoadTrackingConfig, RoadTrackingSim

TRAINING_CONFIG = RoadTrackingConfig(planner="random", histories=2, particles=200)
"""The default episode of training: the paper's map and targets with a smaller filter (2 × 2 ×
200 particles instead of 10 × 2 × 500), so that an agent step costs milliseconds."""


class RoadSearchEnv(gym.Env[np.ndarray, np.int64]):
    """The road search, one decision per road (see the module docstring).

    Parameters
    ----------
    config
        The episode (its ``planner`` is ignored: the agent chooses). One UAV.
    roads
        The map's directed roads, if already built.
    bins_per_edge
        Histogram bins per directed edge of the observation (Eq. 22).
    include_map
        Whether the observation carries the map (Eq. 24–25).
    reward_scale
        Scans per unit of reward.
    """

    metadata: dict[str, Any] = {"render_modes": []}  # noqa: RUF012 (Gymnasium's class attribute)

    def __init__(self, config: RoadTrackingConfig = TRAINING_CONFIG,
                 roads: DirectedRoads | None = None, *, bins_per_edge: int = 10,
                 include_map: bool = True, reward_scale: float = 10.0) -> None:
        if config.uavs != 1:
            raise ValueError(f"the environment flies one UAV, not {config.uavs}")
        self.config = dataclasses.replace(config, planner="random")
        self.roads = roads if roads is not None else DirectedRoads(config.map.build())
        self.features = RoadFeatures(self.roads, config.targets, 1, bins_per_edge, config.gain,
                                     include_map)
        self.reward_scale = float(reward_scale)
        self.action_space = gym.spaces.Discrete(int(np.diff(self.roads.out_ptr).max()))
        self.observation_space = gym.spaces.Box(0.0, np.inf, (self.features.size,), np.float32)
        self._sim: RoadTrackingSim | None = None
        self._pending = WAIT

    @property
    def sim(self) -> RoadTrackingSim:
        """The running episode (after :meth:`reset`)."""
        if self._sim is None:
            raise RuntimeError("call reset() first")
        return self._sim

    def _node(self) -> int:
        return int(self.sim.uavs.nodes()[0])

    def _observe(self) -> FloatArray:
        return self.features.observe(self.sim.belief, self.sim.uav_points(), self._node())

    def _choose(self, q: int, node: int) -> int:
        edge, self._pending = self._pending, WAIT
        return edge

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        """A new episode: targets and the UAV's start drawn from ``seed`` (or the environment's
        random stream)."""
        super().reset(seed=seed)
        episode_seed = int(self.np_random.integers(MAX_SEED))
        self._sim = RoadTrackingSim(self.config, episode_seed, self.roads)
        self._pending = WAIT
        self.sim.step(self._choose)  # the UAV stands at its start node
        return self._observe(), {"time_s": self.sim.time_s}

    def step(self, action: np.int64 | int) -> tuple[np.ndarray, float, bool, bool,
                                                    dict[str, Any]]:
        """Fly the chosen road to its end node; reward = −Σ entropy over its scans / scale."""
        sim = self.sim
        if not self.action_space.contains(np.int64(action)):
            raise ValueError(f"action {action!r} is not in {self.action_space}")
        leaving = self.roads.leaving(self._node())
        self._pending = int(leaving[int(action) % leaving.size])
        total = 0.0
        while not sim.done:
            entropy = sim.step(self._choose)
            if entropy is not None:
                total += entropy
            if self._pending == WAIT and sim.uavs.s[0] >= self.roads.length[sim.uavs.edge[0]]:
                break
        reward = -total / self.reward_scale
        return (self._observe(), reward, False, sim.done,
                {"time_s": sim.time_s, "entropy": sim.belief.combined_entropy()})
