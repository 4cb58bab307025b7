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

Run: ``.venv/bin/python benchmarks/radio_planning.py [--reps 5]`` (serial: one BLAS thread).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.tables import table
from searchtrack.estimate.radio.particles import LabelledParticles
from searchtrack.models.radio import UavModel
from searchtrack.models.radio.scenario import RadioScenario
from searchtrack.plan.radio import RadioPlanProblem, RadioPlanSettings, solve

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
    args = parser.parse_args()
    with threadpool_limits(limits=1):
        solve(problem(4, 50, "renyi"), backend="exhaustive")  # compile the kernels
        part1(args.reps)
        part2(args.reps)


if __name__ == "__main__":
    main()
