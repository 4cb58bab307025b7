"""The ``assign`` plan family: one candidate action per UAV on a particle belief (paper 003),
read from a JSON file and solved by a backend of :data:`searchtrack.plan.assign.BACKENDS`.

PROBLEM.json::

    {"uavs": [[x, y, z], ...],
     "actions": [[[[x, y, z], ...], ...], ...],
     "belief": {"positions": [[x, y], ...], "weights": [w, ...]},
     "sensor": {"peak_pd": 0.9, "scale_xy_m": 10.0, "scale_z_m": 30.0},
     "objective": "end",
     "min_separation_m": 0}

``uavs`` holds the current pose of each of the ``R`` UAVs (m). ``actions[r]`` lists the
candidate actions of UAV ``r`` (at least one), each a list of ``T`` poses ``[x, y, z]`` (m, the
same ``T`` for every action). ``belief`` is a particle PHD: ``N ≥ 1`` positions ``[x, y]`` (ground
targets) or ``[x, y, z]`` and ``N`` non-negative weights summing to the expected number of
targets. ``sensor`` is a :class:`~searchtrack.models.footprint.GaussianFieldOfView`: peak
detection probability in ``(0, 1]`` and the footprint's horizontal and vertical scales (m).
``objective`` (optional, default ``"end"``) is ``"end"`` (expected number of detections,
003 eq. 13) or ``"mi"`` (binary mutual information, 003 §2.5); ``min_separation_m`` (optional,
default 0 = off) forbids pairs of actions that come closer at a common step.

The ``"plan"`` object of PLAN.json: ``{"objective": "end", "actions": [a_0, ...], "poses":
[[[x, y, z], ...], ...]}`` — the chosen action index of each UAV and the poses it flies.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.fields import TOP_LEVEL, JsonFields
from searchtrack.core.files import read_json
from searchtrack.core.result import Result
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.models.footprint import GaussianFieldOfView
from searchtrack.plan.assign import (
    BACKENDS as BACKENDS,
)
from searchtrack.plan.assign import (
    Assignment,
    AssignmentProblem,
    ExpectedDetections,
    MutualInformation,
    Objective,
)
from searchtrack.plan.assign import solve as solve_assignment
from searchtrack.sim.export.plans import VehiclePaths
from searchtrack.sim.kernels import kernels_of

DESCRIPTION = "one candidate action per UAV on a particle belief (paper 003)"
KERNELS = kernels_of(BACKENDS)

#: Largest PROBLEM.json read (bytes).
MAX_PROBLEM_BYTES = 32 * 2**20
#: Largest detection matrix (poses × particles) a problem may need: about 160 MB of floats.
MAX_DETECTION_ENTRIES = 20_000_000
#: Coordinates and lengths must lie within ± this (m).
MAX_DISTANCE_M = 1e7

OBJECTIVES = ("end", "mi")
_TOP_KEYS = ("uavs", "actions", "belief", "sensor", "objective", "min_separation_m")
_BELIEF_KEYS = ("positions", "weights")
_SENSOR_KEYS = ("peak_pd", "scale_xy_m", "scale_z_m")


@dataclass(frozen=True)
class AssignJob:
    """A validated PROBLEM.json: the assignment problem and where it came from."""

    path: Path
    problem: AssignmentProblem

    @property
    def name(self) -> str:
        """The file's stem."""
        return self.path.stem


class ProblemFields(JsonFields):
    """Field checks raising :class:`ParseError` naming the file and the dotted JSON key: numbers
    lie within ±:data:`MAX_DISTANCE_M` unless a call says otherwise.

    Parameters
    ----------
    path
        The file read.
    """

    def __init__(self, path: Path) -> None:
        super().__init__(path, low=-MAX_DISTANCE_M, high=MAX_DISTANCE_M, finite_in_range=True)
        self.path = path

    def points(self, value: Any, key: str, dims: tuple[int, ...]) -> np.ndarray[Any, Any]:
        """A list of points of one length in ``dims`` as an ``(n, d)`` array."""
        rows = self.items(value, key, "points")
        first = rows[0]
        want = len(first) if isinstance(first, list) and len(first) in dims else dims[0]
        shape = " or ".join(str(d) for d in dims)
        out = np.empty((len(rows), want))
        for i, row in enumerate(rows):
            if not isinstance(row, list) or len(row) != want:
                raise self.fail(f"{key}[{i}]", f"must be a list of {want if i else shape} "
                                f"numbers (x, y{', z' if want == 3 else ''}), got {row!r}")
            out[i] = [self.number(v, f"{key}[{i}][{j}]") for j, v in enumerate(row)]
        return out


