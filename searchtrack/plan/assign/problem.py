"""One action per UAV on a particle belief: the frozen assignment problem and its plan.

Each UAV ``r`` has candidate actions ``Q^r``; an action is the sequence of ``T`` sensor poses it
produces (an array ``(T, pose_dim)``, paper 003 §2.3). The belief is a particle PHD (any
:class:`~searchtrack.estimate.particle_belief.ParticleBelief`): positions ``(N, p)`` and weights
``(N,)`` summing to the expected number of targets. The objective is a spec
(:class:`~searchtrack.plan.assign.objectives.ExpectedDetections`,
:class:`~searchtrack.plan.assign.objectives.MutualInformation`). The detection probabilities
``p_d(x_j | q_{r,a,t})`` are computed once, vectorised, on first use.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from searchtrack.core.checks import readonly
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import BoolArray, FloatArray
from searchtrack.estimate.particle_belief import ParticleBelief, checked_arrays
from searchtrack.models.footprint import detection_matrix
from searchtrack.models.particle_models import DetectionSensor
from searchtrack.plan.assign.objectives import ExpectedDetections, Objective

#: ``p_d`` is capped at ``1 − PD_CAP_EPS`` where ``−log(1 − p_d)`` is needed.
PD_CAP_EPS = 1e-9




@dataclass(frozen=True, eq=False)
class AssignmentProblem:
    """Choose one candidate action per UAV to maximise a monotone submodular objective.

    Parameters
    ----------
    actions
        One array per UAV of shape ``(A_r, T, pose_dim)``: ``A_r ≥ 1`` candidate actions, each
        ``T`` poses (``T`` and ``pose_dim`` shared by all UAVs; pose starts ``[x, y, z]``).
    belief
        The particle belief; its ``(N, p)`` positions (m) and ``(N,)`` non-negative PHD weights
        are copied, read-only, into :attr:`positions` and :attr:`weights`.
    sensor
        The detection model (``p_d`` is all the objectives use).
    objective
        :class:`ExpectedDetections` (003 eq. 13, the default) or
        :class:`~searchtrack.plan.assign.objectives.MutualInformation` (003 §2.5).
    min_separation_m
        Actions of two UAVs conflict when their positions at some common step are closer than
        this (003 §2.3 collision pruning); 0 disables the check.
    origins
        Optional ``(R, ≥3)`` current UAV poses (the NLP bounds its first step from them).
    name
        Free label for logs.
    """

    actions: tuple[FloatArray, ...]
    belief: ParticleBelief
    sensor: DetectionSensor
    objective: Objective = field(default_factory=ExpectedDetections)
    min_separation_m: float = 0.0
    origins: FloatArray | None = None
    name: str = "assignment"
    positions: FloatArray = field(init=False, repr=False)
    weights: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        acts = tuple(readonly(np.asarray(a, dtype=np.float64))
                     for a in self.actions) if isinstance(
            self.actions, (list, tuple)) else ()
        if not acts:
            raise InvalidInputError("actions", self.actions, "must be a non-empty list of arrays")
        shape = acts[0].shape[1:]
        for r, a in enumerate(acts):
            if a.ndim != 3 or a.shape[0] < 1 or a.shape[1] < 1 or a.shape[2] < 3:
                raise InvalidInputError(f"actions[{r}]", a.shape,
                                        "must have shape (A_r >= 1, T >= 1, pose_dim >= 3)")
            if a.shape[1:] != shape:
                raise InvalidInputError(f"actions[{r}]", a.shape,
                                        f"every UAV needs the same (T, pose_dim) {shape}")
            if not np.all(np.isfinite(a)):
                raise InvalidInputError(f"actions[{r}]", "non-finite", "poses must be finite")
        if not isinstance(self.belief, ParticleBelief):
            raise InvalidInputError("belief", self.belief, "must implement ParticleBelief")
        pos, w = checked_arrays(self.belief.positions, self.belief.weights, prefix="belief.")
        if not isinstance(self.sensor, DetectionSensor):
            raise InvalidInputError("sensor", self.sensor, "must implement DetectionSensor")
        if not isinstance(self.objective, Objective):
            raise InvalidInputError("objective", self.objective,
                                    "must be an Objective (ExpectedDetections() or "
                                    "MutualInformation(...))")
        sep = self.min_separation_m
        if not isinstance(sep, (int, float)) or not (math.isfinite(sep) and sep >= 0.0):
            raise InvalidInputError("min_separation_m", sep, "must be finite and >= 0")
        if self.origins is not None:
            org = readonly(np.asarray(self.origins, dtype=np.float64))
            if org.ndim != 2 or org.shape[0] != len(acts) or org.shape[1] < 3 or not np.all(
                    np.isfinite(org)):
                raise InvalidInputError("origins", org.shape,
                                        f"must be a finite ({len(acts)}, >=3) array")
            object.__setattr__(self, "origins", org)
        object.__setattr__(self, "actions", acts)
        object.__setattr__(self, "positions", pos)
        object.__setattr__(self, "weights", w)

    @property
    def robots(self) -> int:
        """Number of UAVs ``R``."""
        return len(self.actions)

    @property
    def horizon(self) -> int:
        """Poses per action ``T``."""
        return int(self.actions[0].shape[1])

    def n_actions(self, robot: int) -> int:
        """``|Q^r|``."""
        return int(self.actions[robot].shape[0])

    @cached_property
    def detection(self) -> tuple[FloatArray, ...]:
        """Per UAV, ``(A_r, T, N)`` detection probabilities, from one batched sensor call."""
        poses = np.concatenate([a.reshape(-1, a.shape[2]) for a in self.actions])
        flat = detection_matrix(self.sensor, poses, self.positions)
        out: list[FloatArray] = []
        start = 0
        n = self.positions.shape[0]
        for a in self.actions:
            k = a.shape[0] * a.shape[1]
            block = flat[start:start + k].reshape(a.shape[0], a.shape[1], n)
            block.setflags(write=False)
            out.append(block)
            start += k
        return tuple(out)

    @cached_property
    def hit(self) -> tuple[FloatArray, ...]:
        """Per UAV, ``(A_r, N)`` probabilities ``1 − Π_t (1 − p_d)`` that an action detects a
        particle (a view of :attr:`detection` when ``T = 1``: no copy)."""
        out = []
        for block in self.detection:
            if block.shape[1] == 1:
                out.append(block[:, 0])
                continue
            m = np.subtract(1.0, block[:, 0])
            for t in range(1, block.shape[1]):
                m *= 1.0 - block[:, t]
            np.subtract(1.0, m, out=m)
            m.setflags(write=False)
            out.append(m)
        return tuple(out)

    @cached_property
    def miss(self) -> tuple[FloatArray, ...]:
        """Per UAV, ``(A_r, N)`` miss probabilities ``Π_t (1 − p_d)`` of each action."""
        out = []
        for h in self.hit:
            m = 1.0 - h
            m.setflags(write=False)
            out.append(m)
        return tuple(out)

    @cached_property
    def log_miss(self) -> tuple[FloatArray, ...]:
        """Per UAV, ``(A_r, N)`` values ``ℓ = −Σ_t log(1 − p_d)`` (``p_d`` capped below 1)."""
        out = []
        for block in self.detection:
            m = -np.sum(np.log1p(-np.minimum(block, 1.0 - PD_CAP_EPS)), axis=1)
            m.setflags(write=False)
            out.append(m)
        return tuple(out)

    @cached_property
    def conflicts(self) -> dict[tuple[int, int], BoolArray]:
        """``{(r, s): (A_r, A_s) bool}`` for ``r < s``: True where the two actions come closer
        than ``min_separation_m`` at a common step (empty when the check is off)."""
        if self.min_separation_m <= 0.0:
            return {}
        out: dict[tuple[int, int], BoolArray] = {}
        sep2 = self.min_separation_m**2
        for r in range(self.robots):
            for s in range(r + 1, self.robots):
                pr = self.actions[r][:, :, :3]
                ps = self.actions[s][:, :, :3]
                d2 = np.sum((pr[:, None, :, :] - ps[None, :, :, :]) ** 2, axis=3)
                bad = np.min(d2, axis=2) < sep2
                if np.any(bad):
                    out[(r, s)] = bad
        return out

    def compatible(self, selection: Sequence[tuple[int, int]], robot: int) -> BoolArray:
        """``(A_robot,)`` mask of the actions of ``robot`` that conflict with no selected one."""
        ok = np.ones(self.n_actions(robot), dtype=bool)
        for r, a in selection:
            if r < robot and (r, robot) in self.conflicts:
                ok &= ~self.conflicts[(r, robot)][a]
            elif r > robot and (robot, r) in self.conflicts:
                ok &= ~self.conflicts[(robot, r)][:, a]
        return ok


@dataclass(frozen=True, eq=False)
class Assignment:
    """The plan: the chosen action per UAV and the poses it flies.

    Parameters
    ----------
    actions
        Index of the chosen action of each UAV (for the NLP: the action it started from).
    poses
        ``(R, T, pose_dim)`` poses flown (the NLP moves them off the candidate set).
    """

    actions: tuple[int, ...]
    poses: FloatArray

    @classmethod
    def of(cls, problem: AssignmentProblem, actions: Sequence[int]) -> Assignment:
        """The plan that flies ``actions[r]`` of every UAV ``r``."""
        poses = np.stack([problem.actions[r][a] for r, a in enumerate(actions)])
        return cls(tuple(int(a) for a in actions), poses)

    @property
    def selection(self) -> tuple[tuple[int, int], ...]:
        """``((r, a), ...)`` pairs."""
        return tuple(enumerate(self.actions))
