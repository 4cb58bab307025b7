"""The receding-horizon search planner of paper 004 (§4.1, eqs. 7–8).

Every sequence of ``τ`` lattice moves from the current position (eq. 7) that stays in the search
box is scored ``α E(q) + T(q)`` (eq. 8): ``E`` the exploration bonus along the sequence (eq. 10),
``T`` either the centre probabilities of the estimated targets (eq. 11) or the MI of the targets
with the empty measurement along the horizon. The planner returns the best sequence; only its
first waypoint is flown before replanning. Enumeration is exhaustive (``6^τ`` for 3-D moves);
ties go to the first sequence in lexicographic move order (``+x, +y, +z, −x, −y, −z``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.particle_models import DetectionSensor
from searchtrack.plan.assign.actions import lattice_moves, lattice_sequences
from searchtrack.plan.assign.exploration import (
    ExplorationBonus,
    centre_probability,
    empty_horizon_mi,
)

Refinement = Literal["centre", "mi", "none"]


@dataclass(frozen=True)
class RecedingConfig:
    """Parameters of the planner.

    Parameters
    ----------
    step_m
        Length of one lattice move (12 m in 004's simulations).
    horizon
        ``τ``, moves per sequence (004 compares 1, 2, 3).
    alpha
        Weight of exploration against refinement (not given in 004, ambiguity A3).
    refinement
        ``"centre"`` (eq. 11), ``"mi"`` (empty-horizon MI) or ``"none"`` (exploration only).
    dims
        2 (four planar moves) or 3 (six moves).
    """

    step_m: float = 12.0
    horizon: int = 1
    alpha: float = 1.0
    refinement: Refinement = "centre"
    dims: int = 3

    def __post_init__(self) -> None:
        if not (math.isfinite(self.step_m) and self.step_m > 0.0):
            raise InvalidInputError("step_m", self.step_m, "must be finite and > 0")
        if not isinstance(self.horizon, int) or not 1 <= self.horizon <= 5:
            raise InvalidInputError("horizon", self.horizon, "must be an integer in [1, 5]")
        if not (math.isfinite(self.alpha) and self.alpha >= 0.0):
            raise InvalidInputError("alpha", self.alpha, "must be finite and >= 0")
        if self.refinement not in ("centre", "mi", "none"):
            raise InvalidInputError("refinement", self.refinement,
                                    "must be 'centre', 'mi' or 'none'")
        if self.dims not in (2, 3):
            raise InvalidInputError("dims", self.dims, "must be 2 or 3")


@dataclass(frozen=True, eq=False)
class SearchStep:
    """The planner's answer: the best sequence, its first waypoint and its score parts."""

    sequence: FloatArray
    exploration: float
    refinement: float
    score: float
    candidates: int

    @property
    def waypoint(self) -> FloatArray:
        """``q*_{k+1}``, the position to fly to next."""
        out: FloatArray = self.sequence[0]
        return out


def plan_search_step(
    position: FloatArray, bounds: FloatArray, bonus: ExplorationBonus, sensor: DetectionSensor,
    config: RecedingConfig, *, centres: FloatArray | None = None,
    positions: FloatArray | None = None, weights: FloatArray | None = None,
) -> SearchStep:
    """Maximise ``α E(q) + T(q)`` over every in-box move sequence from ``position``.

    Parameters
    ----------
    position
        Current UAV position ``[x, y, z]``.
    bounds
        ``(3, 2)`` search box; sequences leaving it are excluded (ambiguity A6).
    bonus
        The exploration-bonus grid, already updated with the poses flown so far.
    centres
        ``(c, 3)`` estimated target centres (for ``refinement="centre"``).
    positions, weights
        The particle belief (for ``refinement="mi"``).

    Raises
    ------
    InvalidInputError
        Missing refinement inputs, or no move sequence stays in the box.
    """
    b = np.asarray(bounds, dtype=np.float64)
    if b.shape != (3, 2):
        raise InvalidInputError("bounds", bounds, "must be (3, 2)")
    if config.refinement == "centre" and centres is None:
        raise InvalidInputError("centres", centres, "refinement='centre' needs the centres")
    if config.refinement == "mi" and (positions is None or weights is None):
        raise InvalidInputError("positions", positions, "refinement='mi' needs the belief")
    moves = lattice_moves(config.step_m, config.dims)
    if config.dims == 2:
        moves = np.concatenate([moves, np.zeros((moves.shape[0], 1))], axis=1)
    seqs = lattice_sequences(np.asarray(position, dtype=np.float64), moves, config.horizon, b)
    if seqs.shape[0] == 0:
        raise InvalidInputError("position", position, "no move sequence stays inside bounds")
    ex = bonus.at(seqs.reshape(-1, 3)).reshape(seqs.shape[:2]).sum(axis=1)
    ref = np.zeros(seqs.shape[0])
    if config.refinement == "centre" and centres is not None and centres.shape[0] > 0:
        ref = np.array([centre_probability(sensor, centres, s) for s in seqs])
    elif config.refinement == "mi" and positions is not None and weights is not None:
        ref = np.array([empty_horizon_mi(sensor, positions, weights, s) for s in seqs])
    score = config.alpha * ex + ref
    best = int(np.argmax(score))
    return SearchStep(seqs[best], float(ex[best]), float(ref[best]), float(score[best]),
                      int(seqs.shape[0]))