def _actions(f: ProblemFields, raw: Any, robots: int) -> tuple[np.ndarray[Any, Any], ...]:
    per_uav = f.items(raw, "actions", "candidate actions per UAV")
    if len(per_uav) != robots:
        raise f.fail("actions", f"needs one list of actions per UAV ({robots}), "
                     f"got {len(per_uav)}")
    out = []
    steps: int | None = None
    for r, acts in enumerate(per_uav):
        block = []
        for a, action in enumerate(f.items(acts, f"actions[{r}]", "actions")):
            poses = f.points(action, f"actions[{r}][{a}]", (3,))
            if steps is None:
                steps = poses.shape[0]
            if poses.shape[0] != steps:
                raise f.fail(f"actions[{r}][{a}]", f"has {poses.shape[0]} poses; every action "
                             f"needs the same number ({steps})")
            block.append(poses)
        out.append(np.stack(block))
    return tuple(out)


def read_sensor(f: ProblemFields, raw: Any) -> GaussianFieldOfView:
    spec = f.obj(raw, "sensor", _SENSOR_KEYS)
    peak = f.number(f.get(spec, "peak_pd", "sensor."), "sensor.peak_pd", low=0.0,
                    low_open=True, high=1.0)
    scales = [f.number(f.get(spec, k, "sensor."), f"sensor.{k}", low=0.0, low_open=True)
              for k in ("scale_xy_m", "scale_z_m")]
    return GaussianFieldOfView(peak, scales[0], scales[1])


def read_belief(f: ProblemFields, raw: Any) -> WeightedParticles:
    spec = f.obj(raw, "belief", _BELIEF_KEYS)
    positions = f.points(f.get(spec, "positions", "belief."), "belief.positions", (2, 3))
    weights_raw = f.items(f.get(spec, "weights", "belief."), "belief.weights", "weights")
    if len(weights_raw) != positions.shape[0]:
        raise f.fail("belief.weights", f"needs one weight per position ({positions.shape[0]}), "
                     f"got {len(weights_raw)}")
    weights = np.array([f.number(w, f"belief.weights[{i}]", low=0.0, high=1e6)
                        for i, w in enumerate(weights_raw)])
    return WeightedParticles(positions, weights)


def _objective(f: ProblemFields, name: Any) -> Objective:
    if name not in OBJECTIVES:
        raise f.fail("objective", f"must be one of {list(OBJECTIVES)}, got {name!r}")
    return ExpectedDetections() if name == "end" else MutualInformation()


def load_problem(path: str | Path,
                 keys: tuple[str, ...]) -> tuple[ProblemFields, dict[str, Any]]:
    """The field reader of ``path`` and its top-level JSON object (only ``keys`` allowed).

    Raises
    ------
    ParseError
        Unreadable or not JSON (naming the line), not an object, an unknown key.
    """
    p = Path(path)
    f = ProblemFields(p)
    raw = read_json(p, max_bytes=MAX_PROBLEM_BYTES)
    return f, f.obj(raw, TOP_LEVEL, keys)


