"""The seams between particle beliefs and the world: target motion and detection sensors.

Particle filters (the SMC-PHD of papers 003 and 004) and the planners that score actions on
particle beliefs only talk to the world through these two protocols, so any motion model (random
walk, constant velocity, static, a Gaussian-process velocity field) and any sensor (a camera with
logistic detection probability, an omnidirectional 3-D ranging sensor, a plain position sensor)
can be combined.

Conventions
-----------
- A target state is a row of an ``(N, d)`` float array; its first ``position_dim`` columns are the
  position in metres (2 on the ground plane, 3 in the air), any further columns are velocities.
- A sensor pose is a 1-D float array whose first 3 entries are the sensor position ``[x, y, z]``
  (metres); sensors may read further entries (yaw, pitch in radians) and document them.
- A measurement is a row of a ``(k, meas_dim)`` float array.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from searchtrack.core.types import FloatArray


@runtime_checkable
class MotionModel(Protocol):
    """Single-target Markov motion ``f(x' | x)`` sampled on particles."""

    @property
    def state_dim(self) -> int:
        """Length ``d`` of a state row."""
        ...

    @property
    def position_dim(self) -> int:
        """How many leading state columns are the position (2 or 3)."""
        ...

    def propagate(self, states: FloatArray, dt_s: float, rng: np.random.Generator) -> FloatArray:
        """A new ``(N, d)`` array: each row drawn from ``f(· | row)`` over ``dt_s`` seconds."""
        ...


@runtime_checkable
class DetectionSensor(Protocol):
    """A sensor that detects targets with probability ``p_d(x | q)`` and measures them with
    likelihood ``g(z | x, q)``, amid Poisson clutter of intensity ``c(z | q)``."""

    @property
    def meas_dim(self) -> int:
        """Length of a measurement row."""
        ...

    def detection_probability(self, pose: FloatArray, positions: FloatArray) -> FloatArray:
        """``(N,)`` values ``p_d(x | q)`` in ``[0, 1]`` for ``(N, position_dim)`` positions."""
        ...

    def likelihood(
        self, pose: FloatArray, measurements: FloatArray, positions: FloatArray
    ) -> FloatArray:
        """``(k, N)`` densities ``g(z_i | x_j, q)`` for ``(k, meas_dim)`` measurements."""
        ...

    def clutter_intensity(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """``(k,)`` clutter PHD ``c(z_i | q)`` (0 for a clutter-free sensor)."""
        ...

    def to_position(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """``(k, position_dim)`` positions that produce the measurements noise-free (``h⁻¹``),
        used for measurement-driven birth."""
        ...
