"""The ``search`` plan family: one receding-horizon step of paper 004's search (exploration +
refinement, eq. 8) from a particle belief, solved by a backend of
:data:`searchtrack.plan.search.BACKENDS`.

PROBLEM.json::

    {"uav": [x, y, z],
     "bounds": [[x0, x1], [y0, y1], [z0, z1]],
     "belief": {"positions": [[x, y, z], ...], "weights": [w, ...]},
     "centres": [[x, y, z], ...],
     "sensor": {"peak_pd": 0.98, "scale_xy_m": 25.0, "scale_z_m": 25.0},
     "exploration": {"resolution_m": 10.0, "visited": [[x, y, z], ...]},
     "settings": {"horizon": 2, "alpha": 1.0, "refinement": "centre", "step_m": 12.0,
                  "dims": 3, "lawnmower_spacing_m": 48.0}}

``uav`` is the searching UAV's current position (m); ``bounds`` the search box (lo ≤ hi on each
axis, lo < hi for the exploration grid): move sequences leaving it are excluded. ``belief`` is
the particle belief (``N ≥ 1`` positions ``[x, y, z]`` or ground ``[x, y]``, non-negative
weights), read by the ``"mi"`` refinement. ``centres`` (optional, default none) are the estimated
target centres read by the ``"centre"`` refinement (004 eq. 11). ``sensor`` is a
:class:`~searchtrack.models.footprint.GaussianFieldOfView` (the field of view: peak detection
probability in ``(0, 1]``, horizontal and vertical scales in m). ``exploration`` (optional) is
the state of the exploration bonus ``ι`` (eq. 9): a grid over the box at ``resolution_m``
(default 10) starting at 1 and multiplied by ``1 − π`` at each pose of ``visited`` (default none,
the poses flown so far). ``settings`` (optional, each key too) map to
:class:`~searchtrack.plan.search.SearchSettings`: ``horizon`` ``τ`` in [1, 5] (default 1),
``alpha`` ``α ≥ 0`` (default 1), ``refinement`` ``"centre"`` (default,
:class:`~searchtrack.plan.search.CentreProbability`), ``"mi"``
(:class:`~searchtrack.plan.search.EmptyHorizonMI`) or ``"none"``, ``step_m`` (lattice move,
default 12), ``dims`` 3 (six moves, default) or 2 (planar moves), ``lawnmower_spacing_m``
(default 48).

Backends: ``receding`` (every lattice sequence of the horizon, OPTIMAL over the lattice),
``lawnmower`` (the coverage pattern, FEASIBLE) and ``auto`` (= ``receding``). The objective is the
score ``α E + T`` (maximised). The ``"plan"`` object of PLAN.json: ``{"refinement": "centre",
"waypoint": [x, y, z], "sequence": [[x, y, z], ...], "score": {"exploration": E, "refinement":
T, "alpha": α, "total": α E + T}, "candidates": S}`` — the next position to fly, the ``τ``
positions planned, the score split and how many sequences were compared.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result
from searchtrack.plan.search import (
    BACKENDS as BACKENDS,
)
from searchtrack.plan.search import (
    CentreProbability,
    EmptyHorizonMI,
    ExplorationBonus,
    NoRefinement,
    Refinement,
    SearchPlan,
    SearchProblem,
    SearchSettings,
)
from searchtrack.plan.search import solve as solve_search
from searchtrack.sim.export.plans import VehiclePaths
from searchtrack.sim.jobs.assign import (
    ProblemFields,
    load_problem,
    read_belief,
    read_sensor,
)
from searchtrack.sim.kernels import kernels_of

DESCRIPTION = "one exploration + refinement receding-horizon search step (paper 004)"
KERNELS = kernels_of(BACKENDS)

#: Largest exploration grid (points) a problem may ask for.
MAX_GRID_POINTS = 2_000_000
#: Largest grid points × visited poses (the cost of rebuilding ``ι``).
MAX_BONUS_WORK = 50_000_000

REFINEMENTS: dict[str, type[Refinement]] = {
    "centre": CentreProbability, "mi": EmptyHorizonMI, "none": NoRefinement}
_TOP_KEYS = ("uav", "bounds", "belief", "centres", "sensor", "exploration", "settings")
_EXPLORATION_KEYS = ("resolution_m", "visited")
_SETTINGS_KEYS = ("horizon", "alpha", "refinement", "step_m", "dims", "lawnmower_spacing_m")


@dataclass(frozen=True)
class SearchJob:
    """A validated PROBLEM.json: the search problem, the poses flown and where it came from."""

    path: Path
    problem: SearchProblem
    visited: np.ndarray[Any, Any]

    @property
    def name(self) -> str:
        """The file's stem."""
        return self.path.stem


