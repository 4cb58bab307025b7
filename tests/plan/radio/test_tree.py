"""Tree expansion: children in order, the shared-prefix posterior update (eqs. 29–30), the
reward, the discounted value and the void probability at every pose."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate.labelled_particles import LabelledParticles, update
from searchtrack.models.radio import primitives
from searchtrack.plan.radio import tree as tree_module
from searchtrack.plan.radio.divergences import cauchy_schwarz, renyi, void_probability
from searchtrack.plan.radio.ideal import amplitudes, frame_counts, frame_overlap
from searchtrack.plan.radio.tree import Nodes, Scorer

from .helpers import problem


def test_root() -> None:
    """The root is the UAV's pose with π₂ = π₁: equal weights, the belief's r, raised to
    ``explore_existence`` for the labels not in the ideal measurement set (r ≤ 0.5)."""
    p = problem(plan_particles=20)
    root = Scorer(p, 0).root()
    assert root.size == 1 and root.level == 0 and root.min_void.tolist() == [1.0]
    assert p.belief.r.tolist() == [0.9, 0.6, 0.3, 0.97]
    assert np.allclose(np.exp(root.log_w), 1 / 20) and root.r[0].tolist() == [0.9, 0.6, 0.5, 0.97]
    plain = Scorer(problem(plan_particles=20, explore_existence=0.0), 0).root()
    assert np.array_equal(plain.r[0], p.belief.r)
    assert np.array_equal(root.pose[0], p.uav_pose)


def _posterior(scorer: Scorer, parent_w: np.ndarray, parent_r: np.ndarray, level: int,
               pose: np.ndarray) -> LabelledParticles:
    """The filter's update of one parent by the ideal measurement at ``pose`` (NumPy path)."""
    la, sig = scorer.look, scorer.problem.scenario.signal
    t = (level + 1) * 5 - 1
    gamma = amplitudes(sig, la.xy[t], pose[None])
    gamma_hat = amplitudes(sig, la.estimate_xy[level], pose[None]) * la.estimated
    log_g = scorer.likelihood.log_likelihood(
        gamma, frame_counts(la.frames[level], sig.frames),
        frame_overlap(la.frames[level], la.estimate_frame[level], sig.frames), gamma_hat)[0]
    dummy = np.zeros((*parent_w.shape, 4))
    prior = LabelledParticles(dummy, np.zeros(parent_w.shape, np.int8), np.zeros(parent_w.shape),
                              parent_w, parent_r)
    return update(prior, log_g)


@pytest.mark.parametrize("reward", ["renyi", "cs"])
def test_two_levels_by_hand(reward: str) -> None:
    """Each child: the primitives' path, the filter's update of its parent, D(π₂, π₁), the
    discounted sum, and the void probability of the cloud at each of its poses; the reward's
    densities start from the exploration existences (label 2, r = 0.3 → 0.5), the void from
    the belief's r."""
    p = problem(plan_particles=40, reward=reward, discount=0.7, alpha=0.3, cs_k=2.0)
    sc = Scorer(p, 3)
    one = sc.expand(sc.root())
    heads, paths = primitives(p.scenario.uav, p.uav_pose, p.scenario.area_m)
    assert np.array_equal(one.headings[:, 0], heads) and np.array_equal(one.path, paths)
    two = sc.expand(one)
    assert two.size == sum(primitives(p.scenario.uav, q, p.scenario.area_m)[0].size
                           for q in one.pose)
    la = sc.look
    r1 = np.where(la.r <= 0.5, np.maximum(la.r, 0.5), la.r)
    assert r1.tolist() == [0.9, 0.6, 0.5, 0.97]
    parent = 0
    for c in range(two.size):
        while not np.array_equal(two.path[c, :5], one.path[parent]):
            parent += 1
        for level, node, idx, prev in ((0, one, parent, None), (1, two, c, parent)):
            w_in = la.w if prev is None else np.exp(one.log_w[prev])
            r_in = r1 if prev is None else one.r[prev]
            post = _posterior(sc, w_in, r_in, level, node.path[idx, 5 * level + 4])
            assert np.allclose(np.exp(node.log_w[idx]), post.w, rtol=1e-9, atol=1e-15)
            assert np.allclose(node.r[idx], post.r, rtol=1e-9, atol=1e-15)
            div = (renyi(r1, la.w, post.r, post.w, 0.3) if reward == "renyi"
                   else cauchy_schwarz(r1, la.w, post.r, post.w, 2.0))
            assert node.rewards[idx, level] == pytest.approx(float(div), rel=1e-8, abs=1e-12)
        assert two.value[c] == pytest.approx(two.rewards[c, 0] + 0.7 * two.rewards[c, 1])
        for s in range(10):
            want = void_probability(la.r, la.w, la.xy[s], two.path[c, s, :2], 50.0)
            assert two.void[c, s] == pytest.approx(float(want), abs=1e-12)
    assert np.all(two.rewards > 0.0)