def read_problem(path: str | Path) -> AssignJob:
    """Read and validate an assignment PROBLEM.json (format in the module docstring).

    Raises
    ------
    ParseError
        Naming the file and the JSON key at fault (``sensor.peak_pd``, ``actions[1][0][2]``).
    """
    f, top = load_problem(path, _TOP_KEYS)
    uavs = f.points(f.get(top, "uavs"), "uavs", (3,))
    actions = _actions(f, f.get(top, "actions"), uavs.shape[0])
    belief = read_belief(f, f.get(top, "belief"))
    sensor = read_sensor(f, f.get(top, "sensor"))
    objective = _objective(f, top.get("objective", "end"))
    separation = f.number(top.get("min_separation_m", 0.0), "min_separation_m", low=0.0)
    entries = sum(a.shape[0] * a.shape[1] for a in actions) * belief.positions.shape[0]
    if entries > MAX_DETECTION_ENTRIES:
        raise f.fail("actions", f"poses × particles = {entries} exceeds "
                     f"{MAX_DETECTION_ENTRIES}; use fewer actions or particles")
    try:
        problem = AssignmentProblem(actions, belief, sensor, objective=objective,
                                    min_separation_m=separation, origins=uavs, name=f.path.stem)
    except InvalidInputError as exc:
        raise f.fail(exc.field, exc.reason) from None
    return AssignJob(f.path, problem)


def backends() -> list[str]:
    """The assignment backends, ``"auto"`` first."""
    return BACKENDS.names()


def solve(problem: AssignJob, *, backend: str, time_limit_s: float,
          seed: int) -> Result[Assignment]:
    """Assign one action per UAV with the named backend (see :func:`searchtrack.plan.assign.
    solve`)."""
    return solve_assignment(problem.problem, backend=backend, time_limit_s=time_limit_s,
                            seed=seed)


def plan_json(problem: AssignJob, result: Result[Assignment]) -> dict[str, Any]:
    """The ``"plan"`` object: objective name, chosen action per UAV and the poses flown."""
    plan = result.plan
    if plan is None:
        raise ValueError("plan_json needs a result with a plan")
    return {"objective": problem.problem.objective.name,
            "actions": list(plan.actions),
            "poses": np.round(plan.poses[:, :, :3], 6).tolist()}


def figure(problem: AssignJob, result: Result[Assignment], path: Path) -> Path | None:
    """PNG of the particles (area ∝ weight), the UAVs, every candidate action (faint) and the
    chosen ones."""
    from searchtrack.sim.figure_style import pyplot, save_png

    plt = pyplot()

    prob = problem.problem
    fig, ax = plt.subplots(figsize=(6.0, 6.0))
    w = prob.weights
    sizes = 4.0 + 60.0 * w / max(float(w.max()), 1e-12)
    ax.scatter(prob.positions[:, 0], prob.positions[:, 1], s=sizes, c="tab:gray", alpha=0.5,
               label="particles")
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    origins = prob.origins if prob.origins is not None else np.zeros((prob.robots, 3))
    for r in range(prob.robots):
        colour = colours[r % len(colours)]
        for action in prob.actions[r]:
            xy = np.vstack([origins[r, :2], action[:, :2]])
            ax.plot(xy[:, 0], xy[:, 1], color=colour, alpha=0.2, lw=1)
        if result.plan is not None:
            xy = np.vstack([origins[r, :2], result.plan.poses[r, :, :2]])
            ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=2.5, marker="o", ms=3,
                    label=f"UAV {r}: action {result.plan.actions[r]}")
        ax.plot(*origins[r, :2], marker="^", color=colour, ms=9)
    ax.set_aspect("equal")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_title(f"{problem.name}: {prob.objective.name}, {result.status.name}")
    ax.legend(loc="best", fontsize=7)
    return save_png(fig, Path(path), tight_bbox=True)   # equal axes leave blank bands


def vehicle_paths(problem: AssignJob, result: Result[Assignment]) -> VehiclePaths:
    """Each UAV from its pose through the poses of its chosen action (at their altitudes)."""
    plan, prob = result.plan, problem.problem
    if plan is None:
        raise ValueError("vehicle_paths needs a result with a plan")
    origins = prob.origins if prob.origins is not None else np.zeros((prob.robots, 3))
    return VehiclePaths(tuple(np.vstack([origins[r, :3], plan.poses[r, :, :3]])
                              for r in range(prob.robots)))
