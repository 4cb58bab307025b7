"""The deep-RL road planner of Moore et al. 2021 (§4.3), flown without a deep-learning stack.

:class:`RoadFeatures` builds the policy's observation (Eq. 22–26) from any
:class:`~searchtrack.estimate.belief.RoadParticleBelief`; :class:`RoadPolicy` is the trained
actor network as NumPy arrays (``.npz``), choosing the next road at a node. Training lives in
:mod:`searchtrack.sim.road_particles.rl_training` (the ``rl`` extra).
"""

from __future__ import annotations

from searchtrack.plan.road_rl.features import RoadFeatures
from searchtrack.plan.road_rl.policy import RoadPolicy, policy_for

__all__ = ["RoadFeatures", "RoadPolicy", "policy_for"]
