"""``searchtrack plan assign`` against a brute force written here, on many small random problems:
both objectives (END and binary MI), with and without the separation constraint, every backend
that takes the problem. The brute force enumerates the joint actions; MI is evaluated by
enumerating the Poisson target counts of every particle (no series, no closed form), so nearly
invisible particles (``p_d`` down to 1e-12) are as exact as the rest."""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.stats import poisson

from searchtrack.plan.assign import BACKENDS
from tests.sim.jobs.helpers import plan_cli

ASSIGN_TOL = 1e-9
#: Poisson counts enumerated per particle (weights ≤ 1: tail mass below 1e-19).
N_MAX = 20


def pd_matrix(poses: np.ndarray, particles: np.ndarray, sensor: dict[str, float]) -> np.ndarray:
    """``(K, N)`` Gaussian field of view, written out: ``p0 exp(−½ Σ (Δ / F)²)``."""
    out = np.zeros((poses.shape[0], particles.shape[0]))
    for k, q in enumerate(poses):
        for n, x in enumerate(particles):
            x3 = [x[0], x[1], x[2] if len(x) > 2 else 0.0]
            d2 = (((q[0] - x3[0]) / sensor["scale_xy_m"]) ** 2
                  + ((q[1] - x3[1]) / sensor["scale_xy_m"]) ** 2
                  + ((q[2] - x3[2]) / sensor["scale_z_m"]) ** 2)
            out[k, n] = sensor["peak_pd"] * math.exp(-0.5 * d2)
    return out


def end_value(pd: np.ndarray, weights: np.ndarray) -> float:
    """Expected number of detected targets: ``Σ_n w_n (1 − Π_k (1 − p_kn))``."""
    return sum(float(w) * (1.0 - float(np.prod(1.0 - pd[:, n]))) for n, w in enumerate(weights))


def mi_value(pd: np.ndarray, weights: np.ndarray) -> float:
    """``I[X; Y]`` of the binary detections by enumerating the target counts of each particle."""
    m, n = pd.shape
    log_miss = np.log1p(-np.minimum(pd, 1.0 - 1e-300))  # log(1 − p), exact for tiny p
    counts = np.array(list(itertools.product(range(N_MAX + 1), repeat=n)), dtype=np.float64)
    prob = np.prod([poisson.pmf(counts[:, i], w) for i, w in enumerate(weights)], axis=0)
    log_pi = counts @ log_miss.T  # (C, M): log P(y_j = 0 | counts)
    pi = np.exp(log_pi)
    one_minus = -np.expm1(log_pi)
    joint = np.array([prob @ np.prod(np.where([(y >> j) & 1 for j in range(m)], one_minus, pi),
                                     axis=1) for y in range(1 << m)])
    with np.errstate(divide="ignore", invalid="ignore"):
        h = -log_pi * pi - np.where(one_minus > 0.0, one_minus * np.log(one_minus), 0.0)
    h_cond = float(prob @ np.sum(h, axis=1))
    nz = joint[joint > 0.0]
    return float(-np.sum(nz * np.log(nz))) - h_cond


def random_problem(rng: np.random.Generator, objective: str) -> dict[str, Any]:
    """2–3 UAVs, 2–3 actions of 1–2 poses, 1–3 particles (MI) or up to 12 (END); actions drawn
    near and far from the particles so detection probabilities span 1e-12 … 0.9."""
    robots = int(rng.integers(2, 4))
    steps = int(rng.integers(1, 3))
    n = int(rng.integers(1, 4)) if objective == "mi" else int(rng.integers(1, 13))
    if objective == "mi" and robots * steps > 4:
        steps = 1
    particles = np.round(rng.uniform(0, 100, size=(n, 2)), 1)
    actions = []
    for _ in range(robots):
        acts = []
        for _ in range(int(rng.integers(2, 4))):
            centre = rng.uniform(-60, 160, size=2)
            poses = [[round(float(centre[0] + 10 * t), 1), round(float(centre[1]), 1),
                      round(float(rng.uniform(20, 40)), 1)] for t in range(steps)]
            acts.append(poses)
        actions.append(acts)
    return {
        "uavs": [a[0][0] for a in actions],
        "actions": actions,
        "belief": {"positions": particles.tolist(),
                   "weights": np.round(rng.uniform(0.05, 1.0, size=n), 3).tolist()},
        "sensor": {"peak_pd": round(float(rng.uniform(0.5, 0.95)), 2),
                   "scale_xy_m": round(float(rng.uniform(6, 25)), 1),
                   "scale_z_m": round(float(rng.uniform(20, 40)), 1)},
        "objective": objective,
        "min_separation_m": float(rng.choice([0.0, 0.0, 30.0])),
    }


