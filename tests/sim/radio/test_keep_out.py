"""Keep-out discs around radio-tag estimates flown by the trajectory controllers: tracking
without discs, clearance in closed loop, discs that already hold the UAV, kinematic limits,
the heading fallback and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.angles import wrap_angle
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.radio.uav import UavModel, fly_heading
from searchtrack.sim.radio.keep_out import (
    KeepOut,
    escape_floor_m,
    fly_with_keep_out,
    inflated_radius_m,
)

UAV = UavModel()
KEEP = KeepOut()
RHO = UAV.speed_mps / UAV.max_turn_rate  # tightest turn radius, 19.1 m
GOAL = np.array([400.0, 0.0])


def _primitive(pose: FloatArray, heading: float) -> FloatArray:
    return np.asarray(fly_heading(UAV, pose, heading, UAV.plan_interval_s)[:, :2])


def _toward(pose: FloatArray, point: FloatArray) -> FloatArray:
    return _primitive(pose, math.atan2(point[1] - pose[1], point[0] - pose[0]))


def _distance(pose: FloatArray, centre: FloatArray) -> float:
    return float(np.hypot(*(pose[:2] - centre)))


@pytest.mark.parametrize("heading", [0.0, math.pi / 2, -2.5])
def test_without_discs_the_reference_is_followed(heading: float) -> None:
    """With no estimates the pose after one step lies within 2 m of the primitive's first pose
    (the primitives step along chords, the controller along arcs); the call is deterministic."""
    pose = np.array([100.0, 50.0, 0.3])
    ref = _primitive(pose, heading)
    flown, result = fly_with_keep_out(KEEP, UAV, pose, ref, np.zeros((0, 2)))
    assert result.plan is not None and result.stats["heading_fallback"] == 0.0
    assert float(np.hypot(*(flown[:2] - ref[0]))) < 2.0
    again, _ = fly_with_keep_out(KEEP, UAV, pose, ref, np.zeros((0, 2)))
    # the same to rounding: the QP solver's workspace is reused between calls
    np.testing.assert_allclose(flown, again, rtol=0.0, atol=1e-9)


@pytest.mark.parametrize("backend", ["auto", "nmpc", "ltv_mpc"])
def test_disc_on_the_path_is_kept_clear_in_closed_loop(backend: str) -> None:
    """A disc centred on the straight reference is skirted over 20 s by every optimising
    controller (NMPC alone needs the warm start: cold, the disc dead ahead is locally
    infeasible): every pose stays ``radius_m`` or more from the centre (stage points are held
    at the inflated radius, so no tolerance is needed) while the reference crosses the centre."""
    keep = KeepOut(backend=backend, time_limit_s=2.0)  # generous: a busy machine
    centre = np.array([200.0, 0.0])
    pose = np.array([0.0, 0.0, 0.0])
    straight = np.asarray(fly_heading(UAV, pose, 0.0, 20.0)[:, :2])
    assert np.min(np.hypot(*(straight - centre).T)) < 1.0
    gaps, backends = [], set()
    for _ in range(20):
        pose, result = fly_with_keep_out(keep, UAV, pose, _toward(pose, GOAL), centre)
        gaps.append(_distance(pose, centre))
        backends.add(result.backend)
        assert result.plan is not None
    assert min(gaps) >= KEEP.radius_m
    assert min(gaps) < inflated_radius_m(KEEP, UAV) + KEEP.margin_m + 3.0  # it did skirt it
    assert pose[0] > 300.0 and backends <= {"nmpc", "ltv_mpc", "closed_form"}


def test_disc_behind_the_uav_that_holds_it_is_not_approached() -> None:
    """An estimate 21 m behind (inside ``r_min``): no error, the distance does not decrease, the
    disc is reported shrunk, and later steps move the UAV back out."""
    centre = np.array([-20.0, 5.0])
    pose = np.array([0.0, 0.0, 0.0])
    start = _distance(pose, centre)
    flown, result = fly_with_keep_out(KEEP, UAV, pose, _primitive(pose, math.pi), centre)
    assert result.stats["shrunk_discs"] == 1.0 and result.plan is not None
    assert _distance(flown, centre) >= start
    for _ in range(3):
        flown, _ = fly_with_keep_out(KEEP, UAV, flown, _primitive(flown, math.pi), centre)
    assert _distance(flown, centre) > KEEP.radius_m


def test_disc_appearing_dead_ahead_costs_no_more_than_the_escape() -> None:
    """An estimate 30 m dead ahead cannot be kept out of: NMPC, given the disc shrunk to the
    escape floor (turning away at the maximum rate), stays feasible and the UAV gets no closer
    than that floor (0.2 m for solver tolerances), where the reference passes 10 m from it."""
    centre = np.array([30.0, 0.0])
    pose = np.array([0.0, 0.0, 0.0])
    floor = float(escape_floor_m(KEEP, UAV, pose, centre[None])[0])
    assert floor == pytest.approx(math.hypot(30.0, RHO) - RHO, abs=1.0)
    flown, result = fly_with_keep_out(KeepOut(backend="nmpc"), UAV, pose,
                                      _primitive(pose, 0.0), centre)
    assert result.plan is not None and result.stats["shrunk_discs"] == 1.0
    assert _distance(flown, centre) >= floor - 0.2
    assert _distance(flown, centre) > 10.0 + 5.0


def test_estimate_on_the_uav_is_left_out_without_error() -> None:
    """An estimate on the UAV's position is dropped from the solve; the step still flies."""
    pose = np.array([10.0, 10.0, 1.0])
    flown, result = fly_with_keep_out(KEEP, UAV, pose, _primitive(pose, 1.0), pose[:2])
    assert result.stats["dropped_discs"] == 1.0 and result.plan is not None
    assert _distance(flown, pose[:2]) > 15.0