def _bounds(f: ProblemFields, raw: Any) -> np.ndarray[Any, Any]:
    rows = f.items(raw, "bounds", "[lo, hi] per axis")
    if len(rows) != 3:
        raise f.fail("bounds", f"needs 3 rows [lo, hi] (x, y, z), got {len(rows)}")
    out = np.empty((3, 2))
    for i, row in enumerate(rows):
        if not isinstance(row, list) or len(row) != 2:
            raise f.fail(f"bounds[{i}]", f"must be [lo, hi], got {row!r}")
        out[i] = [f.number(v, f"bounds[{i}][{j}]") for j, v in enumerate(row)]
        if out[i, 1] <= out[i, 0]:
            raise f.fail(f"bounds[{i}]", f"needs lo < hi, got {row!r}")
    return out


def _inside(f: ProblemFields, point: np.ndarray[Any, Any], box: np.ndarray[Any, Any],
            key: str) -> None:
    if np.any(point < box[:, 0]) or np.any(point > box[:, 1]):
        raise f.fail(key, f"{point.tolist()} lies outside bounds {box.tolist()}")


def _settings(f: ProblemFields, raw: Any) -> SearchSettings:
    spec = f.obj(raw, "settings", _SETTINGS_KEYS)
    horizon = spec.get("horizon", 1)
    if isinstance(horizon, bool) or not isinstance(horizon, int) or not 1 <= horizon <= 5:
        raise f.fail("settings.horizon", f"must be an integer in [1, 5], got {horizon!r}")
    dims = spec.get("dims", 3)
    if isinstance(dims, bool) or dims not in (2, 3):
        raise f.fail("settings.dims", f"must be 2 or 3, got {dims!r}")
    name = spec.get("refinement", "centre")
    if not isinstance(name, str) or name not in REFINEMENTS:
        raise f.fail("settings.refinement", f"must be one of {list(REFINEMENTS)}, got {name!r}")
    alpha = f.number(spec.get("alpha", 1.0), "settings.alpha", low=0.0, high=1e6)
    step = f.number(spec.get("step_m", 12.0), "settings.step_m", low=0.0, low_open=True)
    spacing = f.number(spec.get("lawnmower_spacing_m", 48.0), "settings.lawnmower_spacing_m",
                       low=0.0, low_open=True)
    return SearchSettings(step_m=step, horizon=horizon, alpha=alpha,
                          refinement=REFINEMENTS[name](), dims=int(dims),
                          lawnmower_spacing_m=spacing)


def _exploration(f: ProblemFields, raw: Any, box: np.ndarray[Any, Any]
                 ) -> tuple[float, np.ndarray[Any, Any]]:
    spec = f.obj(raw, "exploration", _EXPLORATION_KEYS)
    resolution = f.number(spec.get("resolution_m", 10.0), "exploration.resolution_m", low=0.0,
                          low_open=True)
    points = float(np.prod(np.floor((box[:, 1] - box[:, 0]) / resolution) + 2))
    if points > MAX_GRID_POINTS:
        raise f.fail("exploration.resolution_m", f"the grid would hold about {points:.0f} points "
                     f"(limit {MAX_GRID_POINTS}); use a coarser resolution")
    raw_visited = spec.get("visited", [])
    if not isinstance(raw_visited, list):
        raise f.fail("exploration.visited", "must be a list of positions [x, y, z]")
    visited = (f.points(raw_visited, "exploration.visited", (3,)) if raw_visited
               else np.empty((0, 3)))
    if points * visited.shape[0] > MAX_BONUS_WORK:
        raise f.fail("exploration.visited", f"grid points × visited poses exceeds "
                     f"{MAX_BONUS_WORK}; use a coarser resolution or fewer poses")
    return resolution, visited


def read_problem(path: str | Path) -> SearchJob:
    """Read and validate a search PROBLEM.json (format in the module docstring).

    Raises
    ------
    ParseError
        Naming the file and the JSON key at fault (``settings.horizon``, ``uav[2]``).
    """
    f, top = load_problem(path, _TOP_KEYS)
    uav_raw = f.get(top, "uav")
    if not isinstance(uav_raw, list) or len(uav_raw) != 3:
        raise f.fail("uav", f"must be a position [x, y, z], got {uav_raw!r}")
    uav = np.array([f.number(v, f"uav[{j}]") for j, v in enumerate(uav_raw)])
    box = _bounds(f, f.get(top, "bounds"))
    _inside(f, uav, box, "uav")
    belief = read_belief(f, f.get(top, "belief"))
    raw_centres = top.get("centres", [])
    if not isinstance(raw_centres, list):
        raise f.fail("centres", "must be a list of positions [x, y, z]")
    centres = (f.points(raw_centres, "centres", (3,)) if raw_centres else np.empty((0, 3)))
    sensor = read_sensor(f, f.get(top, "sensor"))
    resolution, visited = _exploration(f, top.get("exploration", {}), box)
    settings = _settings(f, top.get("settings", {}))
    try:
        bonus = ExplorationBonus(box, resolution)
        for pose in visited:
            bonus = bonus.updated(sensor, pose)
        problem = SearchProblem(uav, box, bonus, sensor, settings, belief=belief,
                                centres=centres, name=f.path.stem)
    except InvalidInputError as exc:
        raise f.fail(exc.field, exc.reason) from None
    return SearchJob(f.path, problem, visited)


