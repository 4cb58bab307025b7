"""Backend registries, and the two ways an ``auto`` backend composes others: heuristic then
exact, and a fallback chain."""

from __future__ import annotations

import time

import pytest

from searchtrack.core import (
    Backend,
    Deadline,
    Registry,
    Result,
    Stage,
    Status,
    fallback_chain,
    heuristic_then_exact,
    relabel,
)
from searchtrack.core.errors import InvalidInputError

Calls = list[tuple[str, float]]


def _backend(name: str, status: Status, objective: float | None, bound: float | None,
             calls: Calls):
    """A toy backend that records its time limit and answers with fixed numbers."""
    def solve(problem: int, /, *, time_limit_s: float, seed: int) -> Result[str]:
        calls.append((name, time_limit_s))
        plan = f"{name}-plan" if status.has_plan else None
        return Result(status, objective, bound, 0.0, name, plan, message=f"{name} says hi")
    return solve


def test_heuristic_then_exact_merges_and_proves() -> None:
    """The exact stage gets the heuristic's answer and the time left; the answer has the better
    plan, the tighter bound, OPTIMAL when they meet, and the heuristic's numbers in stats."""
    calls: Calls = []
    seen: list[Result[str]] = []

    def exact(problem: int, first: Result[str], limit_s: float, seed: int) -> Result[str]:
        seen.append(first)
        return _backend("exact", Status.OPTIMAL, 5.0, 5.0, calls)(problem, time_limit_s=limit_s,
                                                                     seed=seed)

    out = heuristic_then_exact(1, _backend("heur", Status.FEASIBLE, 5.0, None, calls), exact,
                               time_limit_s=2.0, seed=0, heuristic_limit_s=0.5)
    assert calls[0] == ("heur", 0.5) and 1.0 < calls[1][1] <= 2.0
    assert seen[0].plan == "heur-plan"
    assert out.status is Status.OPTIMAL and out.bound == 5.0 and out.objective == 5.0
    assert out.stats["heuristic_objective"] == 5.0 and "answered" in out.message


def test_heuristic_then_exact_keeps_a_better_heuristic_plan() -> None:
    """A heuristic plan better than the exact stage's (cut off early) is the answer, with the
    exact stage's bound."""
    calls: Calls = []
    out = heuristic_then_exact(
        1, _backend("heur", Status.FEASIBLE, 7.0, None, calls),
        lambda p, first, limit, seed: _backend("exact", Status.FEASIBLE, 6.0, 9.0, calls)(
            p, time_limit_s=limit, seed=seed),
        time_limit_s=1.0, seed=0, heuristic_limit_s=0.1)
    assert (out.plan, out.bound, out.status, out.backend) == ("heur-plan", 9.0, Status.FEASIBLE,
                                                              "heur")


def test_heuristic_then_exact_without_an_exact_stage() -> None:
    """With no exact stage the heuristic's answer comes back, its runtime the composite's."""
    calls: Calls = []
    out = heuristic_then_exact(1, _backend("heur", Status.FEASIBLE, 3.0, None, calls), None,
                               time_limit_s=1.0, seed=0, heuristic_limit_s=5.0)
    assert calls == [("heur", 1.0)] and out.plan == "heur-plan"
    assert out.message == "auto: heur answered (heur says hi)"


def test_heuristic_then_exact_says_no_empty_parentheses() -> None:
    """A heuristic answer with no message of its own reads "answered", not "answered ()"."""
    def quiet(problem: int, /, *, time_limit_s: float, seed: int) -> Result[str]:
        return Result(Status.FEASIBLE, 3.0, None, 0.0, "ils", "plan")

    out = heuristic_then_exact(1, quiet, None, time_limit_s=1.0, seed=0, heuristic_limit_s=1.0)
    assert out.message == "auto: ils answered"


def test_fallback_chain_takes_the_first_answer() -> None:
    """Stages run in order until one has a plan; the message names the failures and
    ``stats["fallbacks"]`` counts them; shares scale the whole limit."""
    calls: Calls = []
    stages = [Stage("a", _backend("a", Status.NO_SOLUTION, None, None, calls), share=0.5),
              Stage("b", _backend("b", Status.ERROR, None, None, calls)),
              Stage("c", _backend("c", Status.FEASIBLE, 1.0, None, calls))]
    out = fallback_chain(0, stages, time_limit_s=2.0, seed=0)
    assert [c[0] for c in calls] == ["a", "b", "c"] and calls[0][1] == pytest.approx(1.0)
    assert out.backend == "c" and out.stats["fallbacks"] == 2.0
    assert "a failed (a says hi)" in out.message and out.message.endswith("c answered")


def test_fallback_chain_skips_unsupported_and_reports_when_nothing_answers() -> None:
    """An unsupported stage is skipped with its reason; with no answer the last failure comes
    back; a custom ``accept`` decides what counts as an answer."""
    calls: Calls = []
    stages = [Stage("a", _backend("a", Status.INFEASIBLE, None, None, calls)),
              Stage("b", _backend("b", Status.FEASIBLE, 1.0, None, calls),
                    supports=lambda problem: "not for this one")]
    out = fallback_chain(0, stages, time_limit_s=1.0, seed=0)
    assert out.status is Status.INFEASIBLE and "b skipped (not for this one)" in out.message
    assert [c[0] for c in calls] == ["a"]
    calls.clear()
    done = fallback_chain(0, stages, time_limit_s=1.0, seed=0,
                          accept=lambda r: r.status is not Status.ERROR)
    assert done.status is Status.INFEASIBLE and done.stats["fallbacks"] == 0.0


