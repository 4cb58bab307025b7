"""Radio-tag path planning (Nguyen et al., §III-D, eq. 45): time of one planning call.

Part 1: the exhaustive planner (H = 3; N_θ = 8 gives 8 + 64 + 512 = 584 tree nodes) for
``plan_particles`` per label ∈ {250, 1000, 2000, 5000} and N_θ ∈ {4, 6, 8}, Rényi (α = 0.5) and
Cauchy–Schwarz (K = 1) rewards, r_min = 50 m and P_vmin = 0.9. The belief: the paper's four
tags (§IV-A) as 10,000 particles per label around their start positions (σ = 60 m, existences
0.95, 0.9, 0.6, 0.3), the UAV at (600, 500) heading π/4. A call is everything ``solve`` does:
drawing and predicting the look-ahead cloud (15 s), the likelihood table, the search.
``nodes`` counts the children expanded (subtrees that cannot beat a feasible incumbent are
dropped), ``ms`` the median (and max) wall time over ``--reps`` calls with seeds 0, 1, ...;
``feasible`` how many calls found a plan meeting the constraint. Target: ≤ 1 s per call at the
default settings (1000 particles per label, N_θ = 8).

Part 2: every backend at the default settings: time, and the mean objective over the
exhaustive one on the calls where both met the constraint (``auto`` reports no node count).

Part 0 (first): the exhaustive call at the default settings on the reference scoring
(:class:`~searchtrack.plan.radio.reference.ReferenceScorer`: the NumPy propagation and the
step-by-step update and reward) and on the fused one, back to back, seed by seed; ``same``
counts the calls whose plans (headings) agree and ``|Δobj|`` is the largest objective difference.

Run: ``.venv/bin/python benchmarks/radio_planning.py [--reps 5] [--compare-only]`` (serial:
one BLAS thread).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.tables import table
from searchtrack.estimate.radio.particles import LabelledParticles
from searchtrack.models.radio import UavModel
from searchtrack.models.radio.scenario import RadioScenario
from searchtrack.plan.radio import RadioPlanProblem, RadioPlanSettings, backends, solve
from searchtrack.plan.radio.reference import ReferenceScorer
from searchtrack.plan.radio.tree import Scorer

POSE = np.array([600.0, 500.0, np.pi / 4])
EXISTENCE = (0.95, 0.9, 0.6, 0.3)


def belief(scenario: RadioScenario, n: int, rng: np.random.Generator) -> LabelledParticles:
    """``n`` particles per label around the paper's tags' start states."""
    labels = scenario.signal.n_labels
    x = np.zeros((labels, n, 4))
    tau = np.zeros((labels, n))
    for tag in scenario.tags:
        start = np.asarray(tag.initial_state)
        x[tag.label] = start + rng.standard_normal((n, 4)) * np.array([60.0, 1.0, 60.0, 1.0])
        tau[tag.label] = np.mod(tag.tau_s + 0.003 * rng.standard_normal(n), 1.0)
    mode = rng.integers(0, 2, (labels, n)).astype(np.int8)
    return LabelledParticles(x, mode, tau, np.full((labels, n), 1.0 / n),
                             np.array(EXISTENCE[:labels]))


def problem(n_headings: int, particles: int, reward: str) -> RadioPlanProblem:
    """The benchmark problem for one cell of the table."""
    sc = RadioScenario(uav=UavModel(n_headings=n_headings))
    settings = RadioPlanSettings(reward=reward, plan_particles=particles)
    return RadioPlanProblem(belief(sc, 10_000, np.random.default_rng(1)), POSE, sc, settings)


def calls(p: RadioPlanProblem, backend: str, reps: int) -> tuple[list[float], list[float], int,
                                                                   int]:
    """Wall times (ms), objectives, feasible count and nodes of ``reps`` calls."""
    ms, objective, feasible, nodes = [], [], 0, 0
    for seed in range(reps):
        start = time.perf_counter()
        res = solve(p, backend=backend, time_limit_s=60.0, seed=seed)
        ms.append(1e3 * (time.perf_counter() - start))
        assert res.plan is not None, res.message
        objective.append(res.objective if res.objective is not None else float("nan"))
        feasible += res.plan.feasible
        nodes = int(res.stats.get("nodes", -1))
    return ms, objective, feasible, nodes


@contextmanager
def scoring(scorer: type[Scorer]) -> Iterator[None]:
    """The backends build ``scorer`` for their calls while the context lasts."""
    kept = backends.Scorer
    backends.Scorer = scorer  # type: ignore[misc]
    try:
        yield
    finally:
        backends.Scorer = kept  # type: ignore[misc]


def part0(reps: int) -> None:
    """Reference against fused scoring, exhaustive at the default settings."""
    rows = []
    for reward in ("renyi", "cs"):
        p = problem(8, 1000, reward)
        times: dict[str, list[float]] = {"reference": [], "fused": []}
        same, gap = 0, 0.0
        for seed in range(reps):
            plans = []
            for name, scorer in (("reference", ReferenceScorer), ("fused", Scorer)):
                with scoring(scorer):
                    start = time.perf_counter()
                    res = solve(p, backend="exhaustive", time_limit_s=60.0, seed=seed)
                    times[name].append(1e3 * (time.perf_counter() - start))
                assert res.plan is not None, res.message
                plans.append(res)
            same += bool(np.array_equal(plans[0].plan.headings, plans[1].plan.headings))
            gap = max(gap, abs((plans[0].objective or 0.0) - (plans[1].objective or 0.0)))
        for name, ms in times.items():
            rows.append([reward, name, f"{statistics.median(ms):.1f} ({max(ms):.1f})",
                         f"{same}/{reps}", f"{gap:.1e}"])
    print(f"\nexhaustive, N_θ = 8, 1000 particles/label, H = 3: reference and fused scoring "
          f"(median (max) of {reps})")
    table(["reward", "scoring", "ms", "same", "|Δobj|"], rows)


def part1(reps: int) -> None:
    """Exhaustive planning time against particles per label and N_θ, both rewards."""
    rows = []
    for reward in ("renyi", "cs"):
        for n_headings in (4, 6, 8):
            for particles in (250, 1000, 2000, 5000):
                p = problem(n_headings, particles, reward)
                ms, _, feasible, nodes = calls(p, "exhaustive", reps)
                rows.append([reward, str(n_headings), str(particles), str(nodes),
                             f"{statistics.median(ms):.0f} ({max(ms):.0f})",
                             f"{feasible}/{reps}"])
    print(f"\nexhaustive, H = 3, one call (median (max) of {reps})")
    table(["reward", "N_θ", "particles/label", "nodes", "ms", "feasible"], rows)


def part2(reps: int) -> None:
    """Every backend at the default settings."""
    rows = []
    for reward in ("renyi", "cs"):
        p = problem(8, 1000, reward)
        _, reference, _, _ = calls(p, "exhaustive", reps)
        for backend in ("exhaustive", "auto", "beam", "greedy", "straight"):
            ms, objective, feasible, nodes = calls(p, backend, reps)
            ratio = [o / r for o, r in zip(objective, reference, strict=True)
                     if np.isfinite(o) and np.isfinite(r) and r > 0]
            rows.append([reward, backend, str(nodes) if nodes >= 0 else "-",
                         f"{statistics.median(ms):.0f} ({max(ms):.0f})",
                         f"{np.mean(ratio):.3f}" if ratio else "-", f"{feasible}/{reps}"])
    print(f"\nbackends, N_θ = 8, 1000 particles/label, H = 3 (median (max) of {reps})")
    table(["reward", "backend", "nodes", "ms", "obj/exh", "feasible"], rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else "")
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--compare-only", action="store_true",
                        help="only part 0: reference against fused scoring at the defaults")
    args = parser.parse_args()
    with threadpool_limits(limits=1):
        for scorer in (ReferenceScorer, Scorer):  # compile the kernels
            with scoring(scorer):
                solve(problem(4, 50, "renyi"), backend="exhaustive")
        part0(args.reps)
        if not args.compare_only:
            part1(args.reps)
            part2(args.reps)


if __name__ == "__main__":
    main()
