"""Dubins UAV (5.1)–(5.5): straight lines and circles in closed form, saturation, bad input."""

from __future__ import annotations

import math
from typing import get_args

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.dubins import (
    MPS_PER_MPH,
    DubinsLimits,
    Method,
    UavState,
    force_to_controls,
    propagate,
    sat,
    step_force,
    unicycle_from_limits,
)

METHODS = get_args(Method)
S_MAX = 80 * MPS_PER_MPH  # 35.7632 m/s (Table 6.2)
FREE = DubinsLimits(speed_max_mps=100.0, speed_min_mps=1.0, turn_rate_max_rps=10.0)


def _state(x: float = 0.0, y: float = 0.0, heading: float = 0.0, speed: float = 30.0) -> UavState:
    return UavState(x_m=[x], y_m=[y], heading_rad=[heading], speed_mps=[speed])


def _run(state: UavState, turn: float, speed: float, dt: float, steps: int, limits: DubinsLimits,
         method: Method) -> UavState:
    for _ in range(steps):
        state = propagate(state, turn, speed, dt, limits, method=method)
    return state


def test_sat_clips_symmetrically() -> None:
    """sat(x, x_max) (5.5) is x inside [−x_max, x_max] and the nearer bound outside."""
    clipped = sat([-3.0, -1.0, 0.5, 2.0, 7.0], 2.0)
    np.testing.assert_array_equal(clipped, [-2.0, -1.0, 0.5, 2.0, 2.0])


@pytest.mark.parametrize("method", METHODS)
def test_straight_line(method: Method) -> None:
    """With zero turn rate every method flies the straight line x₀ + S t (cos θ, sin θ)."""
    theta, speed, dt, steps = 0.3, 30.0, 0.3, 20
    end = _run(_state(1.0, 2.0, theta, speed), 0.0, speed, dt, steps, FREE, method)
    t = dt * steps
    assert end.x_m[0] == pytest.approx(1.0 + speed * t * math.cos(theta), abs=1e-9)
    assert end.y_m[0] == pytest.approx(2.0 + speed * t * math.sin(theta), abs=1e-9)
    assert end.heading_rad[0] == pytest.approx(theta)


@pytest.mark.parametrize(("method", "tol_m"), [("exact", 1e-9), ("rk4", 1e-3)])
def test_constant_turn_circle(method: Method, tol_m: float) -> None:
    """A constant turn rate ω traces the circle of radius S/ω: exact to 1e-9 m, RK4 to 1 mm."""
    speed, omega, dt = 30.0, 0.5, 0.3
    radius = speed / omega  # centre at (0, R) for a start at the origin heading east
    state = _state(speed=speed)
    for k in range(1, 42):  # 12.3 s, more than one full turn (2π/ω = 12.57 s)
        state = propagate(state, omega, speed, dt, FREE, method=method)
        phi = omega * dt * k
        assert state.x_m[0] == pytest.approx(radius * math.sin(phi), abs=tol_m)
        assert state.y_m[0] == pytest.approx(radius * (1 - math.cos(phi)), abs=tol_m)
    assert state.heading_rad[0] == pytest.approx(math.remainder(omega * dt * 41, 2 * math.pi))


def test_euler_converges_at_first_order() -> None:
    """The thesis's Euler step drifts off the circle by an error that halves with Δt."""
    speed, omega, t_end = 30.0, 0.5, 6.0

    def error(dt: float) -> float:
        end = _run(_state(speed=speed), omega, speed, dt, round(t_end / dt), FREE, "euler")
        r = speed / omega
        return math.hypot(end.x_m[0] - r * math.sin(omega * t_end),
                          end.y_m[0] - r * (1 - math.cos(omega * t_end)))

    coarse, fine = error(0.3), error(0.15)
    assert 0.0 < fine < coarse
    assert coarse / fine == pytest.approx(2.0, rel=0.1)