def test_fallback_chain_needs_a_stage() -> None:
    """An empty chain is a programming error."""
    with pytest.raises(ValueError, match="at least one"):
        fallback_chain(0, [], time_limit_s=1.0, seed=0)


@pytest.mark.parametrize("bad", [-1, 2**31, 3_000_000_000, 1.5, True, "3"])
def test_seeds_every_backend_can_take(bad: object) -> None:
    """Seeds outside [0, 2^31 − 1] (what CP-SAT and SCIP take) are refused, naming the seed."""
    from searchtrack.core import MAX_SEED, InvalidInputError, check_seed

    assert check_seed(0) == 0 and check_seed(MAX_SEED) == MAX_SEED
    with pytest.raises(InvalidInputError, match=r"seed=.*\[0, 2147483647\]"):
        check_seed(bad)


def test_registry_lookup_and_errors() -> None:
    """Backends are found by name; unknown names list the valid ones; duplicates are refused."""
    reg: Registry[int, int] = Registry("toy")

    def solve(problem: int, /, *, time_limit_s: float, seed: int) -> Result[int]:
        return Result(Status.OPTIMAL, float(problem), float(problem), 0.0, "double", plan=problem)

    reg.register(Backend("double", solve, True, "returns the input"))
    assert reg.get("double").solve(3, time_limit_s=1.0, seed=0).objective == 3.0
    with pytest.raises(InvalidInputError, match=r"\['double'\]"):
        reg.get("nope")
    with pytest.raises(ValueError, match="already"):
        reg.register(Backend("double", solve, True, "again"))


def _toy_registry() -> Registry[int, int]:
    """A registry with one backend that refuses negative problems."""
    reg: Registry[int, int] = Registry("toy")

    def solve(problem: int, /, *, time_limit_s: float, seed: int) -> Result[int]:
        return Result(Status.OPTIMAL, float(problem), float(problem), 0.0, "id", plan=problem)

    reg.register(Backend("id", solve, True, "returns the input",
                         supports=lambda p: "negative" if p < 0 else None))
    reg.register(Backend("also", solve, False, "the same again"))
    return reg


def test_registry_lists_names_in_registration_order() -> None:
    """names() keeps registration order and is a copy the caller may change."""
    reg = _toy_registry()
    names = reg.names()
    names.append("x")
    assert reg.names() == ["id", "also"] and reg.problem == "toy"


def test_checked_returns_the_backend_that_can_take_the_problem() -> None:
    """checked() hands back the named backend once limit, seed and support pass."""
    reg = _toy_registry()
    assert reg.checked("id", 3, 1.0, 7) is reg.get("id")


@pytest.mark.parametrize(("name", "problem", "limit", "seed", "field", "text"), [
    ("id", 3, 0.0, 0, "time_limit_s", "positive seconds"),
    ("id", 3, 1.0, -1, "seed", "integer in"),
    ("nope", 3, 1.0, 0, "backend", "unknown toy backend"),
    ("id", -2, 1.0, 0, "backend", "negative"),
])
def test_checked_refuses_bad_requests(name: str, problem: int, limit: float, seed: int,
                                      field: str, text: str) -> None:
    """A bad time limit, seed, name, or a backend that cannot take the problem names the field."""
    with pytest.raises(InvalidInputError, match=text) as err:
        _toy_registry().checked(name, problem, limit, seed)
    assert err.value.field == field


def test_relabel_sets_runtime_message_and_adds_stats() -> None:
    """relabel keeps status, plan and backend, takes the deadline's elapsed time and the new
    message, and adds the stats to the old ones."""
    inner = Result(Status.FEASIBLE, 2.0, 3.0, 0.0, "inner", "plan", message="old",
                   stats={"a": 1.0, "b": 2.0})
    deadline = Deadline(10.0, started=time.perf_counter() - 3.0)
    out = relabel(inner, deadline, "new", {"b": 5.0, "c": 3.0})
    assert (out.status, out.plan, out.backend, out.message) == (Status.FEASIBLE, "plan", "inner",
                                                                 "new")
    assert out.stats == {"a": 1.0, "b": 5.0, "c": 3.0} and inner.stats == {"a": 1.0, "b": 2.0}
    assert 3.0 <= out.runtime_s <= deadline.elapsed()


def test_the_validator_turns_a_rejected_answer_into_an_error() -> None:
    """solve() passes every answer with a plan through the family's validator: a plan it
    rejects comes back as ERROR with no plan, objective or bound, naming what it found."""
    reg: Registry[int, int] = Registry(
        "toy", validator=lambda p, r, seed: [] if r.plan == p else [f"plan {r.plan} is not {p}"])

    def honest(problem: int, /, *, time_limit_s: float, seed: int) -> Result[int]:
        return Result(Status.OPTIMAL, float(problem), float(problem), 0.0, "honest", problem)

    def liar(problem: int, /, *, time_limit_s: float, seed: int) -> Result[int]:
        return Result(Status.OPTIMAL, 1.0, 1.0, 0.0, "liar", problem + 1)

    reg.register(Backend("honest", honest, True, "returns the input"))
    reg.register(Backend("liar", liar, True, "returns the next integer"))
    assert reg.solve("honest", 3, time_limit_s=1.0, seed=0).status is Status.OPTIMAL
    bad = reg.solve("liar", 3, time_limit_s=1.0, seed=0)
    assert bad.status is Status.ERROR
    assert bad.plan is None and bad.objective is None and bad.bound is None
    assert "plan 4 is not 3" in bad.message
