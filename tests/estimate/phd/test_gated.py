"""The gated update passes equal the dense update on the standard scenario."""

from __future__ import annotations

import dataclasses

import numpy as np

from searchtrack.estimate.metrics import ospa
from searchtrack.estimate.phd import (
    PHDConfig,
    PHDState,
    SensorScan,
    extract,
    gated,
    predict,
    resample,
    update,
)
from searchtrack.sim.particles.scenario import standard_scenario

from .helpers import POSE


def test_measurement_grid_lists_the_measurements_within_the_gate_of_each_cell() -> None:
    """CSR lists per cell of the measurements within the gate of it (border cells reach outward,
    since particles' cells are clamped), increasing measurement index within a cell."""
    z = np.array([[5.0, 5.0], [95.0, 5.0], [-50.0, 5.0], [5.0, 250.0], [48.0, 5.0]])
    start, order = gated.measurement_grid(z, np.zeros(2), np.array([50.0, 50.0]),
                                          np.array([2, 2]), 10.0)
    assert start.tolist() == [0, 3, 4, 6, 6]
    assert order.tolist() == [0, 2, 4, 3, 1, 4]


def test_measurement_grid_finds_every_pair_inside_the_gate() -> None:
    """Every particle-measurement pair closer than the gate is listed in the particle's cell."""
    rng = np.random.default_rng(3)
    z = rng.uniform(-100.0, 1100.0, (60, 2))
    x = rng.uniform(0.0, 1000.0, (4000, 2))
    lo, size, shape, gate = np.zeros(2), np.array([1000.0 / 33, 1000.0 / 31]), \
        np.array([33, 31]), 90.0
    start, order = gated.measurement_grid(z, lo, size, shape, gate)
    cells = np.minimum((x // size).astype(np.int64), shape - 1)
    for xi, (c0, c1) in zip(x, cells, strict=True):
        q = c0 * shape[1] + c1
        listed = set(order[start[q]:start[q + 1]].tolist())
        near = np.flatnonzero(np.hypot(*(z - xi).T) < gate)
        assert set(near.tolist()) <= listed


def _run(cfg: PHDConfig, n_scans: int) -> list[tuple[PHDState, PHDState, np.ndarray]]:
    sc = standard_scenario(0, n_scans=n_scans)
    rng = np.random.default_rng(0)
    st, out = PHDState.empty(4, 2), []
    for z in sc.scans:
        updated = update(predict(st, sc.motion, cfg, sc.dt_s, rng),
                         [SensorScan(sc.sensor, POSE, z)], cfg)
        est = extract(updated, cfg)
        st = resample(updated, cfg, rng)
        out.append((updated, st, np.asarray(est.positions)))
    return out


def test_compiled_backend_equals_the_numpy_equations_on_the_standard_scenario() -> None:
    """Same generator, same draws: the compiled passes give the NumPy update's particles,
    weights, tags and records to rounding on every scan, hence the same OSPA and count."""
    sc = standard_scenario(0, n_scans=40)
    base = PHDConfig(particles_per_target=3000, min_particles=3000, max_particles=3000,
                     region=sc.sensor.area)
    ref = _run(dataclasses.replace(base, backend="numpy"), 40)
    fast = _run(base, 40)
    d_ref, d_fast = [], []
    for k, ((u1, s1, e1), (u2, s2, e2)) in enumerate(zip(ref, fast, strict=True)):
        for a, b in ((u1, u2), (s1, s2)):
            np.testing.assert_allclose(b.states, a.states, rtol=0, atol=1e-9)
            np.testing.assert_allclose(b.weights, a.weights, rtol=1e-9, atol=1e-300)
            np.testing.assert_array_equal(b.tags, a.tags)
            np.testing.assert_array_equal(b.labels, a.labels)
        for f in ("detection_states", "detection_masses", "missed_states", "missed_existence",
                  "seed_positions", "seed_masses"):
            np.testing.assert_allclose(getattr(u2.record, f), getattr(u1.record, f),
                                       rtol=1e-9, atol=1e-12)
        if k >= 20:
            d_ref.append(ospa(e1, sc.truth[k][:, :2], 100.0, 1.0))
            d_fast.append(ospa(e2, sc.truth[k][:, :2], 100.0, 1.0))
            assert e1.shape == e2.shape
    assert np.mean(d_fast) == np.mean(d_ref) or abs(np.mean(d_fast) - np.mean(d_ref)) < 1e-9