def test_exact_full_circle_returns_to_start() -> None:
    """After 2π/ω seconds the exact step is back at its start with its starting heading."""
    steps, speed = 40, 35.0
    omega = 2 * math.pi / (steps * 0.25)
    end = _run(_state(5.0, -3.0, 1.0, speed), omega, speed, 0.25, steps, FREE, "exact")
    assert (end.x_m[0], end.y_m[0]) == pytest.approx((5.0, -3.0), abs=1e-9)
    assert end.heading_rad[0] == pytest.approx(1.0, abs=1e-12)


def test_rk4_step_is_the_unicycle_models_step() -> None:
    """One implementation of (5.1): the RK4 step is the unicycle vehicle model's, wind-free."""
    limits = DubinsLimits(speed_max_mps=40.0, speed_min_mps=10.0, turn_rate_max_rps=1.5)
    model = unicycle_from_limits(limits)
    start = UavState(x_m=[1.0, -20.0], y_m=[2.0, 7.0], heading_rad=[0.3, -2.9],
                     speed_mps=[20.0, 35.0])
    out = propagate(start, [0.4, -1.2], [25.0, 38.0], 0.7, limits, method="rk4")
    for i, (turn, speed) in enumerate([(0.4, 25.0), (-1.2, 38.0)]):
        pose = [start.x_m[i], start.y_m[i], start.heading_rad[i]]
        x, y, heading = model.step(pose, [speed, turn], 0.7)
        assert (out.x_m[i], out.y_m[i]) == (x, y)
        assert out.heading_rad[i] == pytest.approx(math.remainder(heading, 2 * math.pi))


def test_from_limits_copies_the_potential_field_limits() -> None:
    """unicycle_from_limits takes the speed and turn-rate limits of DubinsLimits."""
    limits = DubinsLimits(speed_max_mps=30.0, speed_min_mps=20.0, turn_rate_max_rps=0.7)
    model = unicycle_from_limits(limits)
    assert model.input_lower == (20.0, -0.7)
    assert model.input_upper == (30.0, 0.7)


def test_turn_rate_saturates_at_the_thesis_radius() -> None:
    """A hard turn is saturated to 50 °/s: at 80 mph the UAV flies the 41.0 m circle (§5.1)."""
    limits = DubinsLimits(speed_max_mps=S_MAX, speed_min_mps=S_MAX,
                          turn_rate_max_rps=math.radians(50.0))
    radius = float(limits.turn_radius_m(S_MAX))
    assert radius == pytest.approx(40.98, abs=0.01)
    state = _state(speed=S_MAX)
    for _ in range(30):
        state = propagate(state, 100.0, S_MAX, 0.3, limits)
        assert math.hypot(state.x_m[0], state.y_m[0] - radius) == pytest.approx(radius, abs=1e-9)
    state = propagate(_state(speed=S_MAX), -100.0, S_MAX, 0.3, limits)
    assert state.heading_rad[0] == pytest.approx(-math.radians(50.0) * 0.3)


def test_speed_is_clamped() -> None:
    """Commanded speeds are clamped to [S_min, S_max]; forward forces cannot exceed S_max."""
    limits = DubinsLimits(speed_max_mps=40.0, speed_min_mps=20.0, turn_rate_max_rps=1.0)
    state = UavState(x_m=[0, 0, 0], y_m=[0, 0, 0], heading_rad=[0, 0, 0], speed_mps=[30, 30, 30])
    out = propagate(state, 0.0, [100.0, 5.0, 25.0], 1.0, limits)
    np.testing.assert_array_equal(out.speed_mps, [40.0, 20.0, 25.0])
    np.testing.assert_allclose(out.x_m, [40.0, 20.0, 25.0])
    push = _state(speed=30.0)
    for _ in range(10):
        push = step_force(push, [[50.0, 0.0]], 0.3, limits)
        assert 20.0 <= push.speed_mps[0] <= 40.0
    assert push.speed_mps[0] == 40.0
    brake = step_force(_state(speed=30.0), [[-1e6, 0.0]], 0.3, limits)
    assert brake.speed_mps[0] == 20.0  # (5.4) alone would go negative; S_min holds


