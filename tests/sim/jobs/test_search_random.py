"""``searchtrack plan search`` against a brute force written here, on many small random problems:
every refinement (centre, MI, none), planar and 3-D lattices, horizons 1–3, and exploration grids
over boxes with non-round bounds. The brute force builds the lattice sequences, the exploration
grid (its cell counts in exact decimal arithmetic, as the format documents), the bonus and its
multilinear interpolation, and the MI (by enumerating target counts) on its own."""

from __future__ import annotations

import itertools
import math
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests.sim.jobs.helpers import plan_cli
from tests.sim.jobs.test_assign_random import mi_value, pd_matrix

TOL = 1e-9


def axis_points(lo: float, hi: float, resolution: float) -> np.ndarray:
    """Grid points of one axis: ``n = ⌈(hi − lo) / resolution⌉`` equal cells, the division done
    on the decimal numbers as written (so 89.9 − 49.9 is exactly 40)."""
    n = max(1, math.ceil((Fraction(str(hi)) - Fraction(str(lo))) / Fraction(str(resolution))))
    return np.array([lo + (hi - lo) * i / n for i in range(n + 1)])


def interpolate(axes: list[np.ndarray], values: np.ndarray, point: np.ndarray) -> float:
    """Multilinear interpolation of the grid ``values`` at ``point`` (clamped to the box)."""
    corners: list[list[tuple[int, float]]] = []
    for d, ax in enumerate(axes):
        x = min(max(float(point[d]), float(ax[0])), float(ax[-1]))
        i = min(int(np.searchsorted(ax, x, side="right")) - 1, ax.size - 2)
        t = (x - ax[i]) / (ax[i + 1] - ax[i])
        corners.append([(i, 1.0 - t), (i + 1, t)])
    total = 0.0
    for combo in itertools.product(*corners):
        weight = math.prod(w for _, w in combo)
        total += weight * float(values[tuple(i for i, _ in combo)])
    return total


def bonus_grid(doc: dict[str, Any]) -> tuple[list[np.ndarray], np.ndarray]:
    """The exploration bonus on its grid: 1 times ``1 − p_d(x, v)`` for every visited pose."""
    exploration = doc.get("exploration", {})
    resolution = exploration.get("resolution_m", 10.0)
    axes = [axis_points(lo, hi, resolution) for lo, hi in doc["bounds"]]
    mesh = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    values = np.ones(mesh.shape[0])
    for v in exploration.get("visited", []):
        values *= 1.0 - pd_matrix(np.array([v], dtype=float), mesh, doc["sensor"])[0]
    return axes, values.reshape(tuple(a.size for a in axes))


def sequences(doc: dict[str, Any]) -> list[np.ndarray]:
    """Every lattice sequence of the horizon that stays in the box."""
    s = doc["settings"]
    step, dims, horizon = s["step_m"], s["dims"], s["horizon"]
    moves = [np.eye(3)[d] * step for d in range(dims)] + [-np.eye(3)[d] * step
                                                         for d in range(dims)]
    box = np.array(doc["bounds"], dtype=float)
    out = []
    for combo in itertools.product(range(len(moves)), repeat=horizon):
        seq = np.array(doc["uav"], dtype=float) + np.cumsum([moves[i] for i in combo], axis=0)
        if np.all((seq >= box[:, 0]) & (seq <= box[:, 1])):
            out.append(seq)
    return out


def score(doc: dict[str, Any], seq: np.ndarray, grid: tuple[list[np.ndarray], np.ndarray]
          ) -> float:
    """``α E + T`` of one sequence."""
    s = doc["settings"]
    explore = sum(interpolate(grid[0], grid[1], q) for q in seq)
    refinement = s["refinement"]
    if refinement == "centre":
        centres = np.array(doc.get("centres", []), dtype=float).reshape(-1, 3)
        ref = float(np.sum(pd_matrix(seq, centres, doc["sensor"]))) if centres.size else 0.0
    elif refinement == "mi":
        positions = np.array(doc["belief"]["positions"], dtype=float)
        pd = pd_matrix(seq, positions, doc["sensor"])
        seen = 1.0 - np.prod(1.0 - pd, axis=0)
        ref = mi_value(seen[None, :], np.array(doc["belief"]["weights"], dtype=float))
    else:
        ref = 0.0
    return float(s["alpha"]) * explore + ref


