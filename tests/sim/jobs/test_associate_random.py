"""``searchtrack plan associate`` against a brute force written here, on small random problems
over non-square grids: every association backend, the EMD matrix and the gated assignment.

The reference shares nothing with the library's solvers: the road graph is built from the
documented grid (junction ``(r, c)`` at ``(c·s, r·s)`` is node ``c·rows + r``, a road of length
``s`` between neighbours), road distances come from Dijkstra (:mod:`scipy.sparse.csgraph`), each
EMD is the transportation LP solved by :func:`scipy.optimize.linprog`, and the assignment is the
best of all partial one-to-one matchings under the gate, enumerated."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.optimize import linprog
from scipy.sparse import coo_array
from scipy.sparse.csgraph import dijkstra

from searchtrack.estimate.association import BACKENDS, AssociationProblem
from searchtrack.sim.jobs import associate
from tests.sim.jobs.helpers import plan_cli

Matrix = NDArray[np.float64]
Matching = tuple[tuple[int, int], ...]

#: Non-square grids (rows, cols).
GRIDS = [(2, 3), (3, 2), (2, 4), (4, 2), (3, 4), (4, 3), (2, 5), (5, 3)]
#: PLAN.json rounds each EMD to 4 decimals (m).
JSON_ROUNDING_M = 5e-5
REL = 1e-6
#: HiGHS's feasibility tolerance (1e-7) is absolute: on unit masses it moves an EMD by up to
#: ~1e-5 m, so the LP moves MASS_SCALE units instead; masses below NEGLIGIBLE are dropped.
MASS_SCALE = 1e6
NEGLIGIBLE = 1e-14


def junction_xy(rows: int, cols: int, spacing: float) -> Matrix:
    """Row ``c·rows + r`` is junction ``(r, c)`` at ``(c·s, r·s)``."""
    xy = np.zeros((rows * cols, 2))
    for r in range(rows):
        for c in range(cols):
            xy[c * rows + r] = (c * spacing, r * spacing)
    return xy


def road_distances(rows: int, cols: int, spacing: float) -> Matrix:
    """All-pairs shortest road distances (m) on the grid, one road of length ``s`` per block."""
    a: list[int] = []
    b: list[int] = []
    for r in range(rows):
        for c in range(cols):
            if c + 1 < cols:
                a.append(c * rows + r)
                b.append((c + 1) * rows + r)
            if r + 1 < rows:
                a.append(c * rows + r)
                b.append(c * rows + r + 1)
    n = rows * cols
    graph = coo_array((np.full(len(a), float(spacing)), (a, b)), shape=(n, n)).tocsr()
    return np.asarray(dijkstra(graph, directed=False), dtype=np.float64)


def gaussian(xy: Matrix, point: list[float], sd: float) -> Matrix:
    """Weights ``∝ exp(−‖point − node‖² / 2 sd²)`` over the nodes, summing to 1."""
    d2 = np.array([(x - point[0]) ** 2 + (y - point[1]) ** 2 for x, y in xy])
    log_w = -d2 / (2.0 * sd * sd)
    w = np.exp(log_w - log_w.max())
    return np.asarray(w / w.sum(), dtype=np.float64)


def truncated(w: Matrix, mass: float) -> Matrix:
    """The documented signature: the heaviest nodes (ties: lower index first) until ``mass`` of
    the total is held, renormalised; ``mass = 1`` keeps every node of positive weight."""
    if mass >= 1.0:
        return np.asarray(w / w.sum(), dtype=np.float64)
    order = sorted(range(w.size), key=lambda i: (-w[i], i))
    kept: list[int] = []
    held = 0.0
    for i in order:
        kept.append(i)
        held += float(w[i])
        if held >= mass * float(w.sum()):
            break
    out = np.zeros_like(w)
    out[kept] = w[kept]
    return np.asarray(out / out.sum(), dtype=np.float64)


def emd(p: Matrix, q: Matrix, dist: Matrix) -> float:
    """The transportation LP ``min Σ f_ij d_ij``, marginals ``p`` and ``q``, ``f ≥ 0``.

    Masses below :data:`NEGLIGIBLE` are dropped first (the rest renormalised): they move the EMD
    by less than ``n · NEGLIGIBLE`` times the longest distance, and rows of 1e-100 upset HiGHS."""
    src = np.flatnonzero(p > NEGLIGIBLE)
    dst = np.flatnonzero(q > NEGLIGIBLE)
    p = p / p[src].sum()
    q = q / q[dst].sum()
    m, n = src.size, dst.size
    a_eq = np.zeros((m + n, m * n))
    for i in range(m):
        a_eq[i, i * n:(i + 1) * n] = 1.0
    for j in range(n):
        a_eq[m + j, j::n] = 1.0
    b_eq = MASS_SCALE * np.concatenate([p[src], q[dst]])
    res = linprog(dist[np.ix_(src, dst)].ravel(), A_eq=a_eq, b_eq=b_eq, bounds=(0, None),
                  method="highs-ds")
    assert res.status == 0, res.message
    return float(res.fun) / MASS_SCALE


def reference_costs(doc: dict[str, Any]) -> Matrix:
    """The ``(k, q)`` EMD matrix of the problem, computed from its documented definition."""
    rows, cols = doc["map"]["grid"]
    s = float(doc["map"]["spacing_m"])
    xy = junction_xy(rows, cols, s)
    dist = road_distances(rows, cols, s)
    mass = float(doc.get("support_mass", 0.999))
    trackers = []
    for t in doc["trackers"]:
        if "nodes" in t:
            p = np.zeros(rows * cols)
            for key, m in t["nodes"].items():
                p[int(key)] += float(m)
            trackers.append(p / p.sum())
        else:
            trackers.append(gaussian(xy, t["peak"], float(t.get("sd_m", 20.0))))
    noise = float(doc.get("noise_sd_m", 10.0))
    dens = [gaussian(xy, det, noise) for det in doc["detections"]]
    return np.array([[emd(truncated(p, mass), truncated(u, mass), dist) for u in dens]
                     for p in trackers])


def matchings(costs: Matrix, gate: float) -> dict[Matching, float]:
    """Every one-to-one set of pairs (sorted) with EMD below the gate and its saving
    ``Σ (gate − EMD)``."""
    k, q = costs.shape
    out: dict[Matching, float] = {}
    for choice in itertools.product([None, *range(k)], repeat=q):
        used = [i for i in choice if i is not None]
        if len(set(used)) != len(used):
            continue
        pairs = tuple(sorted((i, j) for j, i in enumerate(choice) if i is not None))
        if all(costs[i, j] < gate for i, j in pairs):
            out[pairs] = sum(gate - costs[i, j] for i, j in pairs)
    return out


def greedy(costs: Matrix, gate: float) -> set[tuple[int, int]]:
    """Algorithm 1 spelled out: the cheapest remaining pair under the gate, again and again."""
    free_t, free_d = set(range(costs.shape[0])), set(range(costs.shape[1]))
    pairs: set[tuple[int, int]] = set()
    while True:
        options = [(costs[i, j], i, j) for i in free_t for j in free_d if costs[i, j] < gate]
        if not options:
            return pairs
        _, i, j = min(options)
        pairs.add((i, j))
        free_t.discard(i)
        free_d.discard(j)


def on_road(rng: np.random.Generator, rows: int, cols: int, s: float, jitter: float) -> list[float]:
    """A random point of a random block, moved by up to ``jitter`` m off the road."""
    r, c = int(rng.integers(rows)), int(rng.integers(cols))
    along = float(rng.uniform(0.0, s))
    horizontal = bool(rng.integers(2)) if rows > 1 and cols > 1 else cols > 1
    if horizontal and c + 1 < cols:
        x, y = c * s + along, r * s
    elif r + 1 < rows:
        x, y = c * s, r * s + along
    else:
        x, y = c * s, r * s
    return [round(x + float(rng.uniform(-jitter, jitter)), 3),
            round(y + float(rng.uniform(-jitter, jitter)), 3)]


def random_problem(seed: int, support_mass: float | None) -> dict[str, Any]:
    """A grid with rows ≠ cols, 1–3 trackers (node masses or a peak), 1–3 detections."""
    rng = np.random.default_rng(7919 * seed + 11)
    rows, cols = GRIDS[int(rng.integers(len(GRIDS)))]
    s = int(rng.integers(30, 101))
    n = rows * cols
    trackers: list[dict[str, Any]] = []
    for _ in range(int(rng.integers(1, 4))):
        if rng.random() < 0.5:
            nodes = rng.choice(n, size=int(rng.integers(1, 4)), replace=False)
            trackers.append({"nodes": {str(int(v)): round(float(rng.uniform(0.05, 1.0)), 3)
                                       for v in nodes}})
        else:
            trackers.append({"peak": on_road(rng, rows, cols, s, 5.0),
                             "sd_m": round(float(rng.uniform(5.0, 60.0)), 1)})
    detections = [on_road(rng, rows, cols, s, 10.0) for _ in range(int(rng.integers(1, 4)))]
    return {"map": {"grid": [rows, cols], "spacing_m": s}, "trackers": trackers,
            "detections": detections, "noise_sd_m": round(float(rng.uniform(3.0, 40.0)), 1),
            "gate_m": float(round(float(rng.uniform(0.4, 3.0)) * s)),
            "support_mass": 1.0 if support_mass is None else support_mass}


def run_cli(tmp_path: Path, doc: dict[str, Any], backend: str) -> tuple[int, dict[str, Any]]:
    """``searchtrack plan associate`` on ``doc``: the exit status and PLAN.json."""
    return plan_cli(tmp_path, "associate", doc, "--backend", backend, "--time-limit", "10")


def close(got: float, want: float, abs_tol: float = 1e-6) -> bool:
    """``got`` equals ``want`` within 1e-6 relative or ``abs_tol``."""
    return math.isclose(got, want, rel_tol=REL, abs_tol=abs_tol)


def check_plan(doc: dict[str, Any], record: dict[str, Any], ref: Matrix,
               saving: dict[Matching, float]) -> None:
    """Every claim of one PLAN.json against the reference EMD matrix and matchings."""
    gate = float(doc["gate_m"])
    best = max(saving.values())
    plan = record["plan"]
    k, q = ref.shape
    tag = json.dumps(doc)
    assert plan["gate_m"] == gate
    assert len(plan["costs"]) == k and all(len(row) == q for row in plan["costs"]), tag
    for i, j in itertools.product(range(k), range(q)):
        got = plan["costs"][i][j]
        if got is None:
            assert ref[i, j] >= gate * (1.0 - 1e-9), (i, j, ref[i, j], tag)
        else:
            assert close(got, ref[i, j], JSON_ROUNDING_M), (i, j, got, ref[i, j], tag)
    pairs = tuple(sorted((p["tracker"], p["detection"]) for p in plan["pairs"]))
    assert len({i for i, _ in pairs}) == len(pairs) == len({j for _, j in pairs}), tag
    for p in plan["pairs"]:
        assert close(p["emd_m"], ref[p["tracker"], p["detection"]], JSON_ROUNDING_M), tag
    assert plan["assignment"] == [dict((j, i) for i, j in pairs).get(j) for j in range(q)]
    assert plan["new"] == [j for j in range(q) if plan["assignment"][j] is None]
    assert pairs in saving, f"{record['backend']} pairs {pairs} not all under the gate: {tag}"
    total = sum(ref[i, j] for i, j in pairs)
    assert close(plan["total_emd_m"], total, JSON_ROUNDING_M * (1 + len(pairs))), tag
    assert close(record["objective"], saving[pairs]), (record["objective"], saving[pairs], tag)
    assert record["objective"] <= best + 1e-6 * max(1.0, best), tag
    if record["status"] == "OPTIMAL":
        assert close(record["objective"], best), (
            f"{record['backend']} claims OPTIMAL {record['objective']} but the best matching "
            f"saves {best} ({max(saving, key=lambda m: saving[m])}): {tag}")


CASES = [(seed, None) for seed in range(40)] + [(100 + seed, 0.9) for seed in range(6)] + \
    [(200 + seed, 0.97) for seed in range(6)]


@pytest.mark.parametrize(("seed", "support_mass"), CASES)
def test_every_backend_matches_the_brute_force(tmp_path: Path, seed: int,
                                               support_mass: float | None,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    """The EMD matrix equals the LP reference (unrounded to 1e-6 relative, PLAN.json to its 4
    decimals), every assignment is gated and one-to-one and saves what it claims, OPTIMAL is the
    enumerated best, greedy is Algorithm 1 (when no two gated EMDs tie)."""
    doc = random_problem(seed, support_mass)
    ref = reference_costs(doc)
    gate = float(doc["gate_m"])
    saving = matchings(ref, gate)
    path = tmp_path / "problem.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    job = associate.read_problem(path)
    exact = associate.solve(job, backend="optimal", time_limit_s=10.0, seed=0)
    assert exact.plan is not None
    costs = exact.plan.costs
    for i, j in itertools.product(*map(range, ref.shape)):
        if math.isinf(costs[i, j]):
            assert ref[i, j] >= gate * (1.0 - 1e-9), (i, j, ref[i, j], doc)
        else:
            assert close(float(costs[i, j]), float(ref[i, j])), (i, j, costs[i, j], ref[i, j], doc)
    statuses = {}
    for backend in associate.backends():
        code, record = run_cli(tmp_path, doc, backend)
        capsys.readouterr()
        if code == 2 and BACKENDS.get(backend).supports(AssociationProblem(costs, gate)):
            continue
        assert code == 0 and record["plan"] is not None, (backend, record)
        check_plan(doc, record, ref, saving)
        statuses[backend] = record["status"]
        gated = sorted(ref[ref < gate].ravel())
        if backend == "greedy" and all(b - a > 1e-6 for a, b in itertools.pairwise(gated)):
            got = {(p["tracker"], p["detection"]) for p in record["plan"]["pairs"]}
            assert got == greedy(ref, gate), (got, greedy(ref, gate), doc)
    assert statuses.get("optimal") == "OPTIMAL", statuses


def test_the_documented_node_numbering_on_a_2x3_grid(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """Node 1 of a 2 × 3 grid is junction (r=1, c=0) at (0, 50): EMD 0 to a detection there and
    100 m of road to one at (50, 0)."""
    doc = {"map": {"grid": [2, 3], "spacing_m": 50}, "trackers": [{"nodes": {"1": 1}}],
           "detections": [[0, 50], [50, 0]], "noise_sd_m": 0.5, "gate_m": 300,
           "support_mass": 1.0}
    code, record = run_cli(tmp_path, doc, "optimal")
    capsys.readouterr()
    assert code == 0
    assert record["plan"]["costs"][0] == [pytest.approx(0.0, abs=1e-9),
                                          pytest.approx(100.0, rel=1e-9)]
    assert record["plan"]["assignment"] == [0, None]


@pytest.mark.parametrize(("rows", "cols"), [(2, 3), (3, 2), (2, 5), (4, 3), (3, 5)])
def test_every_junction_is_node_c_rows_plus_r(tmp_path: Path, rows: int, cols: int,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    """One tracker on node ``c·rows + r`` and one detection at ``(c·s, r·s)`` per junction: the
    EMD matrix is the Manhattan distance between the junctions (0 on the diagonal) and each
    tracker takes its own detection."""
    s = int(np.random.default_rng(rows * 10 + cols).integers(30, 101))
    cells = [(r, c) for c in range(cols) for r in range(rows)]
    doc = {"map": {"grid": [rows, cols], "spacing_m": s},
           "trackers": [{"nodes": {str(c * rows + r): 1}} for r, c in cells],
           "detections": [[c * s, r * s] for r, c in cells],
           "noise_sd_m": 0.5, "gate_m": s * (rows + cols), "support_mass": 1.0}
    code, record = run_cli(tmp_path, doc, "optimal")
    capsys.readouterr()
    assert code == 0
    want = [[s * (abs(r - r2) + abs(c - c2)) for r2, c2 in cells] for r, c in cells]
    assert np.allclose(np.array(record["plan"]["costs"], dtype=float), want, rtol=0, atol=1e-6)
    assert record["plan"]["assignment"] == list(range(len(cells)))
