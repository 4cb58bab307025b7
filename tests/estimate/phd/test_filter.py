"""One scan of the SMC-PHD filter chained over a run: determinism and tracking quality."""

from __future__ import annotations

import numpy as np

from searchtrack.estimate.metrics import ospa
from searchtrack.estimate.phd import (
    PHDConfig,
    PHDState,
    SensorScan,
    extract,
    predict,
    resample,
    step,
    update,
)
from searchtrack.models.motion import ConstantVelocity
from searchtrack.models.position_sensor import PositionSensor
from searchtrack.sim.particles.scenario import standard_scenario

from .helpers import AREA, POSE


def test_filter_is_deterministic_for_a_seed() -> None:
    """Two runs with the same seed give identical particles and estimates."""
    sc = standard_scenario(3, n_targets=3, n_scans=15)
    cfg = PHDConfig(region=AREA)

    def run(seed: int) -> tuple[np.ndarray, np.ndarray]:
        rng = np.random.default_rng(seed)
        st = PHDState.empty(4)
        for z in sc.scans:
            st, est = step(st, [SensorScan(sc.sensor, POSE, z)], sc.motion, cfg, 1.0, rng)
        return st.states, est.states

    a, b = run(7), run(7)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])

def test_filter_tracks_the_standard_scenario() -> None:
    """On a 3-target standard-like run the late-scan OSPA stays well under the cut-off."""
    sc = standard_scenario(5, n_targets=3, n_scans=40)
    cfg = PHDConfig(region=AREA)
    rng = np.random.default_rng(0)
    st = PHDState.empty(4)
    dist = []
    for k, z in enumerate(sc.scans):
        st, est = step(st, [SensorScan(sc.sensor, POSE, z)], sc.motion, cfg, 1.0, rng)
        if k >= 15:
            dist.append(ospa(est.positions, sc.truth[k][:, :2], c=100.0))
    assert np.mean(dist) < 30.0


def test_step_is_predict_update_extract_resample() -> None:
    """One step equals predict, update, extract and resample in a row with the same generator;
    the k-means estimates come from the weights before resampling."""
    motion = ConstantVelocity(0.5)
    cfg = PHDConfig(region=AREA, extraction="kmeans")
    sensor = PositionSensor(0.9, 10.0, 5.0, AREA)
    st = update(PHDState.empty(4), [SensorScan(sensor, POSE, np.array([[300.0, 300.0]]))], cfg)
    scans = [SensorScan(sensor, POSE, np.array([[302.0, 301.0], [800.0, 100.0]]))]
    after, est = step(st, scans, motion, cfg, 1.0, np.random.default_rng(4))
    rng = np.random.default_rng(4)
    updated = update(predict(st, motion, cfg, 1.0, rng), scans, cfg)
    by_hand = resample(updated, cfg, rng)
    np.testing.assert_array_equal(after.states, by_hand.states)
    np.testing.assert_array_equal(after.weights, by_hand.weights)
    np.testing.assert_array_equal(est.states, extract(updated, cfg).states)
    assert not np.array_equal(est.states, extract(by_hand, cfg).states)
