"""The SMC-PHD filter stepped by predict and update draws and answers exactly as ``step``."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.phd import PHDConfig, PHDState, SensorScan, step
from searchtrack.estimate.phd.stepping import PHDFilter
from searchtrack.estimate.stepping import PointEstimates, SteppedFilter
from searchtrack.models.motion import ConstantVelocity

from .helpers import AREA, POSE, cloud, phd_state, sensor


def _scans(seed: int, n: int) -> list[np.ndarray]:
    """``n`` scans of two targets near (300, 300) and (700, 600), with noise."""
    rng = np.random.default_rng(seed)
    centres = np.array([[300.0, 300.0], [700.0, 600.0]])
    return [centres + 10.0 * rng.standard_normal(centres.shape) for _ in range(n)]


@pytest.mark.parametrize("extraction", ["attribution", "kmeans"])
def test_predict_then_update_is_one_step(extraction: str) -> None:
    """Over several scans, predict and update with one generator give the states and the
    estimates of ``step`` with an equal generator, bit for bit."""
    motion, pos = ConstantVelocity(0.5), sensor(clutter=2.0)
    cfg = PHDConfig(region=AREA, extraction=extraction)
    start = phd_state(cloud((300.0, 300.0), 200, 1.0), cloud((700.0, 600.0), 200, 1.0, seed=1))
    stepped = PHDFilter(start, motion, pos, cfg, np.random.default_rng(4))
    assert isinstance(stepped, SteppedFilter) and isinstance(stepped, PointEstimates)
    assert stepped.estimates_xy().shape == (0, 2)
    rng = np.random.default_rng(4)
    state = start
    for z in _scans(0, 5):
        state, est = step(state, [SensorScan(pos, POSE, z)], motion, cfg, 1.0, rng)
        stepped.predict(1.0)
        got = stepped.update([z], POSE)
        np.testing.assert_array_equal(got.states, est.states)
        np.testing.assert_array_equal(stepped.state.states, state.states)
        np.testing.assert_array_equal(stepped.state.weights, state.weights)
    np.testing.assert_array_equal(stepped.estimates_xy(), est.positions[:, :2])
    assert len(est) == 2


def test_several_sensors_update_in_one_scan() -> None:
    """Two poses, two measurement arrays: the iterated corrector of ``step`` with both."""
    motion, pos = ConstantVelocity(0.5), sensor(clutter=1.0)
    cfg = PHDConfig(region=AREA)
    start = phd_state(cloud((300.0, 300.0), 100, 1.0))
    poses = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]])
    z = [np.array([[301.0, 299.0]]), np.array([[299.0, 302.0]])]
    stepped = PHDFilter(start, motion, pos, cfg, np.random.default_rng(1))
    stepped.predict(1.0)
    got = stepped.update(z, poses)
    state, est = step(start, [SensorScan(pos, q, m) for q, m in zip(poses, z, strict=True)],
                      motion, cfg, 1.0, np.random.default_rng(1))
    np.testing.assert_array_equal(got.states, est.states)
    np.testing.assert_array_equal(stepped.state.states, state.states)


def test_bad_inputs_are_refused_by_name() -> None:
    """A pose count unlike the scan's, a seed instead of a generator and a state of another
    kind are refused, naming the field."""
    motion, pos, cfg = ConstantVelocity(0.5), sensor(), PHDConfig(region=AREA)
    stepped = PHDFilter(PHDState.empty(4), motion, pos, cfg, np.random.default_rng(0))
    with pytest.raises(InvalidInputError) as info:
        stepped.update([np.zeros((0, 2)), np.zeros((0, 2))], POSE)
    assert info.value.field == "pose"
    with pytest.raises(InvalidInputError) as info:
        PHDFilter(PHDState.empty(4), motion, pos, cfg, 3)  # type: ignore[arg-type]
    assert info.value.field == "rng"
    with pytest.raises(InvalidInputError) as info:
        PHDFilter(None, motion, pos, cfg, np.random.default_rng(0))  # type: ignore[arg-type]
    assert info.value.field == "state"