def _odd(rng: np.random.Generator, lo: float, hi: float) -> float:
    """A coordinate with one decimal, often not a multiple of the resolution."""
    return round(float(rng.uniform(lo, hi)), 1)


def random_problem(rng: np.random.Generator) -> dict[str, Any]:
    """A box with one-decimal bounds of unequal sides, a few visited poses, 1–3 particles."""
    x0, y0, z0 = _odd(rng, -50, 50), _odd(rng, -50, 50), _odd(rng, 10, 20)
    res = float(rng.choice([5.0, 7.5, 10.0, 12.0]))
    wx, wy, wz = (res * int(rng.integers(2, 6)) + float(rng.choice([0.0, 0.0, 0.1, 3.3])),
                  res * int(rng.integers(1, 5)) + float(rng.choice([0.0, 0.1, 2.2])),
                  res * int(rng.integers(1, 3)) + float(rng.choice([0.0, 0.3])))
    bounds = [[x0, round(x0 + wx, 1)], [y0, round(y0 + wy, 1)], [z0, round(z0 + wz, 1)]]
    box = np.array(bounds)
    uav = [round(float(rng.uniform(lo, hi)), 1) for lo, hi in box]
    n = int(rng.integers(1, 4))
    positions = [[_odd(rng, lo, hi) for lo, hi in box[:2]] for _ in range(n)]
    visited = [[_odd(rng, lo, hi) for lo, hi in box] for _ in range(int(rng.integers(0, 4)))]
    return {
        "uav": uav, "bounds": bounds,
        "belief": {"positions": positions,
                   "weights": np.round(rng.uniform(0.1, 1.0, size=n), 3).tolist()},
        "centres": [[_odd(rng, lo, hi) for lo, hi in box] for _ in range(int(rng.integers(0, 3)))],
        "sensor": {"peak_pd": round(float(rng.uniform(0.5, 0.95)), 2),
                   "scale_xy_m": round(float(rng.uniform(5, 25)), 1),
                   "scale_z_m": round(float(rng.uniform(15, 40)), 1)},
        "exploration": {"resolution_m": res, "visited": visited},
        "settings": {"horizon": int(rng.integers(1, 4)),
                     "alpha": round(float(rng.choice([0.0, 0.5, 1.0, 3.0])), 2),
                     "refinement": str(rng.choice(["centre", "mi", "none"])),
                     "step_m": float(rng.choice([4.0, 7.0, 12.0])),
                     "dims": int(rng.choice([2, 3]))},
    }


@pytest.mark.parametrize("seed", range(60))
def test_optimal_search_step_matches_the_brute_force(tmp_path: Path, seed: int,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """The reported score is the plan's true score and, when OPTIMAL, the best over the
    lattice; with no sequence inside the box the command answers no plan."""
    doc = random_problem(np.random.default_rng(seed))
    seqs = sequences(doc)
    code, plan = plan_cli(tmp_path, "search", doc)
    capsys.readouterr()
    if not seqs:
        assert code == 1
        return
    assert code == 0
    grid = bonus_grid(doc)
    best = max(score(doc, s, grid) for s in seqs)
    chosen = np.array(plan["plan"]["sequence"], dtype=float)
    assert plan["objective"] == pytest.approx(score(doc, chosen, grid), abs=TOL, rel=TOL), doc
    assert plan["plan"]["candidates"] == len(seqs)
    if plan["status"] == "OPTIMAL":
        assert plan["objective"] == pytest.approx(best, abs=TOL, rel=TOL), doc


def test_grid_of_a_non_round_box_keeps_the_stated_resolution() -> None:
    """[49.9, 89.9] at 10 m is four cells of exactly 10 m, not five of 8 m."""
    assert np.allclose(np.diff(axis_points(49.9, 89.9, 10.0)), 10.0)
    from searchtrack.plan.search import ExplorationBonus

    bonus = ExplorationBonus(np.array([[49.9, 89.9], [-20.0, 20.0], [20.0, 40.0]]), 10.0)
    assert [a.size for a in bonus.axes] == [5, 5, 3]
