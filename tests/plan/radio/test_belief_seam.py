"""The belief seam: the radio planner reads a LabelledParticleBelief, whichever implementation
holds it. On a small independent belief written here (one packed array per label, modes stored
as floats) it answers exactly as on the library's LabelledParticles and the TBD-LMB filter
holding the same numbers."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.belief import LabelledParticleBelief
from searchtrack.estimate.labelled_particles import LabelledParticles
from searchtrack.plan.radio import (
    BACKENDS,
    RadioPlanProblem,
    RadioPlanSettings,
    check_plan,
    solve,
)
from searchtrack.plan.radio.lookahead import look_ahead

from .helpers import POSE, scenario, spread_belief, tag_ahead


class PackedBelief:
    """A test-local labelled belief: per label one ``(N, 7)`` array of columns
    ``px, vx, py, vy, mode, tau, w`` and an existence probability, kept as Python lists."""

    def __init__(self, x: FloatArray, mode: FloatArray, tau: FloatArray, w: FloatArray,
                 r: FloatArray) -> None:
        self._rows = [np.column_stack([x[lab], mode[lab].astype(np.float64), tau[lab], w[lab]])
                      for lab in range(x.shape[0])]
        self._r = [float(v) for v in r]

    def _column(self, j: int) -> FloatArray:
        return np.stack([rows[:, j] for rows in self._rows])

    @property
    def x(self) -> FloatArray:
        return np.stack([rows[:, :4] for rows in self._rows])

    @property
    def mode(self) -> IntArray:
        return self._column(4).astype(np.int64)

    @property
    def tau(self) -> FloatArray:
        return self._column(5)

    @property
    def w(self) -> FloatArray:
        return self._column(6)

    @property
    def r(self) -> FloatArray:
        return np.array(self._r)


def _packed(b: LabelledParticles) -> PackedBelief:
    return PackedBelief(b.x, b.mode, b.tau, b.w, b.r)


def _problems(b: LabelledParticles, **settings: object) -> list[RadioPlanProblem]:
    """The same numbers as the library's store and as the test-local belief."""
    kw: dict[str, object] = {"plan_particles": 40, "horizon": 2}
    kw.update(settings)
    st = RadioPlanSettings(**kw)  # type: ignore[arg-type]
    beliefs: list[LabelledParticleBelief] = [b, _packed(b)]
    assert all(isinstance(v, LabelledParticleBelief) for v in beliefs)
    assert not isinstance(beliefs[1], LabelledParticles)
    return [RadioPlanProblem(v, POSE, scenario(), st) for v in beliefs]


def _same_answers(problems: list[RadioPlanProblem], backends: list[str], seed: int) -> None:
    for backend in backends:
        results = [solve(p, backend=backend, seed=seed, time_limit_s=60.0) for p in problems]
        first = results[0]
        assert first.plan is not None, backend
        for p, res in zip(problems[1:], results[1:], strict=True):
            assert res.status is first.status and res.objective == first.objective, backend
            assert res.plan is not None and res.plan.feasible == first.plan.feasible, backend
            for name in ("headings", "path", "rewards", "void"):
                np.testing.assert_array_equal(getattr(res.plan, name),
                                              getattr(first.plan, name), err_msg=backend)
            a = check_plan(problems[0], first.plan, seed=seed,
                           any_heading=backend == "straight")
            b = check_plan(p, res.plan, seed=seed, any_heading=backend == "straight")
            assert a.valid == b.valid and a.objective == b.objective, backend
            np.testing.assert_array_equal(a.void, b.void)
            np.testing.assert_array_equal(a.rewards, b.rewards)


@pytest.mark.parametrize("reward", ["renyi", "cs"])
def test_every_backend_answers_alike_on_the_test_belief(reward: str) -> None:
    """Every backend gives the same status, objective, plan and validator verdict on the
    library's belief and on the packed one (a tag ahead: the void constraint binds)."""
    problems = _problems(tag_ahead(), reward=reward, alpha=0.7)
    _same_answers(problems, list(BACKENDS.names()), seed=7)


def test_the_problem_holds_the_same_numbers_and_look_ahead() -> None:
    """The problem's read-only copy and the look-ahead cloud are equal, array by array."""
    lib, packed = _problems(spread_belief(2), horizon=3, plan_particles=30)
    assert packed.belief.mode.dtype == lib.belief.mode.dtype == np.int8
    for name in ("x", "mode", "tau", "w", "r"):
        np.testing.assert_array_equal(getattr(packed.belief, name), getattr(lib.belief, name))
        assert not getattr(packed.belief, name).flags.writeable
    one = look_ahead(lib, np.random.default_rng(3))
    two = look_ahead(packed, np.random.default_rng(3))
    for name in ("xy", "frames", "r", "w", "estimated", "estimate_xy", "estimate_frame"):
        np.testing.assert_array_equal(getattr(two, name), getattr(one, name))


def test_the_filter_is_planned_on_directly() -> None:
    """The TBD-LMB filter is a LabelledParticleBelief: planning on it answers as on a copy of
    its state, and the plan does not change the filter."""
    from searchtrack.estimate.radio import TbdLmbFilter
    from searchtrack.estimate.radio.filter import FilterConfig
    from searchtrack.models.radio import simulate_stft

    sc = scenario()
    filt = TbdLmbFilter(sc, FilterConfig(particles_per_label=300), seed=4)
    rng = np.random.default_rng(5)
    for k in range(3):
        pose = np.array([600.0 + 10.0 * k, 600.0, 0.0])
        filt.step(simulate_stft(sc.signal, np.array([[700.0, 650.0]]), np.array([0]),
                                np.array([0.3]), pose, rng), pose)
    assert isinstance(filt, LabelledParticleBelief)
    before = filt.labelled_particles()
    st = RadioPlanSettings(horizon=2, plan_particles=30)
    problems = [RadioPlanProblem(v, POSE, sc, st) for v in (filt, before, _packed(before))]
    _same_answers(problems, ["exhaustive", "greedy"], seed=1)
    for name in ("x", "mode", "tau", "w", "r"):
        np.testing.assert_array_equal(getattr(filt.state, name), getattr(before, name))


def test_a_belief_of_mismatched_arrays_is_refused() -> None:
    """A belief whose arrays disagree in shape is refused, naming the belief."""
    b = _packed(spread_belief())
    b._r = b._r[:3]
    with pytest.raises(InvalidInputError, match="belief"):
        RadioPlanProblem(b, POSE, scenario())