def test_expand_all_in_parts_equals_one_expansion(monkeypatch: pytest.MonkeyPatch) -> None:
    """Splitting a batch to bound memory changes nothing, order included."""
    p = problem(plan_particles=30)
    sc = Scorer(p, 1)
    one = sc.expand(sc.root())
    whole = sc.expand(one)
    monkeypatch.setattr(tree_module, "BATCH_ELEMENTS", 1)
    assert len(one.chunks(sc.per_child)) == one.size
    parts = sc.expand_all(one)
    for a, b in zip((whole.path, whole.log_w, whole.r, whole.value, whole.void),
                    (parts.path, parts.log_w, parts.r, parts.value, parts.void), strict=True):
        assert np.array_equal(a, b)


def test_custom_actions_feasibility_and_plan() -> None:
    """An actions rule replaces the primitives; feasibility is min void > P_vmin; a complete
    node becomes a plan carrying its own arrays."""
    p = problem(plan_particles=30, horizon=1)
    sc = Scorer(p, 0)
    heads, paths = primitives(p.scenario.uav, p.uav_pose, p.scenario.area_m)

    def second_only(pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return heads[1:2], paths[1:2]

    kids = sc.expand(sc.root(), second_only)
    assert kids.size == 1 and kids.headings[0, 0] == heads[1]
    plan = sc.plan(kids, 0)
    assert plan.feasible == bool(kids.void[0].min() > 0.9)
    assert np.array_equal(plan.path, paths[1]) and plan.rewards[0] == kids.rewards[0, 0]
    taken = kids.take(np.array([0, 0]))
    assert isinstance(taken, Nodes) and taken.size == 2


@pytest.mark.parametrize("n_headings", [3, 4, 8])
def test_batch_primitives_are_the_models_pose_by_pose(n_headings: int) -> None:
    """Poses inside the area, near its edges and outside it: the batch gives the primitives
    of each pose bit for bit, pose by pose, in primitive order."""
    p = problem(n_headings=n_headings)
    uav, area = p.scenario.uav, p.scenario.area_m
    rng = np.random.default_rng(n_headings)
    poses = np.c_[rng.uniform(-200.0, 1700.0, (300, 2)), rng.uniform(-np.pi, np.pi, 300)]
    poses[:40, 0] = rng.choice([1.0, 20.0, 1480.0, 1499.0], 40)
    parent, heads, paths = tree_module.batch_primitives(uav, poses, area)
    at = 0
    for b in range(poses.shape[0]):
        want_h, want_p = primitives(uav, poses[b], area)
        k = want_h.size
        assert np.array_equal(parent[at:at + k], np.full(k, b))
        assert np.array_equal(heads[at:at + k], want_h)
        assert np.array_equal(paths[at:at + k], want_p)
        at += k
    assert at == parent.size
