"""SMC-PHD prediction (paper 003, eq. 4): survival, motion and births.

Survivors are moved by the motion model and their weights multiplied by ``p_s``. Newborns come
from two sources, both labelled ``NEWBORN``:

- *measurement-driven* (Ristic, Clark & Vo 2010; Ristic et al. 2012): the seeds left by the last
  update, one per measurement ``z`` at ``h⁻¹(z)`` with mass ``ν_z``; each seed gets
  ``birth_particles_per_measurement`` particles around it (position noise
  ``birth_position_sigma_m``, zero-mean velocity noise ``birth_velocity_sigma_mps``) of weight
  ``ν_z / J``. They are born at the previous scan time and moved with the survivors, so a
  measurement seeds a birth but is never used twice to update it.
- an optional *grid* birth intensity (paper 003's birth counts), drawn at the current time.

With ``config.region`` set, particles predicted outside it are dropped (``p_s = 0`` outside the
surveillance region: targets that leave it are gone).
"""

from __future__ import annotations

import threading

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.phd import compiled
from searchtrack.estimate.phd.config import PHDConfig
from searchtrack.estimate.phd.state import NEWBORN, NO_TAG, PERSISTENT, PHDState, UpdateRecord
from searchtrack.models.motion import ConstantVelocity
from searchtrack.models.particle_models import MotionModel


def _newborn_states(positions: FloatArray, state_dim: int, config: PHDConfig,
                    rng: np.random.Generator) -> FloatArray:
    """``(J, d)`` states at ``positions`` with zero-mean random velocities."""
    n, p = positions.shape
    out = np.empty((n, state_dim))
    out[:, :p] = positions
    if state_dim > p:
        out[:, p:] = config.birth_velocity_sigma_mps * rng.standard_normal((n, state_dim - p))
    return out


def predict(state: PHDState, motion: MotionModel, config: PHDConfig, dt_s: float,
            rng: np.random.Generator) -> PHDState:
    """The predicted PHD ``v_{k|k-1}`` after ``dt_s`` seconds.

    Parameters
    ----------
    state
        The posterior at the previous scan, with its birth seeds.
    motion
        Single-target motion model; its ``state_dim`` must match the particles'.
    config
        Survival and birth settings.
    dt_s
        Time since the previous scan (s).
    rng
        Source of every random draw.
    """
    d, p = state.state_dim, state.position_dim
    j = config.birth_particles_per_measurement
    keep = state.record.seed_masses > 0.0
    seeds, seed_mass = state.record.seed_positions[keep], state.record.seed_masses[keep]
    born_pos = np.repeat(seeds, j, axis=0)
    if born_pos.shape[0]:
        born_pos = born_pos + config.birth_position_sigma_m * rng.standard_normal(born_pos.shape)
    born = _newborn_states(born_pos, d, config, rng)
    if config.backend == "numba" and isinstance(motion, ConstantVelocity) and \
            motion.state_dim == d:
        return _predict_compiled(state, born, seed_mass / j, motion, config, dt_s, rng)
    moved = motion.propagate(np.vstack([state.states, born]), dt_s, rng)
    survival = (config.survival_probability if config.survival_map is None else
                np.asarray(config.survival_map.survival(state.positions, dt_s), dtype=np.float64))
    weights = [state.weights * survival, np.repeat(seed_mass / j, j)]
    labels = [np.full(state.n_particles, PERSISTENT), np.full(born.shape[0], NEWBORN)]
    tags = [state.tags, np.full(born.shape[0], NO_TAG)]
    grid = _grid_states(state, config, rng)
    if grid is not None:
        moved = np.vstack([moved, grid])
        weights.append(np.full(grid.shape[0], grid_mass(config) / grid.shape[0]))
        labels.append(np.full(grid.shape[0], NEWBORN))
        tags.append(np.full(grid.shape[0], NO_TAG))
    out = PHDState(moved, np.concatenate(weights), np.concatenate(labels).astype(np.int64),
                   np.concatenate(tags).astype(np.int64), p, UpdateRecord.empty(d, p))
    if config.region is None:
        return out
    pos = out.positions
    inside = np.all((pos >= config.region[:, 0]) & (pos <= config.region[:, 1]), axis=1)
    return out if bool(inside.all()) else out.select(inside)


def grid_mass(config: PHDConfig) -> float:
    """Mass of the grid birth intensity per scan (0 without one)."""
    return 0.0 if config.birth_grid is None else config.birth_grid.mass


def _grid_states(state: PHDState, config: PHDConfig,
                 rng: np.random.Generator) -> FloatArray | None:
    """The grid births' states (drawn now), or ``None`` without a grid birth intensity."""
    grid = config.birth_grid
    if grid is None or grid.mass <= 0.0:
        return None
    if grid.bounds.shape[0] != state.position_dim:
        raise InvalidInputError("birth_grid", grid.bounds.shape,
                                f"must have {state.position_dim} dimensions like the particles")
    return _newborn_states(grid.sample(rng), state.state_dim, config, rng)


_SCRATCH = threading.local()


def motion_noise(rng: np.random.Generator, n: int, d: int) -> FloatArray:
    """``rng.standard_normal((n, d))``'s draws, written into a buffer each thread keeps and
    reuses (grown by a quarter when too small), so a prediction does not map fresh pages for
    its noise; the result is valid until the thread's next call."""
    buf: FloatArray | None = getattr(_SCRATCH, "noise", None)
    if buf is None or buf.shape[0] < n or buf.shape[1] != d:
        rows = n if buf is None or buf.shape[1] != d else max(n, buf.shape[0] + buf.shape[0] // 4)
        buf = np.empty((rows, d))
        _SCRATCH.noise = buf
    out = buf[:n]
    rng.standard_normal(out=out)
    return out


def _predict_compiled(state: PHDState, born: FloatArray, born_mass: FloatArray,
                      motion: ConstantVelocity, config: PHDConfig, dt_s: float,
                      rng: np.random.Generator) -> PHDState:
    """The prediction by one compiled pass per block of particles (survivors, measurement
    births, grid births), with the draws of the NumPy equations in their order."""
    d, p = state.state_dim, state.position_dim
    dt = checks.non_negative("dt_s", dt_s)
    n_moved = state.n_particles + born.shape[0]
    noise = motion_noise(rng, n_moved, d) if dt != 0.0 else None
    survival = np.array([config.survival_probability]) if config.survival_map is None else \
        np.asarray(config.survival_map.survival(state.positions, dt_s), dtype=np.float64)
    j = config.birth_particles_per_measurement
    untagged = np.full(born.shape[0], NO_TAG, dtype=np.int64)
    one = np.ones(1)
    blocks = [compiled.Block(state.states, state.weights, survival, state.tags, PERSISTENT, True),
              compiled.Block(born, np.repeat(born_mass, j), one, untagged, NEWBORN, True)]
    grid = _grid_states(state, config, rng)
    if grid is not None:
        blocks.append(compiled.Block(grid, np.full(grid.shape[0], grid_mass(config) /
                                                   grid.shape[0]), one,
                                     np.full(grid.shape[0], NO_TAG, dtype=np.int64), NEWBORN,
                                     False))
    x, w, labels, tags = compiled.predict_blocks(blocks, motion, dt, noise, config.region)
    return PHDState(x, w, labels, tags, p, UpdateRecord.empty(d, p))
