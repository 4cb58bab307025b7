"""Fixed-wing motion primitives (paper 003 §2.3): kinematics, the altitude band, the control
grid, yaw wrapping and bad inputs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.assign import FixedWingPrimitives, fixed_wing_actions


def test_straight_primitive_matches_kinematics() -> None:
    """Zero rates fly straight at v for steps × step_s seconds; turns keep the speed."""
    prim = FixedWingPrimitives(speeds_mps=(2.0,), yaw_rates_rps=(0.0, 0.2),
                               pitch_rates_rps=(0.0,), steps=2, step_s=5.0)
    acts = fixed_wing_actions(np.array([0.0, 0.0, 10.0, 0.0, 0.0]), prim)
    assert acts.shape == (2, 2, 5)
    np.testing.assert_allclose(acts[0, :, :3], [[10.0, 0.0, 10.0], [20.0, 0.0, 10.0]], atol=1e-9)
    chord = np.linalg.norm(acts[1, 0, :2])
    assert chord < 10.0 and chord > 9.0
    assert acts[1, 1, 3] == pytest.approx(2.0, abs=1e-6)

def test_altitude_limits_prune_primitives() -> None:
    """Climbing or diving out of the altitude band removes the primitive."""
    prim = FixedWingPrimitives(speeds_mps=(5.0,), yaw_rates_rps=(0.0,),
                               pitch_rates_rps=(-0.2, 0.0, 0.2), z_min_m=8.0, z_max_m=12.0)
    acts = fixed_wing_actions(np.array([0.0, 0.0, 10.0, 0.0, 0.0]), prim)
    assert acts.shape[0] == 1
    assert acts[0, 0, 2] == pytest.approx(10.0)

def test_primitives_fly_the_vehicle_model() -> None:
    """The primitives are Euler steps of 003's kinematics written out by hand, with the pitch
    clipped and the yaw wrapped; the vehicle model carries the band and the pitch limit."""
    prim = FixedWingPrimitives(speeds_mps=(3.0,), yaw_rates_rps=(0.25,), pitch_rates_rps=(0.05,),
                               steps=3, step_s=2.0, euler_dt_s=0.1, max_pitch_rad=0.15)
    state = np.array([5.0, -3.0, 20.0, 3.0, 0.1])
    acts = fixed_wing_actions(state, prim)
    x, y, z, yaw, pitch = state
    expected = []
    for _ in range(3):
        for _ in range(20):
            x += 0.1 * 3.0 * np.cos(pitch) * np.cos(yaw)
            y += 0.1 * 3.0 * np.cos(pitch) * np.sin(yaw)
            z += 0.1 * 3.0 * np.sin(pitch)
            yaw += 0.1 * 0.25
            pitch = min(pitch + 0.1 * 0.05, 0.15)
        expected.append([x, y, z, (yaw + np.pi) % (2 * np.pi) - np.pi, pitch])
    np.testing.assert_allclose(acts[0], expected, rtol=0.0, atol=1e-12)
    model = prim.vehicle
    assert (model.state_lower[2], model.state_upper[2]) == (2.0, 50.0)
    assert (model.state_lower[4], model.state_upper[4]) == (-0.15, 0.15)
    assert model.input_lower == model.input_upper == (3.0, 0.25, 0.05)

def test_primitives_bad_input() -> None:
    """Bad control grids and bands raise naming the field."""
    with pytest.raises(InvalidInputError, match="speeds_mps"):
        FixedWingPrimitives(speeds_mps=(0.0,))
    with pytest.raises(InvalidInputError, match="z_max_m"):
        FixedWingPrimitives(z_min_m=10.0, z_max_m=5.0)
    with pytest.raises(InvalidInputError, match="max_pitch_rad"):
        FixedWingPrimitives(max_pitch_rad=2.0)
    with pytest.raises(InvalidInputError, match="state"):
        fixed_wing_actions(np.zeros(3), FixedWingPrimitives())


def test_controls_are_the_grid_in_product_order() -> None:
    """Every (speed, yaw rate, pitch rate) combination, the pitch rate varying fastest; the
    vehicle's nominal input is the mid speed with zero rates clipped into the grid."""
    prim = FixedWingPrimitives(speeds_mps=(1.0, 2.0), yaw_rates_rps=(-0.1, 0.1),
                               pitch_rates_rps=(0.05, 0.1, 0.15))
    u = prim.controls
    assert u.shape == (12, 3)
    np.testing.assert_array_equal(u[:3], [[1.0, -0.1, 0.05], [1.0, -0.1, 0.1],
                                          [1.0, -0.1, 0.15]])
    np.testing.assert_array_equal(u[-1], [2.0, 0.1, 0.15])
    assert prim.vehicle.nominal_input == (1.5, 0.0, 0.05)


def test_yaw_is_wrapped() -> None:
    """Turning at 0.2 rad/s for 5 s from ψ = 3 rad ends at 4 − 2π, in [−π, π)."""
    prim = FixedWingPrimitives(speeds_mps=(1.0,), yaw_rates_rps=(0.2,), pitch_rates_rps=(0.0,),
                               steps=1, step_s=5.0, euler_dt_s=0.5)
    acts = fixed_wing_actions(np.array([0.0, 0.0, 10.0, 3.0, 0.0]), prim)
    assert acts[0, 0, 3] == pytest.approx(4.0 - 2.0 * math.pi, abs=1e-12)


def test_every_primitive_leaving_the_band_gives_no_action() -> None:
    """At the floor of the band, diving only: every primitive is dropped, (0, T, 5) remains."""
    prim = FixedWingPrimitives(speeds_mps=(2.0,), yaw_rates_rps=(0.0, 0.1),
                               pitch_rates_rps=(-0.2,), steps=2, z_min_m=2.0)
    acts = fixed_wing_actions(np.array([0.0, 0.0, 2.0, 0.0, 0.0]), prim)
    assert acts.shape == (0, 2, 5)


def test_more_bad_primitives() -> None:
    """Bad step counts, step lengths and control grids raise naming the field."""
    with pytest.raises(InvalidInputError, match="steps"):
        FixedWingPrimitives(steps=0)
    with pytest.raises(InvalidInputError, match="euler_dt_s"):
        FixedWingPrimitives(step_s=1.0, euler_dt_s=2.0)
    with pytest.raises(InvalidInputError, match="step_s"):
        FixedWingPrimitives(step_s=math.nan)
    with pytest.raises(InvalidInputError, match="yaw_rates_rps"):
        FixedWingPrimitives(yaw_rates_rps=[0.0])  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="pitch_rates_rps"):
        FixedWingPrimitives(pitch_rates_rps=())
    with pytest.raises(InvalidInputError, match="state"):
        fixed_wing_actions(np.array([0.0, 0.0, np.inf, 0.0, 0.0]), FixedWingPrimitives())
