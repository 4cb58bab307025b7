"""Jump-Markov tag motion: WD and CV moments, the mode chain, the τ walk, shapes and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.radio.motion import (
    CV,
    WD,
    TagMotion,
    jump_modes,
    propagate,
    propagate_positions,
    wrap_tau,
)

N = 100_000
MOTION = TagMotion()


def _cloud(x0: list[float], mode: int) -> tuple[np.ndarray, np.ndarray]:
    return np.tile(np.array(x0), (N, 1)), np.full(N, mode, dtype=np.int8)


def test_matrices_follow_eqs_46_and_47_in_px_vx_py_vy_order() -> None:
    """F_WD = diag(1,0,1,0); F_CV = I2 ⊗ [[1,T0],[0,1]]; Q_CV = σ² I2 ⊗ [[T³/3,T²/2],[T²/2,T]]."""
    motion = TagMotion(period_s=2.0)
    f, q = motion.matrices
    np.testing.assert_array_equal(f[WD], np.diag([1.0, 0.0, 1.0, 0.0]))
    np.testing.assert_array_equal(f[CV], [[1, 2, 0, 0], [0, 1, 0, 0], [0, 0, 1, 2], [0, 0, 0, 1]])
    block = 0.05**2 * np.array([[8 / 3, 2.0], [2.0, 2.0]])
    np.testing.assert_allclose(q[CV][:2, :2], block)
    np.testing.assert_allclose(q[CV][2:, 2:], block)
    np.testing.assert_array_equal(q[CV][:2, 2:], 0.0)
    np.testing.assert_array_equal(q[WD], np.diag([0.25, 2.25, 0.25, 2.25]))


def test_wd_forgets_the_velocity() -> None:
    """A WD step keeps the position (variance 0.25) and redraws the velocity (variance 2.25)."""
    x, mode = _cloud([100.0, 5.0, -50.0, -3.0], WD)
    out = propagate_positions(MOTION, x, mode, np.random.default_rng(0))
    np.testing.assert_allclose(out.mean(axis=0), [100.0, 0.0, -50.0, 0.0], atol=0.03)
    np.testing.assert_allclose(np.cov(out.T), np.diag([0.25, 2.25, 0.25, 2.25]), atol=0.03)


def test_cv_moves_with_the_velocity() -> None:
    """A CV step has mean F x and covariance Q_CV (σ_CV = 0.5 here to see the noise)."""
    motion = TagMotion(cv_accel_std=0.5)
    x, mode = _cloud([100.0, 5.0, -50.0, -3.0], CV)
    out = propagate_positions(motion, x, mode, np.random.default_rng(1))
    np.testing.assert_allclose(out.mean(axis=0), [105.0, 5.0, -53.0, -3.0], atol=0.01)
    np.testing.assert_allclose(np.cov(out.T), motion.matrices[1][CV], atol=0.005)


def test_each_object_uses_its_own_previous_mode() -> None:
    """In a mixed cloud WD objects lose their velocity, CV objects keep it; inputs unchanged."""
    x = np.array([[0.0, 10.0, 0.0, 10.0]] * 4)
    mode = np.array([WD, CV, WD, CV], dtype=np.int8)
    tau = np.full(4, 0.5)
    x_copy, mode_copy, tau_copy = x.copy(), mode.copy(), tau.copy()
    motion = TagMotion(wd_velocity_var=0.0, wd_position_var=0.0, cv_accel_std=0.0, tau_std=0.0)
    new_x, _, new_tau = propagate(motion, x, mode, tau, np.random.default_rng(2))
    np.testing.assert_allclose(new_x[[0, 2]], 0.0)
    np.testing.assert_allclose(new_x[[1, 3]], [[10.0, 10.0, 10.0, 10.0]] * 2)
    np.testing.assert_array_equal(new_tau, 0.5)
    np.testing.assert_array_equal(x, x_copy)
    np.testing.assert_array_equal(mode, mode_copy)
    np.testing.assert_array_equal(tau, tau_copy)


@pytest.mark.parametrize("shape", [(), (7,), (3, 5), (2, 1, 4)])
def test_any_leading_shape(shape: tuple[int, ...]) -> None:
    """propagate works on any leading shape and returns new arrays of the same shapes."""
    rng = np.random.default_rng(3)
    x = rng.normal(size=(*shape, 4))
    mode = rng.integers(0, 2, size=shape).astype(np.int8)
    tau = rng.uniform(0, 1, size=shape)
    new_x, new_mode, new_tau = propagate(MOTION, x, mode, tau, rng)
    assert new_x.shape == x.shape and new_mode.shape == mode.shape == new_tau.shape
    assert new_mode.dtype == np.int8
    x.setflags(write=False)  # read-only inputs are fine
    propagate_positions(MOTION, x, mode, rng)


def test_mode_chain_transition_frequencies() -> None:
    """Empirical transition frequencies match mode_transition."""
    motion = TagMotion(mode_transition=((0.7, 0.3), (0.2, 0.8)))
    rng = np.random.default_rng(4)
    mode = rng.integers(0, 2, N).astype(np.int8)
    new = jump_modes(motion, mode, rng)
    for s, row in enumerate(motion.mode_transition):
        frac = np.mean(new[mode == s] == 1)
        assert frac == pytest.approx(row[1], abs=0.01)
    _, through_propagate, _ = propagate(motion, np.zeros((N, 4)), mode, np.zeros(N), rng)
    assert np.mean(through_propagate[mode == 0]) == pytest.approx(0.3, abs=0.01)


def test_tau_walk_and_wrap() -> None:
    """τ steps have std σ_τ T0 and stay in [0, T0), wrapping across both ends."""
    motion = TagMotion(period_s=2.0, tau_std=1e-3)
    rng = np.random.default_rng(5)
    x, mode = np.zeros((N, 4)), np.zeros(N, dtype=np.int8)
    _, _, mid = propagate(motion, x, mode, np.full(N, 1.0), rng)
    assert np.std(mid) == pytest.approx(2e-3, rel=0.02)
    for start in (0.0, 2.0 - 1e-9):
        _, _, tau = propagate(motion, x, mode, np.full(N, start), rng)
        assert tau.min() >= 0.0 and tau.max() < 2.0
        assert np.mean(tau > 1.0) == pytest.approx(0.5, abs=0.02)  # half wrapped
    np.testing.assert_array_equal(wrap_tau(motion, np.array([-1e-18, 2.0, 4.5, -0.5])),
                                  [0.0, 0.0, 0.5, 1.5])


def test_deterministic_for_a_seed() -> None:
    """The same seed gives the same step; positions-only draws match the full step's."""
    x = np.random.default_rng(0).normal(size=(50, 4))
    mode = np.arange(50, dtype=np.int8) % 2
    tau = np.linspace(0, 0.9, 50)
    a = propagate(MOTION, x, mode, tau, np.random.default_rng(6))
    b = propagate(MOTION, x, mode, tau, np.random.default_rng(6))
    for u, v in zip(a, b, strict=True):
        np.testing.assert_array_equal(u, v)
    np.testing.assert_array_equal(propagate_positions(MOTION, x, mode, np.random.default_rng(6)),
                                  a[0])


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"period_s": 0.0}, "period_s"),
    ({"wd_position_var": -1.0}, "wd_position_var"),
    ({"cv_accel_std": math.nan}, "cv_accel_std"),
    ({"tau_std": -1e-4}, "tau_std"),
    ({"mode_transition": ((0.9, 0.2), (0.1, 0.9))}, "mode_transition[0]"),
    ({"mode_transition": ((1.1, -0.1), (0.1, 0.9))}, "mode_transition[0]"),
    ({"mode_transition": ((0.9, 0.1),)}, "mode_transition"),
    ({"initial_mode": (0.5, 0.6)}, "initial_mode"),
    ({"initial_mode": (1.0,)}, "initial_mode"),
])
def test_bad_motion_names_the_field(kwargs: dict[str, object], field: str) -> None:
    """Bad parameters raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        TagMotion(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_bad_states_name_the_argument() -> None:
    """Wrong shapes or modes raise InvalidInputError naming x, mode or tau."""
    rng = np.random.default_rng(0)
    good_x, good_mode, good_tau = np.zeros((3, 4)), np.zeros(3, dtype=np.int8), np.zeros(3)
    cases = [((np.zeros((3, 3)), good_mode, good_tau), "x"),
             ((good_x, np.zeros(4, dtype=np.int8), good_tau), "mode"),
             ((good_x, np.array([0, 2, 1]), good_tau), "mode"),
             ((good_x, np.zeros(3), good_tau), "mode"),
             ((good_x, good_mode, np.zeros(2)), "tau")]
    for args, field in cases:
        with pytest.raises(InvalidInputError) as err:
            propagate(MOTION, *args, rng)
        assert err.value.field == field
    with pytest.raises(InvalidInputError, match="rng"):
        propagate(MOTION, good_x, good_mode, good_tau, None)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="mode"):
        jump_modes(MOTION, np.array([0.5]), rng)