def test_kinematic_limits_hold_every_step() -> None:
    """Around two discs with the reference doubling back, each 1 s step moves 20 m along an
    arc: its chord lies in ``[2ρ sin(ω/2), v]`` (19.10–20 m) and the heading change is at most
    ``ω``; 1e-6 covers the RK4 error (under 1e-7 m for a constant-rate stage)."""
    centres = np.array([[150.0, 40.0], [150.0, -60.0]])
    pose = np.array([0.0, 0.0, 0.0])
    low = 2.0 * RHO * math.sin(UAV.max_turn_rate * UAV.step_s / 2.0)
    for k in range(14):
        ref = _toward(pose, GOAL) if k < 8 else _primitive(pose, math.pi)
        flown, _ = fly_with_keep_out(KEEP, UAV, pose, ref, centres)
        chord = float(np.hypot(*(flown[:2] - pose[:2])))
        assert low - 1e-6 <= chord <= UAV.speed_mps * UAV.step_s + 1e-6
        assert abs(wrap_angle(float(flown[2] - pose[2]))) <= UAV.max_turn_rate + 1e-6
        assert -math.pi <= flown[2] < math.pi
        pose = flown


def test_failed_controller_falls_back_to_the_primitive() -> None:
    """NMPC alone with a 1 µs budget has no plan: the primitive's first pose is flown and the
    message says so."""
    keep = KeepOut(backend="nmpc", time_limit_s=1e-6)
    pose = np.array([0.0, 0.0, 0.0])
    ref = _primitive(pose, math.pi / 2)
    flown, result = fly_with_keep_out(keep, UAV, pose, ref, np.array([[300.0, 300.0]]))
    assert result.plan is None and result.stats["heading_fallback"] == 1.0
    assert "fly_heading" in result.message
    np.testing.assert_allclose(flown, fly_heading(UAV, pose, math.pi / 2, 1.0)[-1], atol=1e-12)


def test_zero_radius_disables_the_discs() -> None:
    """``radius_m = 0`` flies straight over an estimate on the path."""
    pose = np.array([0.0, 0.0, 0.0])
    flown, result = fly_with_keep_out(KeepOut(radius_m=0.0), UAV, pose, _primitive(pose, 0.0),
                                      np.array([25.0, 0.0]))
    assert result.plan is not None and result.stats["dropped_discs"] == 0.0
    np.testing.assert_allclose(flown, [20.0, 0.0, 0.0], atol=1e-6)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"radius_m": -1.0}, "radius_m"), ({"radius_m": math.nan}, "radius_m"),
    ({"backend": "simplex"}, "backend"), ({"horizon": 0}, "horizon"),
    ({"dt_s": 0.0}, "dt_s"), ({"time_limit_s": -1.0}, "time_limit_s"),
    ({"margin_m": 0.0}, "margin_m"),
])
def test_bad_settings_name_the_field(kwargs: dict[str, float], field: str) -> None:
    """Invalid settings raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError, match=field):
        KeepOut(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(("pose", "ref", "centres", "duration", "field"), [
    ([0.0, 0.0], [[20.0, 0.0]], [[99.0, 0.0]], None, "pose"),
    ([0.0, 0.0, math.nan], [[20.0, 0.0]], [[99.0, 0.0]], None, "pose"),
    ([0.0, 0.0, 0.0], [[20.0, 0.0, 0.0]], [[99.0, 0.0]], None, "reference_xy"),
    ([0.0, 0.0, 0.0], np.zeros((0, 2)), [[99.0, 0.0]], None, "reference_xy"),
    ([0.0, 0.0, 0.0], [[20.0, 0.0]], [[math.nan, 0.0]], None, "centres"),
    ([0.0, 0.0, 0.0], [[20.0, 0.0]], [[99.0, 0.0, 1.0]], None, "centres"),
    ([0.0, 0.0, 0.0], [[20.0, 0.0]], [[99.0, 0.0]], 0.5, "duration_s"),
    ([0.0, 0.0, 0.0], [[20.0, 0.0]], [[99.0, 0.0]], 10.0, "duration_s"),
    ([0.0, 0.0, 0.0], [[20.0, 0.0]], [[99.0, 0.0]], -1.0, "duration_s"),
])
def test_bad_input_names_the_field(pose: list[float], ref: object, centres: list[list[float]],
                                   duration: float | None, field: str) -> None:
    """NaNs, wrong shapes and durations that are not whole steps within the horizon raise
    InvalidInputError naming the argument."""
    with pytest.raises(InvalidInputError, match=field):
        fly_with_keep_out(KEEP, UAV, pose, ref, centres, duration)  # type: ignore[arg-type]
