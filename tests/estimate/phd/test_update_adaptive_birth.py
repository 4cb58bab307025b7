"""The adaptive birth of the SMC-PHD update: seeds follow the unexplained measurements."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate.phd import PHDConfig, PHDState, SensorScan, predict, resample, update
from searchtrack.models.motion import Static

from .helpers import POSE
from .helpers import cloud as _cloud
from .helpers import phd_state as _state
from .helpers import sensor as _sensor


def test_off_by_default() -> None:
    """The default keeps the renormalised birth of Ristic et al. 2012 (a constant total)."""
    assert PHDConfig().adaptive_birth is False


def test_seeds_are_the_unexplained_part_not_renormalised() -> None:
    """With clutter each seed is birth_mass · (1 − ρ_z): a measurement at a target seeds almost
    nothing, one far from every particle almost the whole birth_mass."""
    st = _state(_cloud((300, 300), 200, 1.0))
    z = np.array([[300.0, 300.0], [900.0, 100.0]])
    cfg = PHDConfig(birth_mass=0.5, adaptive_birth=True)
    out = update(st, [SensorScan(_sensor(), POSE, z)], cfg)
    rho = out.record.detection_masses
    np.testing.assert_allclose(out.record.seed_masses, 0.5 * (1.0 - rho), rtol=1e-12)
    assert out.record.seed_masses[0] < 0.05 and out.record.seed_masses[1] > 0.5 - 1e-6


def test_every_measurement_explained_seeds_nothing() -> None:
    """Without clutter a measurement any particle explains has ρ_z = 1 and seeds no mass, where
    the renormalised birth would still inject up to birth_mass."""
    st = _state(_cloud((300, 300), 200, 1.0), _cloud((700, 600), 200, 1.0, seed=1))
    z = np.array([[302.0, 298.0], [695.0, 604.0]])
    out = update(st, [SensorScan(_sensor(clutter=0.0), POSE, z)],
                 PHDConfig(birth_mass=1.0, adaptive_birth=True))
    assert out.record.seed_masses.sum() < 1e-12


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_one_unit_of_mass_per_measurement_without_clutter(seed: int) -> None:
    """Clutter-free, birth_mass = 1: the update plus the births it seeds add exactly |Z|
    (ρ_z now, 1 − ρ_z at the next prediction) to the missed mass Σ (1 − p_d) w."""
    rng = np.random.default_rng(seed)
    x, w = _cloud((300, 300), 200, 1.3, seed=seed)
    st = PHDState.from_particles(x[:, :2], w)
    z = np.array([[301.0, 299.0], [900.0, 100.0], [40.0, 950.0]])[: 1 + seed]
    sensor = _sensor(pd=0.7, clutter=0.0)
    cfg = PHDConfig(birth_mass=1.0, adaptive_birth=True, survival_probability=1.0)
    out = update(st, [SensorScan(sensor, POSE, z)], cfg)
    missed = float(np.sum((1.0 - sensor.detection_probability(POSE, st.positions)) * st.weights))
    added = out.expected_count() - missed + out.record.seed_masses.sum()
    assert added == pytest.approx(z.shape[0], rel=1e-9)
    nxt = predict(out, Static(2), cfg, 1.0, rng)
    assert nxt.expected_count() == pytest.approx(missed + z.shape[0], rel=1e-9)


def test_static_target_mass_stays_bounded() -> None:
    """One static target seen with p_d = 0.6 for 60 clutter-free scans: with adaptive birth its
    mass stays below 1/p_d (one unit per detection, thinned by misses) and averages about 1;
    the renormalised birth of the same mass grows past it."""
    sensor = _sensor(pd=0.6, clutter=0.0)
    target = np.array([[500.0, 500.0]])

    def masses(adaptive: bool) -> list[float]:
        rng = np.random.default_rng(4)
        cfg = PHDConfig(birth_mass=1.0, adaptive_birth=adaptive, survival_probability=1.0,
                        birth_position_sigma_m=5.0, particles_per_target=300)
        st, out = PHDState.empty(2, 2), []
        for _ in range(60):
            seen = rng.random() < 0.6
            z = target + 3.0 * rng.standard_normal((1, 2)) if seen else np.empty((0, 2))
            st = predict(st, Static(2), cfg, 1.0, rng)
            st = update(st, [SensorScan(sensor, POSE, z)], cfg)
            out.append(st.expected_count())
            st = resample(st, cfg, rng)
        return out

    adaptive = masses(True)
    assert max(adaptive) <= 1.0 / 0.6 + 1e-9
    assert np.mean(adaptive[10:]) == pytest.approx(1.0, abs=0.35)
    assert max(masses(False)) > max(adaptive)
