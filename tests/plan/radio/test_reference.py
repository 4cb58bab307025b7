"""The fused scoring of the look-ahead tree equals the reference (NumPy) scoring on many small
random beliefs: the same look-ahead draws, the same children, posteriors, rewards and voids, and
the same plans and objectives from every exact backend."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Status
from searchtrack.estimate.labelled_particles import LabelledParticles
from searchtrack.plan.radio import RadioPlanProblem, RadioPlanSettings, backends, solve
from searchtrack.plan.radio.lookahead import look_ahead
from searchtrack.plan.radio.reference import ReferenceScorer, reference_look_ahead
from searchtrack.plan.radio.search import beam_search, exhaustive_search
from searchtrack.plan.radio.tree import Nodes, Scorer

from .helpers import scenario

#: The reward settings drawn from.
REWARDS: tuple[dict[str, object], ...] = (
    {"reward": "renyi", "alpha": 0.5}, {"reward": "renyi", "alpha": 1.0},
    {"reward": "renyi", "alpha": 2.0}, {"reward": "renyi", "alpha": 0.3},
    {"reward": "cs", "cs_k": 1.0}, {"reward": "cs", "cs_k": 2.5},
)


def random_problem(seed: int, *, extreme: bool = True) -> RadioPlanProblem:
    """A small random problem: tags scattered around a random pose at random spreads,
    existences, weights and pulse offsets; random particle counts, horizon and reward;
    ``extreme``: one label's existence 0, ½ or 1."""
    rng = np.random.default_rng(seed)
    labels, n = 4, int(rng.integers(5, 60))
    pose = np.array([*rng.uniform(200.0, 1000.0, 2), rng.uniform(-np.pi, np.pi)])
    centres = pose[:2] + rng.uniform(-400.0, 400.0, (labels, 2))
    spread = rng.uniform(5.0, 150.0, labels)
    x = np.zeros((labels, n, 4))
    x[:, :, 0] = centres[:, None, 0] + spread[:, None] * rng.standard_normal((labels, n))
    x[:, :, 2] = centres[:, None, 1] + spread[:, None] * rng.standard_normal((labels, n))
    x[:, :, 1::2] = rng.standard_normal((labels, n, 2))
    mode = rng.integers(0, 2, (labels, n)).astype(np.int8)
    tau = np.mod(rng.uniform(0.0, 1.0, labels)[:, None]
                 + rng.uniform(0.0, 0.05) * rng.standard_normal((labels, n)), 1.0)
    w = rng.uniform(0.1, 1.0, (labels, n))
    r = rng.uniform(0.0, 1.0, labels)
    special = rng.integers(0, labels), float(rng.choice([0.0, 1.0, 0.5]))
    if extreme:
        r[special[0]] = special[1]
    belief = LabelledParticles(x, mode, tau, w / w.sum(axis=1, keepdims=True), r)
    settings = RadioPlanSettings(
        plan_particles=int(rng.integers(3, 40)), horizon=int(rng.integers(1, 4)),
        r_min_m=float(rng.choice([0.0, 30.0, 80.0])),
        spread_inflation=float(rng.choice([0.0, 1.0])),
        p_void_min=float(rng.uniform(0.5, 0.99)), discount=float(rng.uniform(0.5, 1.0)),
        **REWARDS[seed % len(REWARDS)])  # type: ignore[arg-type]
    return RadioPlanProblem(belief, pose, scenario(int(rng.choice([3, 4, 6]))), settings)


@pytest.mark.parametrize("seed", range(6))
def test_the_look_ahead_draws_are_the_references(seed: int) -> None:
    """The fused propagation gives the reference's cloud, estimates and radii bit for bit."""
    p = random_problem(seed)
    fused = look_ahead(p, np.random.default_rng(seed))
    ref = reference_look_ahead(p, np.random.default_rng(seed))
    for name in ("xy", "frames", "r", "w", "estimated", "estimate_xy", "estimate_frame",
                 "radii"):
        assert np.array_equal(getattr(fused, name), getattr(ref, name)), name


def _close(a: Nodes, b: Nodes) -> None:
    assert np.array_equal(a.headings, b.headings) and np.array_equal(a.path, b.path)
    np.testing.assert_allclose(a.void, b.void, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(a.rewards, b.rewards, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(a.value, b.value, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(a.r, b.r, rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(np.exp(a.log_w), np.exp(b.log_w), rtol=1e-9, atol=1e-14)


@pytest.mark.parametrize("seed", range(40))
def test_every_level_equals_the_reference(seed: int) -> None:
    """Every node of the tree, level by level: the fused expansion's children equal the
    reference's (paths exactly; voids, rewards, values and posteriors to rounding)."""
    p = random_problem(seed)
    fused, ref = Scorer(p, seed), ReferenceScorer(p, seed)
    a, b = fused.root(), ref.root()
    for _ in range(p.settings.horizon):
        a, b = fused.expand_all(a), ref.expand_all(b)
        _close(a, b)


@pytest.mark.parametrize("seed", range(40, 60))
def test_searches_answer_as_the_reference(seed: int) -> None:
    """Exhaustive and beam searches find the same sequence with the same rank."""
    p = random_problem(seed)
    fused, ref = Scorer(p, seed), ReferenceScorer(p, seed)
    for search in (lambda s: exhaustive_search(s, Deadline(60.0)),
                   lambda s: beam_search(s, Deadline(60.0), 2)):
        got, want = search(fused).best, search(ref).best
        assert got is not None and want is not None
        assert np.array_equal(got.plan.headings, want.plan.headings)
        assert got.key[0] == want.key[0]
        assert got.key[1:] == pytest.approx(want.key[1:], rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("seed", range(60, 72))
@pytest.mark.parametrize("backend", ["exhaustive", "beam", "auto"])
def test_backends_answer_as_on_the_reference(seed: int, backend: str,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """Through solve (the validator checking every answer): the same status, plan and
    objective on the fused scoring as on the reference (another plan only where the two tie to
    rounding), and the same again on a second call."""
    p = random_problem(seed, extreme=False)
    fused = [solve(p, backend=backend, time_limit_s=60.0, seed=seed) for _ in range(2)]
    monkeypatch.setattr(backends, "Scorer", ReferenceScorer)
    ref = solve(p, backend=backend, time_limit_s=60.0, seed=seed)
    for got in fused:
        assert got.status is ref.status and got.status is not Status.ERROR, got.message
        assert got.plan is not None and ref.plan is not None
        assert got.plan.feasible == ref.plan.feasible
        if ref.objective is None:
            assert got.objective is None
            assert np.array_equal(got.plan.headings, ref.plan.headings)
        else:
            assert got.objective == pytest.approx(ref.objective, rel=1e-9, abs=1e-12)
    assert np.array_equal(fused[0].plan.rewards, fused[1].plan.rewards)
    assert np.array_equal(fused[0].plan.void, fused[1].plan.void)
