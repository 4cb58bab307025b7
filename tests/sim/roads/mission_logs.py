"""A two-step mission log recorded by hand on a 2 × 2 grid, shared by the record and figure tests.

The grid of 100 m blocks at 50 m spacing has 8 nodes (the 4 corners first). One tracker, born at
0.3 s, holds 0.7 on node 3 and 0.3 on node 2 at both steps; step 1 has a valid tracker and a
valid association, step 2 a spurious tracker and a false one. Target 0 was detected at 0.3 s,
target 1 never.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from searchtrack.estimate import LikelihoodField, TrackerBank
from searchtrack.models import SensorModel, grid_network
from searchtrack.sim.roads.metrics import StepScore
from searchtrack.sim.roads.record import MissionLog, Recorder, StepTimes
from searchtrack.sim.roads.scenario import MapSpec, Scenario

SENSOR = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=150.0, position_noise_m=5.0)
SCENARIO = Scenario("rec", MapSpec("grid", rows=2, cols=2, block_m=100.0, spacing_m=50.0),
                    uav_count=2, target_count=2, sensor=SENSOR, altitude_m=None,
                    duration_s=0.6, dt_s=0.3, seed=7)
LLR = np.array([-1.0, 0.0, 2.0, 5.0, 0.0, 0.0, -3.0, 0.5])


@dataclass(frozen=True)
class StepAnswer:
    """The part of a guidance answer a recorder keeps."""

    mode: tuple[str, ...]
    plan_ms: float


def tracker_probability() -> np.ndarray:
    """The tracker's distribution: 0.7 on node 3, 0.3 on node 2."""
    p = np.zeros(8)
    p[3], p[2] = 0.7, 0.3
    return p


def two_step_log() -> MissionLog:
    """The log of two hand-made steps (see the module docstring)."""
    net = grid_network(2, 2, 100.0, 50.0)
    rec = Recorder(SCENARIO, net, uav_start=np.array([[0.0, 0.0], [100.0, 100.0]]),
                   target_start=np.array([[50.0, 0.0], [0.0, 50.0]]))
    bank = TrackerBank(net.n_nodes).with_birth(tracker_probability())
    rec.birth(0.3, 0, 1, 12.345)
    rec.add(0.3, np.array([[10.0, 0.0], [100.0, 90.0]]), np.array([[55.0, 0.0], [0.0, 45.0]]),
            StepScore(1, 1, 1, 0), StepAnswer(("search", "loiter"), 2.5),
            StepTimes(0.001, 0.002, 0.003, 0.004, 0.005, 0.006, 0.007), bank, [(0, 0, 1)])
    rec.add(0.6, np.array([[20.04, 0.0], [100.0, 80.0]]), np.array([[60.0, 0.0], [0.0, 40.0]]),
            StepScore(1, 0, 0, 1), StepAnswer(("search", "search"), 0.0), StepTimes(), bank,
            [(1, 0, -1)])
    return rec.finish(LikelihoodField(LLR), bank, np.array([0.3, np.nan]))


def empty_log() -> MissionLog:
    """A log with no step: a neutral field, no trackers, nothing detected."""
    net = grid_network(2, 2, 100.0, 50.0)
    rec = Recorder(SCENARIO, net, uav_start=np.array([[0.0, 0.0], [100.0, 100.0]]),
                   target_start=np.array([[50.0, 0.0], [0.0, 50.0]]))
    return rec.finish(LikelihoodField.neutral(net.n_nodes), TrackerBank(net.n_nodes),
                      np.full(2, np.nan))
