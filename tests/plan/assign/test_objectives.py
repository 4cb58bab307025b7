"""The objectives: END and binary MI as set functions (values, monotonicity, submodularity,
gains, caching), their specs and the coverage check."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.assign import AssignmentProblem
from searchtrack.plan.assign.mutual_info import binary_mi
from searchtrack.plan.assign.objectives import (
    ExpectedDetections,
    ExpectedDetectionsFunction,
    MutualInformation,
    MutualInformationFunction,
    coverage_only,
    expected_detections_of_poses,
)

from .helpers import DiscSensor, random_problem


@pytest.mark.parametrize("objective", ["end", "mi"])
@pytest.mark.parametrize("seed", range(6))
def test_monotone_and_submodular(objective: str, seed: int) -> None:
    """f(A ∪ e) − f(A) ≥ f(B ∪ e) − f(B) ≥ 0 for A ⊆ B over random (UAV, action) sets."""
    rng = np.random.default_rng(seed)
    p = random_problem(rng, robots=4, actions=3, steps=2, particles=40, objective=objective,
                       gaussian=seed % 2 == 0)
    f = p.objective.evaluator(p)
    ground = [(r, a) for r in range(4) for a in range(3)]
    assert f.value(()) == pytest.approx(0.0, abs=1e-9)
    for _ in range(15):
        idx = rng.permutation(len(ground))
        big = [ground[i] for i in idx[:4]]
        small = big[: rng.integers(0, 4)]
        e = ground[idx[5]]
        gain_small = f.value([*small, e]) - f.value(small)
        gain_big = f.value([*big, e]) - f.value(big)
        assert gain_big >= -1e-9
        assert gain_small >= gain_big - 1e-7

def test_end_closed_form_matches_definition() -> None:
    """END equals Σ w (1 − Π (1 − p_d)) computed pose by pose, and gains match differences."""
    rng = np.random.default_rng(3)
    p = random_problem(rng, robots=3, actions=4, steps=2, gaussian=True)
    f = ExpectedDetectionsFunction(p)
    sel = ((0, 1), (2, 3))
    poses = np.concatenate([p.actions[r][a] for r, a in sel])
    expected = sum(w * (1 - np.prod([1 - p.sensor.detection_probability(q, p.positions)[j]
                                     for q in poses])) for j, w in enumerate(p.weights))
    assert f.value(sel) == pytest.approx(expected, rel=1e-12)
    assert expected_detections_of_poses(p, poses) == pytest.approx(expected, rel=1e-12)
    gains = f.gains(sel, 1)
    for a in range(4):
        assert gains[a] == pytest.approx(f.value([*sel, (1, a)]) - f.value(sel), abs=1e-12)
        assert f.gain(sel, 1, a) == pytest.approx(gains[a], abs=1e-12)

def test_objective_specs_build_their_set_functions() -> None:
    """Each spec names itself, declares whether it is a coverage objective and builds its set
    function; MutualInformation checks its settings."""
    from searchtrack.core.errors import InvalidInputError

    p = random_problem(np.random.default_rng(0))
    end, mi = ExpectedDetections(), MutualInformation(clutter_rate=0.1)
    assert (end.name, end.coverage, mi.name, mi.coverage) == ("end", True, "mi", False)
    assert isinstance(end.evaluator(p), ExpectedDetectionsFunction)
    assert mi.evaluator(p).value(()) == pytest.approx(0.0, abs=1e-12)
    for kwargs, field in (({"exact_max": 21}, "exact_max"), ({"samples": 5}, "samples"),
                          ({"clutter_rate": -1.0}, "clutter_rate"), ({"seed": -1}, "seed")):
        with pytest.raises(InvalidInputError, match=field):
            MutualInformation(**kwargs)  # type: ignore[arg-type]


def test_end_by_hand() -> None:
    """Particles of weight 1 (x = 0) and 2 (x = 50), p_d = 0.8 within 10 m; UAV 0 over the
    first, UAV 1 over either. Both over the first: miss (0.04, 1), END 0.96; split: miss
    (0.2, 0.2), END 0.8 + 1.6 = 2.4; UAV 1's gains given UAV 0 are 0.8 · 0.2 and 2 · 0.8."""
    belief = WeightedParticles(np.array([[0.0, 0.0], [50.0, 0.0]]), np.array([1.0, 2.0]))
    uav0 = np.array([[[0.0, 0.0, 20.0]]])
    uav1 = np.array([[[0.0, 0.0, 20.0]], [[50.0, 0.0, 20.0]]])
    f = ExpectedDetectionsFunction(AssignmentProblem((uav0, uav1), belief, DiscSensor()))
    np.testing.assert_allclose(f.miss_product(((0, 0), (1, 0))), [0.04, 1.0], rtol=1e-12)
    np.testing.assert_allclose(f.miss_product(((0, 0), (1, 1))), [0.2, 0.2], rtol=1e-12)
    assert f.value(((0, 0), (1, 0))) == pytest.approx(0.96, rel=1e-12)
    assert f.value(((0, 0), (1, 1))) == pytest.approx(2.4, rel=1e-12)
    np.testing.assert_allclose(f.gains(((0, 0),), 1), [0.16, 1.6], rtol=1e-12)
    assert f.gain(((0, 0),), 1, 1) == pytest.approx(1.6, rel=1e-12)


def test_expected_detections_of_arbitrary_poses() -> None:
    """END of poses off the candidate set: two looks at a particle of weight 2 give
    2 (1 − 0.2²) = 1.92, whatever the leading shape of the pose array."""
    p = AssignmentProblem((np.zeros((1, 1, 3)),),
                          WeightedParticles(np.zeros((1, 2)), np.full(1, 2.0)), DiscSensor())
    poses = np.array([[[1.0, 0.0, 20.0]], [[0.0, 2.0, 20.0]]])  # (R, T, 3)
    assert expected_detections_of_poses(p, poses) == pytest.approx(1.92, rel=1e-12)
    assert expected_detections_of_poses(p, poses.reshape(2, 3)) == pytest.approx(1.92)


def test_mutual_information_function_values_gains_and_cache() -> None:
    """The MI of a selection is binary MI of the stacked detection rows, whatever the order of
    the pairs; gains are value differences."""
    p = random_problem(np.random.default_rng(6), robots=2, actions=3, steps=2, particles=30,
                       objective="mi")
    f = MutualInformationFunction(p, MutualInformation())
    sel = ((1, 2), (0, 1))
    direct = binary_mi(np.concatenate([p.detection[0][1], p.detection[1][2]]), p.weights)
    assert f.value(sel) == pytest.approx(direct, rel=1e-9)
    assert f.value(sel[::-1]) == f.value(sel)
    gains = f.gains(((0, 1),), 1)
    for a in range(3):
        expected = f.value(((0, 1), (1, a))) - f.value(((0, 1),))
        assert gains[a] == pytest.approx(max(expected, 0.0), abs=1e-12)
        assert f.gain(((0, 1),), 1, a) == pytest.approx(gains[a], abs=1e-12)


def test_coverage_only() -> None:
    """END passes the coverage check; MI is refused with a reason naming it."""
    p = random_problem(np.random.default_rng(0))
    assert coverage_only(p) is None
    reason = coverage_only(random_problem(np.random.default_rng(0), objective="mi"))
    assert reason is not None and "'mi'" in reason
    assert ExpectedDetections().evaluator(p).value(()) == 0.0