def backends() -> list[str]:
    """The search backends (``auto`` runs ``receding``)."""
    return BACKENDS.names()


def solve(problem: SearchJob, *, backend: str, time_limit_s: float,
          seed: int) -> Result[SearchPlan]:
    """Plan the next positions with the named backend (see :func:`searchtrack.plan.search.
    solve`)."""
    return solve_search(problem.problem, backend=backend, time_limit_s=time_limit_s, seed=seed)


def plan_json(problem: SearchJob, result: Result[SearchPlan]) -> dict[str, Any]:
    """The ``"plan"`` object: next waypoint, planned sequence, score split, candidates."""
    plan = result.plan
    if plan is None:
        raise ValueError("plan_json needs a result with a plan")
    settings = problem.problem.settings
    return {"refinement": settings.refinement.name,
            "waypoint": np.round(plan.waypoint, 6).tolist(),
            "sequence": np.round(plan.sequence, 6).tolist(),
            "score": {"exploration": plan.exploration, "refinement": plan.refinement,
                      "alpha": settings.alpha, "total": plan.score},
            "candidates": plan.candidates}


def figure(problem: SearchJob, result: Result[SearchPlan], path: Path) -> Path | None:
    """PNG, top view: the exploration bonus at the UAV's altitude (shaded), the particles (area ∝
    weight), the centres, the poses visited and the planned sequence."""
    from searchtrack.sim.figure_style import pyplot, save_png

    plt = pyplot()

    prob = problem.problem
    fig, ax = plt.subplots(figsize=(6.0, 6.0))
    bonus = prob.bonus
    gx, gy = np.meshgrid(bonus.axes[0], bonus.axes[1], indexing="ij")
    grid = np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, prob.position[2])], axis=1)
    shade = ax.pcolormesh(gx, gy, bonus.at(grid).reshape(gx.shape), cmap="Greens", vmin=0.0,
                          vmax=1.0, shading="auto", alpha=0.6)
    fig.colorbar(shade, ax=ax, shrink=0.8, label=f"exploration bonus at z = "
                 f"{prob.position[2]:.0f} m")
    belief = prob.belief
    if belief is not None:
        w = np.asarray(belief.weights)
        sizes = 4.0 + 60.0 * w / max(float(w.max()), 1e-12)
        ax.scatter(belief.positions[:, 0], belief.positions[:, 1], s=sizes, c="tab:gray",
                   alpha=0.5, label="particles")
    if prob.centres is not None and prob.centres.shape[0]:
        ax.scatter(prob.centres[:, 0], prob.centres[:, 1], marker="x", c="tab:red", s=50,
                   label="centres")
    if problem.visited.shape[0]:
        ax.plot(problem.visited[:, 0], problem.visited[:, 1], color="tab:blue", alpha=0.5,
                marker=".", label="visited")
    if result.plan is not None:
        xy = np.vstack([prob.position[:2], result.plan.sequence[:, :2]])
        ax.plot(xy[:, 0], xy[:, 1], color="tab:orange", lw=2.5, marker="o", ms=4,
                label="planned")
    ax.plot(*prob.position[:2], marker="^", color="tab:orange", ms=9)
    ax.set_xlim(*prob.bounds[0])
    ax.set_ylim(*prob.bounds[1])
    ax.set_aspect("equal")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_title(f"{problem.name}: {prob.settings.refinement.name}, {result.status.name}")
    ax.legend(loc="best", fontsize=7)
    return save_png(fig, Path(path))


def vehicle_paths(problem: SearchJob, result: Result[SearchPlan]) -> VehiclePaths:
    """The UAV from its position through the planned sequence, at their altitudes."""
    if result.plan is None:
        raise ValueError("vehicle_paths needs a result with a plan")
    return VehiclePaths((np.vstack([problem.problem.position, result.plan.sequence]),))