def test_force_to_controls_follows_5_3() -> None:
    """A force across the heading turns at Y⊥/S; along the heading it changes the speed by F·Δt."""
    state = UavState(x_m=[0, 0], y_m=[0, 0], heading_rad=[0.0, math.pi / 2], speed_mps=[20, 20])
    turn, speed = force_to_controls(state, [[3.0, 4.0], [3.0, 4.0]], 0.5, FREE)
    np.testing.assert_allclose(turn, [4.0 / 20.0, -3.0 / 20.0])
    np.testing.assert_allclose(speed, [20.0 + 3.0 * 0.5, 20.0 + 4.0 * 0.5])


def test_turn_back_turns_by_the_whole_force_behind_and_agrees_ahead() -> None:
    """For a UAV ``turn_back`` selects, a force behind it turns it at ‖F‖/S toward the side of
    its lateral part (left when dead astern, where (5.3) does not turn at all); ahead of the
    UAV and at 90° both laws give (5.3); the speed law is the same; a UAV left unselected
    turns by (5.3)."""
    heading = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    state = UavState(x_m=np.zeros(6), y_m=np.zeros(6), heading_rad=heading,
                     speed_mps=np.full(6, 20.0))
    force = np.array([[-3.0, 4.0], [-3.0, -4.0], [-5.0, 0.0], [3.0, 4.0], [0.0, -5.0],
                      [-2.0, 0.5]])
    turn, speed = force_to_controls(state, force, 0.5, FREE, turn_back=True)
    thesis_turn, thesis_speed = force_to_controls(state, force, 0.5, FREE)
    np.testing.assert_allclose(turn[:3], [5.0 / 20.0, -5.0 / 20.0, 5.0 / 20.0])
    assert thesis_turn[2] == 0.0  # dead astern: (5.3) gives no turn
    np.testing.assert_allclose(turn[3:5], thesis_turn[3:5])  # ahead, and at 90°
    lateral = 0.5 * math.cos(1.0) + 2.0 * math.sin(1.0)
    assert turn[5] == pytest.approx(math.hypot(2.0, 0.5) / 20.0)
    assert thesis_turn[5] == pytest.approx(lateral / 20.0)
    np.testing.assert_array_equal(speed, thesis_speed)
    fast, _ = force_to_controls(state, 100.0 * force, 0.5, FREE, turn_back=True)
    assert np.all(np.abs(fast) <= FREE.turn_rate_max_rps)
    # near 90° the two laws meet: just behind and just ahead give nearly the same turn
    edge = _state(speed=20.0)
    behind, _ = force_to_controls(edge, [[-1e-6, 5.0]], 0.5, FREE, turn_back=True)
    ahead, _ = force_to_controls(edge, [[1e-6, 5.0]], 0.5, FREE, turn_back=True)
    assert behind[0] == pytest.approx(ahead[0])
    some = np.array([True, False, True, False, False, False])
    mixed, _ = force_to_controls(state, force, 0.5, FREE, turn_back=some)
    np.testing.assert_array_equal(mixed, np.where(some, turn, thesis_turn))


def test_turn_back_holds_a_uav_near_an_anchor_it_overflies() -> None:
    """A constant-speed UAV that flies over its anchor under the weak zero-rest spring of a wide
    footprint (K = (2S/ρ)², ρ = 374 m) stays within the footprint when it turns back; under
    (5.3) alone it flies on, hundreds of metres past it."""
    limits = DubinsLimits()
    k = (2.0 * S_MAX / 374.0) ** 2
    far: dict[bool, float] = {}
    for back in (True, False):
        uav = _state(x=-50.0, y=0.0, heading=0.0, speed=S_MAX)
        farthest = 0.0
        for _ in range(int(60.0 / 0.3)):
            uav = step_force(uav, -k * uav.xy_m, 0.3, limits, turn_back=back)
            farthest = max(farthest, float(np.hypot(uav.x_m[0], uav.y_m[0])))
        far[back] = farthest
    assert far[True] < 374.0 < far[False]