def score(doc: dict[str, Any], choice: tuple[int, ...]) -> float | None:
    """The objective of one joint action, or ``None`` if two UAVs come too close."""
    poses = [np.array(doc["actions"][r][a], dtype=float) for r, a in enumerate(choice)]
    sep = float(doc["min_separation_m"])
    if sep > 0.0:
        for r, s in itertools.combinations(range(len(poses)), 2):
            if np.min(np.linalg.norm(poses[r] - poses[s], axis=1)) < sep:
                return None
    pd = pd_matrix(np.concatenate(poses), np.array(doc["belief"]["positions"], dtype=float),
                   doc["sensor"])
    weights = np.array(doc["belief"]["weights"], dtype=float)
    return end_value(pd, weights) if doc["objective"] == "end" else mi_value(pd, weights)


def brute_force(doc: dict[str, Any]) -> tuple[float | None, dict[tuple[int, ...], float]]:
    """The best objective over all joint actions (``None``: none is feasible) and every score."""
    values = {}
    for choice in itertools.product(*(range(len(a)) for a in doc["actions"])):
        v = score(doc, choice)
        if v is not None:
            values[choice] = v
    return (max(values.values()) if values else None), values


def _backends(objective: str) -> list[str]:
    names = ["auto", "greedy", "lazy_greedy", "brute_force", "exact_bnb"]
    if objective == "end":
        names += ["exact_cpsat", "exact"]
    return [b for b in names if b in BACKENDS.names()]


@pytest.mark.parametrize("objective", ["end", "mi"])
@pytest.mark.parametrize("seed", range(30))
def test_every_claim_matches_the_brute_force(tmp_path: Path, objective: str, seed: int,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """OPTIMAL objectives equal the enumerated optimum, every objective is its plan's true value,
    greedy keeps half of the optimum (without the separation constraint)."""
    rng = np.random.default_rng(1000 * seed + (objective == "mi"))
    doc = random_problem(rng, objective)
    best, values = brute_force(doc)
    for backend in _backends(objective):
        code, plan = plan_cli(tmp_path, "assign", doc, "--backend", backend,
                              "--time-limit", "20")
        capsys.readouterr()
        if best is None:
            assert code != 0, backend
            continue
        if code == 2:  # the backend cannot take this problem (said so in one line)
            continue
        assert code == 0, (backend, plan)
        choice = tuple(plan["plan"]["actions"])
        true = values[choice]
        assert plan["objective"] == pytest.approx(true, abs=ASSIGN_TOL, rel=1e-9), (backend, doc)
        if plan["status"] == "OPTIMAL":
            assert true == pytest.approx(best, abs=ASSIGN_TOL, rel=1e-9), (backend, doc)
        assert true <= best + ASSIGN_TOL
        if backend in ("greedy", "lazy_greedy") and doc["min_separation_m"] == 0.0:
            assert true >= 0.5 * best - ASSIGN_TOL


def test_the_brute_force_mi_matches_a_two_particle_hand_count() -> None:
    """One measurement, one particle of weight w and p_d = p: I = h_b(P(y = 0)) − E h_b(π) with
    π = (1 − p)^N, N ~ Poisson(w); P(y = 0) = e^{−w p}."""
    w, p = 0.7, 0.4
    p0 = math.exp(-w * p)
    h_y = -(p0 * math.log(p0) + (1 - p0) * math.log(1 - p0))
    h_cond = 0.0
    for k in range(60):
        pi = (1 - p) ** k
        if 0 < pi < 1:
            h_cond += poisson.pmf(k, w) * -(pi * math.log(pi) + (1 - pi) * math.log(1 - pi))
    assert mi_value(np.array([[p]]), np.array([w])) == pytest.approx(h_y - h_cond, abs=1e-12)
