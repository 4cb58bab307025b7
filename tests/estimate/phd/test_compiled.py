"""The ``"numba"`` backend against the NumPy equations: births, survival maps, grid births,
several sensors, clutter-free scans and models it does not cover."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.estimate.metrics import ospa
from searchtrack.estimate.phd import (
    BirthGrid,
    PHDConfig,
    PHDState,
    SensorScan,
    compiled,
    predict,
    resample,
    step,
    update,
)
from searchtrack.models.motion import ConstantVelocity
from searchtrack.sim.particles.scenario import standard_scenario

from .helpers import AREA, POSE, cloud, phd_state, sensor


class Half:
    """Survival 0.5 left of x = 500 m, 1 elsewhere."""

    def survival(self, positions: np.ndarray, dt_s: float | None = None) -> np.ndarray:
        return np.where(positions[:, 0] < 500.0, 0.5, 1.0)


def _both(cfg: PHDConfig, scans: list[list[np.ndarray]], clutter: float, dt_s: float = 1.0,
          exact: int = 1000) -> None:
    """Run both backends with one seed over ``scans`` (per scan, one array per sensor) and
    compare the first ``exact`` predicted, updated and resampled PHDs."""
    runs = []
    for backend in ("numpy", "numba"):
        c = dataclasses.replace(cfg, backend=backend)
        rng = np.random.default_rng(5)
        st = phd_state(cloud((300.0, 300.0), 500, 1.0), cloud((700.0, 600.0), 300, 0.6, seed=1))
        out = []
        for zs in scans:
            p = predict(st, ConstantVelocity(0.5), c, dt_s, rng)
            u = update(p, [SensorScan(sensor(clutter=clutter), POSE, z) for z in zs], c)
            st = resample(u, c, rng)
            out += [p, u, st]
        runs.append(out)
    for a, b in list(zip(*runs, strict=True))[:exact]:
        np.testing.assert_allclose(b.states, a.states, rtol=0, atol=1e-9)
        np.testing.assert_allclose(b.weights, a.weights, rtol=1e-9, atol=1e-300)
        np.testing.assert_array_equal(b.tags, a.tags)
        np.testing.assert_array_equal(b.labels, a.labels)
        np.testing.assert_allclose(b.record.detection_masses, a.record.detection_masses,
                                   rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(b.record.missed_existence, a.record.missed_existence,
                                   rtol=1e-9)


SCANS = [[np.array([[302.0, 298.0], [690.0, 610.0], [100.0, 900.0]])],
         [np.array([[305.0, 301.0]])],
         [np.empty((0, 2))],
         [np.array([[308.0, 300.0], [900.0, 100.0]])]]


def test_same_particles_with_clutter() -> None:
    """Cluttered scans, a missed target's read-out and tags included."""
    _both(PHDConfig(region=AREA), SCANS, 10.0)


def test_same_update_without_clutter() -> None:
    """A clutter-free scan with a far measurement (``C_z`` only the likelihood floor): the same
    update. Its birth shares are ratios of rounding errors (see
    :mod:`searchtrack.estimate.phd.update`), so the next draws may differ: compared up to the
    first update only, the runs statistically below."""
    _both(PHDConfig(region=AREA), SCANS, 0.0, exact=2)


def test_clutter_free_runs_agree_statistically() -> None:
    """Without clutter the two backends track a 3-target run with mean counts and OSPA within
    a few percent of each other."""
    sc = standard_scenario(2, n_targets=3, n_scans=40, clutter_rate=0.0)
    scores = []
    for backend in ("numpy", "numba"):
        cfg = PHDConfig(region=sc.sensor.area, backend=backend)
        rng = np.random.default_rng(0)
        st, counts, dist = PHDState.empty(4), [], []
        for k, z in enumerate(sc.scans):
            st, est = step(st, [SensorScan(sc.sensor, POSE, z)], sc.motion, cfg, 1.0, rng)
            if k >= 10:
                counts.append(st.expected_count())
                dist.append(ospa(est.positions, sc.truth[k][:, :2], 100.0, 1.0))
        scores.append((np.mean(counts), np.mean(dist)))
    (c1, d1), (c2, d2) = scores
    assert c2 == pytest.approx(c1, rel=0.05) and d2 == pytest.approx(d1, rel=0.1, abs=1.0)


def test_same_particles_with_survival_map_grid_births_and_several_sensors() -> None:
    """A state-dependent survival, a grid birth intensity and two sensors per scan."""
    grid = BirthGrid.uniform(AREA, mass=0.2, particles=400)
    cfg = PHDConfig(region=AREA, survival_map=Half(), birth_grid=grid, adaptive_birth=True,
                    birth_mass=0.5)
    two = [[z, z[:1] + 3.0] for [z] in SCANS if z.shape[0]]
    _both(cfg, two, 5.0)


def test_same_particles_without_region_and_without_motion_time() -> None:
    """No surveillance region; a zero time step draws no motion noise."""
    _both(PHDConfig(), SCANS[:2], 10.0, dt_s=0.0)


def test_the_gated_passes_cover_position_sensors_only() -> None:
    """Other sensors, no particles or no scans fall back to the NumPy equations."""
    x = np.zeros((3, 4))
    scan = SensorScan(sensor(), POSE, np.zeros((1, 2)))
    assert compiled.gated_supported(x, [scan])
    assert not compiled.gated_supported(np.zeros((0, 4)), [scan])
    assert not compiled.gated_supported(x, [])

    @dataclasses.dataclass(frozen=True)
    class Other:
        meas_dim: int = 2

    other = SensorScan.__new__(SensorScan)
    object.__setattr__(other, "sensor", Other())
    assert not compiled.gated_supported(x, [other])
