"""The standard multi-target scenario for particle-PHD benchmarks.

Ten nearly-constant-velocity targets (``q = 0.5`` m²/s³, as Stone Soup's
``ConstantVelocity(0.5)``) in a 1000 m × 1000 m area, 100 scans 1 s apart, a position sensor with
``p_d = 0.9``, ``σ = 10`` m and 10 clutter points per scan. All targets exist from the first scan
to the last: each starts uniformly in the inner 80 % of the area with a velocity ``N(0, 3² I)``
m/s and moves by the CV model; trajectories that leave the area are rejected and redrawn, so the
targets are exactly nearly-constant-velocity and the true count is always 10.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.types import FloatArray
from searchtrack.models.motion import ConstantVelocity
from searchtrack.models.position_sensor import PositionSensor, area_array

STANDARD_AREA = ((0.0, 1000.0), (0.0, 1000.0))


@dataclass(frozen=True)
class PHDScenario:
    """Truth and scans of one run.

    Attributes
    ----------
    truth
        ``(T, n, 4)`` true states ``[x, y, vx, vy]`` at each scan.
    scans
        ``T`` arrays ``(k_t, 2)`` of detections (targets and clutter, shuffled).
    sensor, motion
        The models that generated them.
    dt_s
        Time between scans (s).
    """

    truth: FloatArray
    scans: tuple[FloatArray, ...]
    sensor: PositionSensor
    motion: ConstantVelocity
    dt_s: float


def _trajectories(n: int, t: int, box: FloatArray, motion: ConstantVelocity, dt: float,
                  speed: float, rng: np.random.Generator) -> FloatArray:
    """``(t, n, 4)`` CV trajectories that stay inside ``box``, by rejection in batches."""
    lo, hi = box[:, 0], box[:, 1]
    kept: list[FloatArray] = [np.empty((t, 0, 4))]
    while sum(k.shape[1] for k in kept) < n:
        m = 4 * n
        x = np.empty((m, 4))
        x[:, :2] = lo + (hi - lo) * (0.1 + 0.8 * rng.random((m, 2)))
        x[:, 2:] = speed * rng.standard_normal((m, 2))
        path = np.empty((t, m, 4))
        path[0] = x
        for k in range(1, t):
            path[k] = motion.propagate(path[k - 1], dt, rng)
        pos = path[:, :, :2]
        ok = np.all((pos >= lo) & (pos <= hi), axis=(0, 2))
        kept.append(path[:, ok])
    return np.concatenate(kept, axis=1)[:, :n]


def standard_scenario(seed: int, *, n_targets: int = 10, n_scans: int = 100, dt_s: float = 1.0,
                      q: float = 0.5, pd: float = 0.9, sigma_m: float = 10.0,
                      clutter_rate: float = 10.0, area: ArrayLike = STANDARD_AREA,
                      speed_sigma_mps: float = 3.0) -> PHDScenario:
    """Simulate the standard scenario (defaults) from ``numpy.random.default_rng(seed)``;
    ``n_targets=0`` gives an empty ``(T, 0, 4)`` truth and clutter-only scans."""
    box = area_array("area", area)
    n = checks.count("n_targets", n_targets, 0)
    t = checks.count("n_scans", n_scans, 1)
    dt = checks.positive("dt_s", dt_s)
    speed = checks.non_negative("speed_sigma_mps", speed_sigma_mps)
    rng = np.random.default_rng(seed)
    motion = ConstantVelocity(q)
    sensor = PositionSensor(pd, sigma_m, clutter_rate, box)
    truth = _trajectories(n, t, box, motion, dt, speed, rng)
    scans = [sensor.measure(x, rng)[0] for x in truth]
    return PHDScenario(truth, tuple(scans), sensor, motion, dt)
