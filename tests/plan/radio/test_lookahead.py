"""The look-ahead cloud: the documented draws, no birth or death, the estimates, and the void
probability against the plain-array form."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.labelled_particles import resample
from searchtrack.models.radio import propagate
from searchtrack.plan.radio.divergences import disc_mass, void_probability
from searchtrack.plan.radio.lookahead import look_ahead

from .helpers import problem


def test_shapes_and_prediction_without_birth_or_death() -> None:
    """T = H·N_p seconds of Λ × N positions, H frame sets; r is the belief's, weights equal."""
    p = problem(horizon=3, plan_particles=40)
    la = look_ahead(p, np.random.default_rng(0))
    assert la.xy.shape == (15, 4, 40, 2) and la.frames.shape == (3, 4, 40)
    assert la.estimate_xy.shape == (3, 4, 2) and la.estimate_frame.shape == (3, 4)
    assert np.array_equal(la.r, p.belief.r)
    assert np.allclose(la.w, 1.0 / 40)
    assert la.estimated.tolist() == [True, True, False, True]


def test_draws_follow_the_documented_recipe() -> None:
    """Systematic resampling, then one full propagation per second, all from one generator."""
    p = problem(horizon=2, plan_particles=30)
    la = look_ahead(p, np.random.default_rng(5))
    rng = np.random.default_rng(5)
    cloud = resample(p.belief, rng, 30)
    x, mode, tau = cloud.x, cloud.mode, cloud.tau
    for t in range(10):
        x, mode, tau = propagate(p.scenario.motion, x, mode, tau, rng)
        assert np.array_equal(la.xy[t], x[:, :, ::2])
        if t in (4, 9):
            j = t // 5
            frames = p.scenario.signal.frame_of(tau)
            assert np.array_equal(la.frames[j], frames)
            assert np.allclose(la.estimate_xy[j], x[:, :, ::2].mean(axis=1))
            for lab in range(4):
                counts = np.bincount(frames[lab])
                assert la.estimate_frame[j, lab] == int(np.argmax(counts))


def test_deterministic_per_seed() -> None:
    """The same seed gives the same cloud; another seed another one."""
    p = problem()
    a, b = look_ahead(p, np.random.default_rng(1)), look_ahead(p, np.random.default_rng(1))
    c = look_ahead(p, np.random.default_rng(2))
    assert np.array_equal(a.xy, b.xy) and not np.array_equal(a.xy, c.xy)


@pytest.mark.parametrize("radius", [0.0, 30.0, 80.0, 400.0])
def test_void_equals_the_plain_array_form(radius: float) -> None:
    """Disc mass and void probability (labels skipped by their bounding boxes) equal the dense
    computation."""
    p = problem(plan_particles=50)
    la = look_ahead(p, np.random.default_rng(3))
    centres = np.random.default_rng(4).uniform(200.0, 1100.0, (25, 2))
    for t in (0, 7):
        mass = la.disc_mass(t, centres, radius)
        assert np.allclose(mass, disc_mass(la.w, la.xy[t], centres, radius), atol=1e-12)
        assert np.allclose(la.void(t, centres, radius),
                           void_probability(la.r, la.w, la.xy[t], centres, radius), atol=1e-12)


def test_no_void_region() -> None:
    """r_min = 0: the empty disc has void probability 1; another radius is still counted, not
    silently taken as empty."""
    p = problem(r_min_m=0.0)
    la = look_ahead(p, np.random.default_rng(0))
    assert la.radii.tolist() == [0.0] * 4
    assert np.array_equal(la.void(3, np.array([[850.0, 650.0]]), 0.0), [1.0])
    assert np.allclose(la.void(3, np.array([[850.0, 650.0]]), 80.0),
                       void_probability(la.r, la.w, la.xy[3], np.array([[850.0, 650.0]]), 80.0))


def test_keep_out_radii_grow_with_each_label_spread() -> None:
    """spread_inflation κ: an estimated label's void disc has radius r_min + κ √(var x + var y)
    of the drawn cloud (before the prediction), the others' (r ≤ 0.5: label 2) r_min; κ = 0
    leaves r_min for every label; the per-label discs give the same void as the dense form and
    never more void than r_min alone."""
    p = problem(plan_particles=50, spread_inflation=2.0)
    la = look_ahead(p, np.random.default_rng(3))
    drawn = resample(p.belief, np.random.default_rng(3), 50)
    xy = drawn.x[:, :, ::2]
    want = 50.0 + 2.0 * np.sqrt(xy[..., 0].var(axis=1) + xy[..., 1].var(axis=1))
    want[2] = 50.0
    assert p.belief.r[2] <= 0.5 < p.belief.r[[0, 1, 3]].min()
    np.testing.assert_allclose(la.radii, want, rtol=1e-12)
    assert np.all(la.radii[[0, 1, 3]] > 50.0)
    plain = look_ahead(problem(plan_particles=50), np.random.default_rng(3))
    assert plain.radii.tolist() == [50.0] * 4
    centres = np.random.default_rng(4).uniform(200.0, 1100.0, (25, 2))
    for t in (0, 7):
        dense = void_probability(la.r, la.w, la.xy[t], centres, la.radii)
        assert np.allclose(la.void(t, centres), dense, atol=1e-12)
        assert np.all(la.void(t, centres) <= plain.void(t, centres) + 1e-12)
    assert np.any(la.void(7, centres) < plain.void(7, centres) - 1e-3)


def test_radii_per_label_are_checked() -> None:
    """One radius per label, each finite and ≥ 0, else InvalidInputError naming radius_m."""
    la = look_ahead(problem(plan_particles=20), np.random.default_rng(0))
    for bad in ([10.0, 20.0], [10.0, -1.0, 5.0, 5.0], [10.0, np.nan, 5.0, 5.0]):
        with pytest.raises(InvalidInputError, match="radius_m"):
            la.void(0, np.zeros((1, 2)), np.array(bad))
