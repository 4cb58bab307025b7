"""The one-pass jump-Markov step: draw for draw the motion model's propagate, and bad inputs."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.labelled_motion import propagate
from searchtrack.models.radio import motion as model
from searchtrack.models.radio.motion import TagMotion

MOTIONS = [TagMotion(),
           TagMotion(period_s=2.0, wd_position_var=4.0, wd_velocity_var=0.5, cv_accel_std=0.3,
                     mode_transition=((0.7, 0.3), (0.4, 0.6)), tau_std=0.05)]


def _particles(motion: TagMotion, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    x = rng.normal(0.0, 100.0, (3, 500, 4))
    mode = rng.integers(0, 2, (3, 500)).astype(np.int8)
    tau = rng.uniform(0.0, motion.period_s, (3, 500))
    tau[0, :4] = [0.0, motion.period_s * (1 - 1e-16), 1e-300, motion.period_s / 2]
    return x, mode, tau


@pytest.mark.parametrize("motion", MOTIONS)
@pytest.mark.parametrize("seed", [0, 1])
def test_equals_the_motion_model_draw_for_draw(motion: TagMotion, seed: int) -> None:
    """Same generator state, same result as models.radio.motion.propagate, bit for bit, and
    the generator is left in the same state."""
    x, mode, tau = _particles(motion, seed)
    rng_a, rng_b = np.random.default_rng(seed + 10), np.random.default_rng(seed + 10)
    got = propagate(motion, x, mode, tau, rng_a)
    want = model.propagate(motion, x, mode, tau, rng_b)
    for g, w in zip(got, want, strict=True):
        assert g.dtype == w.dtype
        np.testing.assert_array_equal(g, w)
    assert rng_a.random() == rng_b.random()
    assert np.all((got[2] >= 0.0) & (got[2] < motion.period_s))
    assert 0 < np.mean(got[1] != mode) < 0.5


def test_tau_just_below_zero_wraps_to_zero() -> None:
    """A τ that wraps to T0 in floating point is set to 0, as the motion model does."""
    motion = TagMotion(tau_std=0.0)
    x, mode, tau = _particles(motion)
    tau[1, :3] = [-1e-20, -motion.period_s, 3.0 * motion.period_s]
    got = propagate(motion, x, mode, tau, np.random.default_rng(2))[2]
    np.testing.assert_array_equal(got, model.propagate(motion, x, mode, tau,
                                                       np.random.default_rng(2))[2])
    np.testing.assert_array_equal(got[1, :3], 0.0)


def test_writes_into_views_and_keeps_inputs() -> None:
    """``out`` views (the prediction's first columns) are filled and returned; inputs unchanged."""
    motion = MOTIONS[0]
    x, mode, tau = _particles(motion)
    copies = (x.copy(), mode.copy(), tau.copy())
    bx, bmode, btau = np.full((3, 700, 4), 7.0), np.full((3, 700), 5, np.int8), np.zeros((3, 700))
    out = (bx[:, :500], bmode[:, :500], btau[:, :500])
    result = propagate(motion, x, mode, tau, np.random.default_rng(1), out=out)
    assert all(r is o for r, o in zip(result, out, strict=True))
    want = model.propagate(motion, x, mode, tau, np.random.default_rng(1))
    for got, w in zip(out, want, strict=True):
        np.testing.assert_array_equal(got, w)
    assert np.all(bx[:, 500:] == 7.0) and np.all(bmode[:, 500:] == 5)
    for a, b in zip((x, mode, tau), copies, strict=True):
        np.testing.assert_array_equal(a, b)


X, MODE, TAU = _particles(MOTIONS[0])


@pytest.mark.parametrize(("args", "field"), [
    ((X[:, :, :2], MODE, TAU), "x"),
    ((X[0], MODE, TAU), "x"),
    ((X, MODE[:, :3], TAU), "mode"),
    ((X, MODE + 1, TAU), "mode"),
    ((X, MODE.astype(float), TAU), "mode"),
    ((X, MODE, TAU[:2]), "tau"),
])
def test_bad_input(args: tuple[np.ndarray, ...], field: str) -> None:
    """Inconsistent shapes or modes other than 0/1 raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        propagate(MOTIONS[0], *args, np.random.default_rng(0))  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize("out", [
    (np.empty((3, 499, 4)), np.empty((3, 500), np.int8), np.empty((3, 500))),
    (np.empty((3, 500, 4)), np.empty((3, 500), np.int64), np.empty((3, 500))),
    (np.empty((3, 500, 4)), np.empty((3, 500), np.int8), np.empty((3, 500), np.float32)),
])
def test_bad_out(out: tuple[np.ndarray, ...]) -> None:
    """``out`` arrays of the wrong shape or dtype are refused before anything is drawn."""
    rng = np.random.default_rng(0)
    with pytest.raises(InvalidInputError, match="out"):
        propagate(MOTIONS[0], X, MODE, TAU, rng, out=out)  # type: ignore[arg-type]
    assert rng.random() == np.random.default_rng(0).random()
    with pytest.raises(InvalidInputError, match="rng"):
        propagate(MOTIONS[0], X, MODE, TAU, 0)  # type: ignore[arg-type]
