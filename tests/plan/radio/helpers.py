"""Small scenarios and labelled particle beliefs shared by the radio planning tests."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from searchtrack.core.types import FloatArray
from searchtrack.estimate.labelled_particles import LabelledParticles
from searchtrack.models.radio import RadioSignal, UavModel
from searchtrack.models.radio.calibration import DEFAULT_CALIBRATION, calibrated
from searchtrack.models.radio.scenario import RadioScenario
from searchtrack.plan.radio import RadioPlanProblem, RadioPlanSettings

#: The UAV pose most tests start from: mid-area, heading east.
POSE = np.array([600.0, 600.0, 0.0])


def scenario(n_headings: int = 4, calibration: str = DEFAULT_CALIBRATION) -> RadioScenario:
    """The paper's scenario with ``n_headings`` primitives (4 keeps brute force small) and the
    signal's ``calibration``."""
    return RadioScenario(signal=calibrated(RadioSignal(), calibration),
                         uav=UavModel(n_headings=n_headings))


def belief(centres: Sequence[Sequence[float]], r: Sequence[float], *, spread_m: float = 60.0,
           n: int = 200, seed: int = 0, tau_s: float = 0.3,
           tau_spread_s: float = 0.003) -> LabelledParticles:
    """Gaussian particle clouds around ``centres`` (one per label of the signal), at rest,
    modes half and half, pulse offsets around ``tau_s``."""
    labels = RadioSignal().n_labels
    assert len(centres) == len(r) == labels
    rng = np.random.default_rng(seed)
    c = np.asarray(centres, dtype=np.float64)
    x = np.zeros((labels, n, 4))
    x[:, :, 0] = c[:, None, 0] + spread_m * rng.standard_normal((labels, n))
    x[:, :, 2] = c[:, None, 1] + spread_m * rng.standard_normal((labels, n))
    mode = rng.integers(0, 2, (labels, n)).astype(np.int8)
    tau = np.mod(tau_s + tau_spread_s * rng.standard_normal((labels, n)), 1.0)
    w = rng.uniform(0.5, 1.5, (labels, n))
    return LabelledParticles(x, mode, tau, w / w.sum(axis=1, keepdims=True),
                             np.asarray(r, dtype=np.float64))


def spread_belief(seed: int = 0, n: int = 200) -> LabelledParticles:
    """Four tags around the default pose at mixed certainty."""
    return belief([[850.0, 650.0], [500.0, 900.0], [300.0, 400.0], [1000.0, 1100.0]],
                  [0.9, 0.6, 0.3, 0.97], seed=seed, n=n)


def problem(b: LabelledParticles | None = None, pose: FloatArray = POSE, *,
            n_headings: int = 4, calibration: str = DEFAULT_CALIBRATION,
            **settings: object) -> RadioPlanProblem:
    """A planning problem on ``b`` (default :func:`spread_belief`) with small settings
    (``plan_particles = 60``, ``horizon = 2``) unless overridden."""
    kw: dict[str, object] = {"plan_particles": 60, "horizon": 2}
    kw.update(settings)
    return RadioPlanProblem(spread_belief() if b is None else b, pose,
                            scenario(n_headings, calibration),
                            RadioPlanSettings(**kw))  # type: ignore[arg-type]


def unit_heading(angle: float) -> FloatArray:
    """``(cos, sin)`` of ``angle``."""
    return np.array([math.cos(angle), math.sin(angle)])


def tag_ahead(r_tag: float = 0.99, n: int = 200) -> LabelledParticles:
    """Label 0 certain and tight 100 m ahead of :data:`POSE` (heading east), the others far."""
    b = belief([[700.0, 600.0], [1300.0, 200.0], [200.0, 1300.0], [1300.0, 1300.0]],
               [r_tag, 0.8, 0.8, 0.8], n=n)
    b.x[0, :, 0] = 700.0 + 15.0 * (b.x[0, :, 0] - 700.0) / 60.0
    b.x[0, :, 2] = 600.0 + 15.0 * (b.x[0, :, 2] - 600.0) / 60.0
    return b


def surrounded(n: int = 200, radius_m: float = 300.0, seed: int = 0) -> LabelledParticles:
    """Every label certain and spread uniformly over a disc of ``radius_m`` around
    :data:`POSE`: no path of a few intervals keeps P(nobody within 50 m) above 0.9."""
    b = belief([POSE[:2].tolist()] * 4, [1.0] * 4, n=n, seed=seed)
    rng = np.random.default_rng(seed)
    rho = radius_m * np.sqrt(rng.random((4, n)))
    phi = rng.uniform(-np.pi, np.pi, (4, n))
    b.x[:, :, 0] = POSE[0] + rho * np.cos(phi)
    b.x[:, :, 2] = POSE[1] + rho * np.sin(phi)
    return b