def test_vectorised_step_matches_one_by_one() -> None:
    """Stepping three UAVs together equals stepping each alone."""
    rng = np.random.default_rng(4)
    state = UavState(x_m=rng.normal(size=3), y_m=rng.normal(size=3),
                     heading_rad=rng.uniform(-3, 3, 3), speed_mps=rng.uniform(20, 30, 3))
    force = rng.normal(scale=20.0, size=(3, 2))
    together = step_force(state, force, 0.3, FREE)
    for j in range(3):
        alone = step_force(_state(state.x_m[j], state.y_m[j], state.heading_rad[j],
                                  state.speed_mps[j]), force[j], 0.3, FREE)
        for name in ("x_m", "y_m", "heading_rad", "speed_mps"):
            assert getattr(together, name)[j] == pytest.approx(getattr(alone, name)[0])


def test_heading_is_wrapped() -> None:
    """Headings stay in [−π, π) after a step across ±π."""
    out = propagate(_state(heading=3.1), 1.0, 30.0, 0.3, FREE)
    assert out.heading_rad[0] == pytest.approx(3.4 - 2 * math.pi)


def test_state_arrays_are_read_only() -> None:
    """UavState copies its inputs and freezes them."""
    x = np.zeros(2)
    state = UavState(x_m=x, y_m=[0, 0], heading_rad=[0, 0], speed_mps=[1, 1])
    x[0] = 5.0
    assert state.x_m[0] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        state.x_m[0] = 1.0


@pytest.mark.parametrize(
    ("build", "field"),
    [
        (lambda: UavState(x_m=[0], y_m=[0], heading_rad=[0], speed_mps=[-5.0]), "speed_mps"),
        (lambda: UavState(x_m=[0], y_m=[0], heading_rad=[0], speed_mps=[0.0]), "speed_mps"),
        (lambda: UavState(x_m=[math.nan], y_m=[0], heading_rad=[0], speed_mps=[1]), "x_m"),
        (lambda: UavState(x_m=[0, 1], y_m=[0], heading_rad=[0, 0], speed_mps=[1, 1]), "y_m"),
        (lambda: DubinsLimits(speed_max_mps=-1.0), "speed_max_mps"),
        (lambda: DubinsLimits(speed_max_mps=10.0, speed_min_mps=20.0), "speed_min_mps"),
        (lambda: DubinsLimits(turn_rate_max_rps=math.nan), "turn_rate_max_rps"),
        (lambda: propagate(_state(), 0.0, -3.0, 0.3, FREE), "speed_mps"),
        (lambda: propagate(_state(), math.nan, 30.0, 0.3, FREE), "turn_rate_rps"),
        (lambda: propagate(_state(), 0.0, 30.0, 0.0, FREE), "dt_s"),
        (lambda: propagate(_state(), 0.0, 30.0, 0.3, FREE, method="midpoint"),  # type: ignore[arg-type]
         "method"),
        (lambda: step_force(_state(), [[1.0, 2.0], [3.0, 4.0]], 0.3, FREE), "force"),
        (lambda: step_force(_state(), [[1.0, math.inf]], 0.3, FREE), "force"),
        (lambda: step_force(_state(), [[1.0, 0.0]], 0.3, FREE, turn_back="yes"), "turn_back"),
        (lambda: step_force(_state(), [[1.0, 0.0]], 0.3, FREE, turn_back=[True, False]),
         "turn_back"),
    ],
)
def test_bad_input_names_the_field(build: object, field: str) -> None:
    """Negative or zero speeds, NaN, S_min > S_max, Δt ≤ 0 and wrong shapes name their field."""
    with pytest.raises(InvalidInputError) as err:
        build()  # type: ignore[operator]
    assert err.value.field == field
