"""The planners a closed-loop road tracking episode can fly (Moore et al. 2021, §4 and §6).

A planner is a *chooser*: called with a UAV's index and the node it has reached, it returns the
directed edge to fly next. :func:`make_chooser` builds one by name:

* a backend of the road-search solver family (:data:`SOLVER_PLANNERS`): the problem is built
  from the filter through the :class:`~searchtrack.estimate.belief.RoadParticleBelief` seam,
  solved within the time limit, and the deciding UAV flies the first edge of its path (receding
  horizon, §4.2); ``ideal`` also reads the true target positions. With ``coordination="joint"``
  (the default, beyond the paper) the problem holds every UAV: the others join from the node
  each is flying to, as late as it gets there, so the paths are chosen together and no two
  UAVs chase the same particles; ``"alone"`` plans the deciding UAV by itself (the paper's
  controller, each UAV blind to the others);
* ``random``: a uniform choice among the roads leaving the node, U-turns included (the
  authors' random planner);
* ``rl``: a trained policy (:class:`~searchtrack.plan.road_rl.RoadPolicy`, NumPy) on the
  observation of Eq. 22–26; ``config.policy`` names its ``.npz`` file, the shipped policy for the
  paper's 3 × 3 grid when empty.

A solver that returns no plan (it cannot happen for the shipped backends, but a stop request
can cut a call short) falls back to the random choice, and the episode goes on.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.registry import MAX_SEED
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.belief import RoadParticleBelief
from searchtrack.models.road_particles import DirectedRoads, RoadMotion
from searchtrack.plan.road_rl import RoadFeatures, RoadPolicy, policy_for
from searchtrack.plan.road_search import BACKENDS, RoadSearchProblem, RoadSearchSettings, solve

if TYPE_CHECKING:
    from searchtrack.sim.road_particles.episode import RoadTrackingConfig

log = logging.getLogger("searchtrack.sim.road_particles.planners")

OWN_PLANNERS = ("random", "rl")
"""The planners flown here rather than solved: the authors' random choice (U-turns included)
and a trained policy."""

SOLVER_PLANNERS = tuple(name for name in BACKENDS.names() if name not in OWN_PLANNERS)
"""Planners that are road-search backends: the names of :data:`searchtrack.plan.road_search.
BACKENDS`, less those flown here (the ``random`` planner is the authors' choice at each node,
not the registry's ``random`` backend)."""

PLANNERS = (*SOLVER_PLANNERS, *OWN_PLANNERS)
"""Every planner an episode can fly."""

Chooser = Callable[[int, int], int]
"""``choose(uav, node) -> directed edge leaving node``."""

SHIPPED_POLICY = "road_grid3x3.npz"
"""The policy shipped in ``searchtrack/data/policies``: the paper's 3 × 3 grid, 2 targets."""


class Episode(Protocol):
    """What a chooser reads of the episode it flies in."""

    @property
    def roads(self) -> DirectedRoads:
        """The map."""
        ...

    @property
    def belief(self) -> RoadParticleBelief:
        """The filter."""
        ...

    @property
    def plan_rng(self) -> np.random.Generator:
        """The planners' random stream."""
        ...

    def truth(self) -> tuple[IntArray, FloatArray]:
        """The true targets' positions ``(edge, s)``."""
        ...

    def uav_points(self) -> FloatArray:
        """``(Q, 2)`` the UAVs' positions."""
        ...

    def uav_arrivals(self) -> tuple[IntArray, FloatArray]:
        """``(Q,)`` the node each UAV flies to and ``(Q,)`` the seconds until it gets there."""
        ...


def shipped_policy_path() -> Path:
    """The shipped policy file."""
    return Path(str(resources.files("searchtrack") / "data" / "policies" / SHIPPED_POLICY))


@functools.lru_cache(maxsize=8)
def _policy(path: str) -> RoadPolicy:
    """The policy in ``path``, read once per process (episodes fly it many times)."""
    return RoadPolicy.load(path)


def flyable_policy(path: str, roads: DirectedRoads) -> tuple[RoadPolicy, RoadFeatures]:
    """The policy in file ``path`` and the features it was trained with, rebuilt on ``roads``.

    Raises
    ------
    ParseError
        Naming the file and the part at fault: a bad file, or a signature (``meta.signature``)
        that does not say the features or does not match ``roads``.
    """
    policy = _policy(path)
    try:
        return policy, policy_for(roads, policy)
    except InvalidInputError as exc:
        raise ParseError(path, None, "meta.signature",
                         exc.reason if exc.field == "signature" else str(exc)) from None


def make_chooser(config: RoadTrackingConfig, episode: Episode) -> Chooser:
    """The chooser of ``config.planner`` in ``episode`` (its belief read at every decision)."""
    roads, belief, rng = episode.roads, episode.belief, episode.plan_rng

    def random_edge(q: int, node: int) -> int:
        return int(rng.choice(roads.leaving(node)))

    if config.planner == "random":
        return random_edge
    if config.planner == "rl":
        policy, features = flyable_policy(str(config.policy or shipped_policy_path()), roads)

        def policy_edge(q: int, node: int) -> int:
            return policy.choose(features, belief, episode.uav_points(), node,
                                 roads.leaving(node))

        return policy_edge
    settings = RoadSearchSettings(
        lookahead=config.lookahead, uav_speed_mps=config.uav_speed_mps,
        motion=RoadMotion(config.target_speed_mps, config.filter_sigma_mps),
        discount=config.discount, gain=config.gain, normalization=config.normalization,
        horizon_s=config.horizon_s or None)
    ideal = config.planner == "ideal"
    joint = config.coordination == "joint" and config.uavs > 1

    def solver_edge(q: int, node: int) -> int:
        draws = int(rng.integers(MAX_SEED))
        if joint:
            nodes, delay = episode.uav_arrivals()
            nodes, delay = nodes.copy(), delay.copy()
            nodes[q], delay[q] = node, 0.0
            mine = q
        else:
            nodes, delay, mine = np.array([node]), np.zeros(1), 0
        problem = RoadSearchProblem.from_belief(
            belief, nodes.tolist(), settings=_with_seed(settings, draws),
            truth=episode.truth() if ideal else None, uav_delay_s=delay.tolist())
        result = solve(problem, backend=config.planner, time_limit_s=config.time_limit_s,
                       seed=draws)
        if result.plan is None:
            log.warning("%s returned no plan (%s): random edge", config.planner,
                        result.status.name)
            return random_edge(q, node)
        return int(result.plan.first_edges[mine])

    return solver_edge


def _with_seed(settings: RoadSearchSettings, seed: int) -> RoadSearchSettings:
    return dataclasses.replace(settings, draw_seed=seed)
