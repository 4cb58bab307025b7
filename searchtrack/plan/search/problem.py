"""One step of the search of paper 004 (§4.1): the frozen problem, its settings and its plan.

A UAV at ``position`` in a search box picks the next ``τ`` positions to fly. The problem holds
what the score ``α E(q) + T(q)`` (eq. 8) reads: the exploration bonus ``ι`` (eq. 9), the sensor,
and for the refinement term ``T`` the particle belief and the estimated target centres.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from searchtrack.core.checks import finite_array, non_negative, positive
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.particle_belief import ParticleBelief
from searchtrack.models.particle_models import DetectionSensor
from searchtrack.plan.search.exploration import ExplorationBonus
from searchtrack.plan.search.refinement import CentreProbability, Refinement


@dataclass(frozen=True)
class SearchSettings:
    """Parameters of the search planners.

    Parameters
    ----------
    step_m
        Length of one lattice move (12 m in 004's simulations).
    horizon
        ``τ``, moves per sequence (004 compares 1, 2, 3).
    alpha
        Weight ``α`` of exploration against refinement (004 gives no value; 1 by default).
    refinement
        The term ``T``: :class:`CentreProbability` (eq. 11),
        :class:`~searchtrack.plan.search.refinement.EmptyHorizonMI` or
        :class:`~searchtrack.plan.search.refinement.NoRefinement` (exploration only).
    dims
        2 (four planar moves) or 3 (six moves).
    lawnmower_spacing_m
        Line and layer spacing of the lawnmower backend (48 m in 004).
    """

    step_m: float = 12.0
    horizon: int = 1
    alpha: float = 1.0
    refinement: Refinement = field(default_factory=CentreProbability)
    dims: int = 3
    lawnmower_spacing_m: float = 48.0

    def __post_init__(self) -> None:
        positive("step_m", self.step_m)
        if not isinstance(self.horizon, int) or not 1 <= self.horizon <= 5:
            raise InvalidInputError("horizon", self.horizon, "must be an integer in [1, 5]")
        non_negative("alpha", self.alpha)
        if not isinstance(self.refinement, Refinement):
            raise InvalidInputError("refinement", self.refinement,
                                    "must be CentreProbability(), EmptyHorizonMI() or "
                                    "NoRefinement()")
        if self.dims not in (2, 3):
            raise InvalidInputError("dims", self.dims, "must be 2 or 3")
        positive("lawnmower_spacing_m", self.lawnmower_spacing_m)


@dataclass(frozen=True, eq=False)
class SearchProblem:
    """Choose the next ``τ`` positions of a searching UAV.

    Parameters
    ----------
    position
        Current UAV position ``[x, y, z]`` (m).
    bounds
        ``(3, 2)`` search box (m); sequences leaving it are excluded.
    bonus
        The exploration bonus, already updated with the poses flown so far.
    sensor
        The detection model (``π`` of eqs. 9–11).
    settings
        Step, horizon, ``α``, the refinement term.
    belief
        The particle belief (read by :class:`EmptyHorizonMI`); ``None`` when not needed.
    centres
        ``(c, 3)`` estimated target centres (read by :class:`CentreProbability`); ``None`` when
        not needed.
    name
        Free label for logs.

    Raises
    ------
    InvalidInputError
        A field out of its domain, or the refinement term's input missing.
    """

    position: FloatArray
    bounds: FloatArray
    bonus: ExplorationBonus
    sensor: DetectionSensor
    settings: SearchSettings = field(default_factory=SearchSettings)
    belief: ParticleBelief | None = None
    centres: FloatArray | None = None
    name: str = "search"

    def __post_init__(self) -> None:
        q = np.array(self.position, dtype=np.float64).reshape(-1)
        if q.shape != (3,) or not np.all(np.isfinite(q)):
            raise InvalidInputError("position", self.position, "must be a finite [x, y, z]")
        b = np.array(self.bounds, dtype=np.float64)
        if b.shape != (3, 2) or not np.all(np.isfinite(b)) or np.any(b[:, 1] < b[:, 0]):
            raise InvalidInputError("bounds", self.bounds, "must be (3, 2) with lo <= hi")
        if not isinstance(self.bonus, ExplorationBonus):
            raise InvalidInputError("bonus", self.bonus, "must be an ExplorationBonus")
        if not isinstance(self.sensor, DetectionSensor):
            raise InvalidInputError("sensor", self.sensor, "must implement DetectionSensor")
        if not isinstance(self.settings, SearchSettings):
            raise InvalidInputError("settings", self.settings, "must be a SearchSettings")
        if self.belief is not None and not isinstance(self.belief, ParticleBelief):
            raise InvalidInputError("belief", self.belief, "must implement ParticleBelief")
        if self.centres is not None:
            object.__setattr__(self, "centres", finite_array("centres", self.centres, (None, 3)))
        for arr in (q, b):
            arr.setflags(write=False)
        object.__setattr__(self, "position", q)
        object.__setattr__(self, "bounds", b)
        self.settings.refinement.check(self)

    def scores(self, sequences: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Exploration ``E`` (eq. 10), refinement ``T`` and score ``α E + T`` (eq. 8) of
        ``(S, τ, 3)`` sequences."""
        ex = self.bonus.at(sequences.reshape(-1, 3)).reshape(sequences.shape[:2]).sum(axis=1)
        ref = self.settings.refinement.scores(self, sequences)
        return ex, ref, self.settings.alpha * ex + ref


@dataclass(frozen=True, eq=False)
class SearchPlan:
    """A plan: the sequence of positions to fly, its score parts and how many were compared."""

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
