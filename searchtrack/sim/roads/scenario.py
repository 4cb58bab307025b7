"""A road search-and-track mission (thesis 001, Ch. 6) as a frozen, validated scenario.

A scenario fixes the map, the UAVs and their sensor, the targets, the filter, the guidance
strategy, the duration and the seed; :func:`load_scenario` reads one from a TOML file (see
``searchtrack/data/scenarios/demo.toml`` for every key with its default).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Literal

from searchtrack.core.checks import non_negative, positive
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.registry import MAX_SEED
from searchtrack.models import (
    CourierModel,
    DubinsLimits,
    RoadNetwork,
    SensorModel,
    grid_network,
    random_network,
    read_osm,
)
from searchtrack.models.lrt_sensor import THESIS_ALTITUDES_M
from searchtrack.plan.guidance.reacquire import check_optw_iterations
from searchtrack.plan.guidance.solve import BACKENDS as GUIDANCE_BACKENDS
from searchtrack.plan.guidance.view import STEERINGS, StrategyConfig, check_search_settings
from searchtrack.plan.optw.solve import BACKENDS as OPTW_BACKENDS
from searchtrack.sim.roads.filter_spec import ASSOCIATORS as ASSOCIATORS
from searchtrack.sim.roads.filter_spec import FilterSpec as FilterSpec

Mode = Literal["track", "detect"]
MODES: tuple[Mode, ...] = ("track", "detect")
STRATEGIES: tuple[str, ...] = tuple(GUIDANCE_BACKENDS.names())
STARTS = ("random", "center", "edge")
BUNDLED_MAPS = ("aguascalientes", "West-Oakland")

#: Most road nodes a mission's map may have: the diffusion operators and the per-node fields of a
#: city map (8602 nodes for the bundled one) scale to this in a few GB.
MAX_ROAD_NODES = 200_000

#: Most time steps a mission may take (ten days at the thesis's 0.3 s).
MAX_STEPS = 3_000_000

#: Most particles ``histories · targets · particles`` an RBPF belief may hold (about 32 bytes
#: each: 320 MB).
MAX_RBPF_PARTICLES = 10_000_000


def bundled_map(name: str) -> Path:
    """Path of an OpenStreetMap extract shipped with searchtrack (© OpenStreetMap contributors,
    ODbL)."""
    if name not in BUNDLED_MAPS:
        raise InvalidInputError("osm", name, f"bundled maps are {list(BUNDLED_MAPS)}")
    return Path(str(resources.files("searchtrack") / "data" / "osm" / f"{name}.osm.bz2"))




@dataclass(frozen=True)
class MapSpec:
    """Which road network: an OSM file, or a synthetic grid or random network.

    Parameters
    ----------
    kind
        ``"osm"``, ``"grid"`` or ``"random"``.
    osm_path
        The ``.osm``/``.osm.bz2`` file (``kind="osm"``).
    spacing_m
        Node spacing after resampling (10 m in the thesis).
    rows, cols, block_m
        Grid size and block length (``kind="grid"``).
    junctions, extent_m, map_seed
        Random planar network (``kind="random"``).
    """

    kind: Literal["osm", "grid", "random"] = "osm"
    osm_path: Path | None = None
    spacing_m: float = 10.0
    rows: int = 10
    cols: int = 10
    block_m: float = 100.0
    junctions: int = 200
    extent_m: float = 2000.0
    map_seed: int = 0

    def __post_init__(self) -> None:
        if self.kind not in ("osm", "grid", "random"):
            raise InvalidInputError("kind", self.kind, "must be 'osm', 'grid' or 'random'")
        if self.kind == "osm" and self.osm_path is None:
            raise InvalidInputError("osm_path", None, "an OSM map needs a file")
        for name in ("spacing_m", "block_m", "extent_m"):
            positive(name, getattr(self, name))
        for name in ("rows", "cols", "junctions"):
            if getattr(self, name) < 2:
                raise InvalidInputError(name, getattr(self, name), "must be ≥ 2")
        nodes = self.estimated_nodes()
        if nodes > MAX_ROAD_NODES:
            raise InvalidInputError(self.kind, self.describe(), f"about {nodes:.3g} road nodes at "
                                    f"spacing_m={self.spacing_m:g}, above the {MAX_ROAD_NODES} a "
                                    "mission can hold in memory")

    def estimated_nodes(self) -> float:
        """Road nodes the synthetic map will have after resampling (an estimate: a grid's
        ``rows·cols`` junctions plus its streets' length / spacing; a random network's
        junctions times its mean street length / spacing); 0 for an OSM file (read to know)."""
        if self.kind == "grid":
            streets_m = (self.rows * (self.cols - 1) + self.cols * (self.rows - 1)) * self.block_m
            return self.rows * self.cols + streets_m / self.spacing_m
        if self.kind == "random":
            mean_street_m = self.extent_m / math.sqrt(self.junctions)
            return self.junctions * (1.0 + 1.5 * mean_street_m / self.spacing_m)
        return 0.0

    def build(self) -> RoadNetwork:
        """The road network (largest connected component, resampled)."""
        if self.kind == "grid":
            return grid_network(self.rows, self.cols, self.block_m, self.spacing_m)
        if self.kind == "random":
            return random_network(self.junctions, self.extent_m, self.spacing_m,
                                  seed=self.map_seed)
        assert self.osm_path is not None
        return read_osm(self.osm_path, self.spacing_m)

    def describe(self) -> str:
        """A short label."""
        if self.kind == "osm":
            assert self.osm_path is not None
            return self.osm_path.name
        if self.kind == "grid":
            return f"grid {self.rows}x{self.cols} @ {self.block_m:g} m"
        return f"random {self.junctions} junctions, {self.extent_m:g} m"


@dataclass(frozen=True)
class GuidanceSpec:
    """How the UAVs fly (thesis Ch. 5).

    Parameters
    ----------
    strategy
        The guidance backend, a name of :data:`searchtrack.plan.guidance.BACKENDS`:
        ``"search"``, ``"loiter"``, ``"search_and_loiter"``, ``"search_and_reacquire"`` or one
        of this library's route strategies (``"route_loiter"``, ...: searching UAVs fly OPTW
        routes over the search field, :mod:`searchtrack.plan.guidance.route_strategies`).
    spring_k, loiter_k
        Spring constants of ∇Q and of ∇L/∇W; ``None`` keeps the planner's defaults.
    revisit_threshold
        ``ϱ``: an assigned UAV searches while its tracker's peak exceeds it (0.3).
    optw_backend, optw_budget_s
        Solver of the reacquisition OPTW, and the time limit of each step's guidance solve
        (shared by the OPTW solves of the UAVs that re-plan in that step).
    optw_iterations
        With ``optw_backend = "ils"``, a cap on each reacquisition OPTW's iterations, so that a
        seed flies the same mission on a slower or busier machine (``None``: the time share
        alone; :class:`~searchtrack.plan.guidance.view.StrategyConfig`).
    coverage_weight
        Weight (≥ 0, the units of the gradient force ∇R) of the coverage force that pushes
        free UAVs (searching, paired with no tracker) away from road the fleet covered
        recently and toward road it has not (a rule of this library, the thesis has none; see
        :func:`~searchtrack.plan.guidance.forces.coverage_force` and
        :class:`~searchtrack.sim.roads.coverage.CoverageMemory`). 0 (default): the thesis's search.
    search_iterations, search_horizon_s, search_replan_s, search_route_nodes, search_cell_m, \
search_serve_m
        The route strategies' search OPTW (:class:`~searchtrack.plan.guidance.view.
        StrategyConfig`, whose defaults these are; ``None`` cell and serve distances derive
        from the footprint ``ρ``). The thesis's strategies do not read them.
    steering
        How the guidance force turns the UAVs (:data:`~searchtrack.plan.guidance.view.
        STEERINGS`): ``"turn_back"`` (default, this library's) turns a loitering, reacquiring
        or routed UAV by the whole force when it points behind it, so a UAV that overflies its
        anchor turns back at once (searching UAVs steer by (5.3)); ``"thesis"`` is (5.3) for
        every UAV, under which a constant-speed UAV flies on past its anchor
        (:mod:`searchtrack.models.dubins`).
    """

    strategy: str = "search_and_loiter"
    spring_k: float | None = None
    loiter_k: float | None = None
    revisit_threshold: float = 0.3
    optw_backend: str = "auto"
    optw_budget_s: float = 0.03
    optw_iterations: int | None = None
    coverage_weight: float = 0.0
    search_iterations: int = StrategyConfig.search_iterations
    search_horizon_s: float = StrategyConfig.search_horizon_s
    search_replan_s: float = StrategyConfig.search_replan_s
    search_route_nodes: int = StrategyConfig.search_route_nodes
    search_cell_m: float | None = StrategyConfig.search_cell_m
    search_serve_m: float | None = StrategyConfig.search_serve_m
    steering: str = "turn_back"

    def __post_init__(self) -> None:
        if self.steering not in STEERINGS:
            raise InvalidInputError("steering", self.steering, f"must be one of {STEERINGS}")
        if self.strategy not in STRATEGIES:
            raise InvalidInputError("strategy", self.strategy,
                                    f"must be one of {GUIDANCE_BACKENDS.names()}")
        if self.optw_backend not in OPTW_BACKENDS.names():
            raise InvalidInputError("optw_backend", self.optw_backend,
                                    f"must be one of {OPTW_BACKENDS.names()}")
        for name in ("spring_k", "loiter_k"):
            value = getattr(self, name)
            if value is not None:
                positive(name, value)
        if not 0.0 < self.revisit_threshold < 1.0:
            raise InvalidInputError("revisit_threshold", self.revisit_threshold,
                                    "must be in (0, 1)")
        positive("optw_budget_s", self.optw_budget_s)
        check_optw_iterations(self.optw_backend, self.optw_iterations)
        non_negative("coverage_weight", self.coverage_weight)
        check_search_settings(self)


@dataclass(frozen=True)
class Scenario:
    """One mission: who flies where, against what, for how long, with which seed.

    Parameters
    ----------
    mode
        ``"track"`` (search and track, §6.2) or ``"detect"`` (§6.1: a target becomes invisible
        once detected, trackers are not kept, the run ends when every target is detected).
    uav_count, uav_start, limits
        Number of UAVs, where they start (``"random"`` road nodes, the map ``"center"``, or an
        ``"edge"`` of the map's bounding box), and their Dubins limits.
    sensor, altitude_m
        The sensor (``altitude_m`` is recorded when it came from the altitude model).
    target_count, courier
        Number of targets and how they drive.
    valid_distance_m
        A tracker is *valid* when its peak node is within this distance of a true target it is
        matched to (one-to-one, minimum total distance); an association is valid when the
        measurement came from the tracker's matched target.
    """

    name: str
    map: MapSpec
    uav_count: int = 3
    target_count: int = 4
    sensor: SensorModel = field(
        default_factory=lambda: SensorModel.at_altitude(THESIS_ALTITUDES_M[0]))
    altitude_m: float | None = THESIS_ALTITUDES_M[0]
    limits: DubinsLimits = field(default_factory=DubinsLimits)
    uav_start: str = "random"
    courier: CourierModel = field(default_factory=CourierModel)
    filter: FilterSpec = field(default_factory=FilterSpec)
    guidance: GuidanceSpec = field(default_factory=GuidanceSpec)
    mode: Mode = "track"
    duration_s: float = 60.0
    dt_s: float = 0.3
    seed: int = 0
    valid_distance_m: float = 100.0

    def __post_init__(self) -> None:
        if not self.name:
            raise InvalidInputError("name", self.name, "must not be empty")
        if self.uav_count < 1:
            raise InvalidInputError("uav_count", self.uav_count, "must be ≥ 1")
        if self.target_count < 1:
            raise InvalidInputError("target_count", self.target_count, "must be ≥ 1")
        if self.mode not in MODES:
            raise InvalidInputError("mode", self.mode, f"must be one of {list(MODES)}")
        if self.uav_start not in STARTS:
            raise InvalidInputError("uav_start", self.uav_start, f"must be one of {list(STARTS)}")
        for name in ("duration_s", "dt_s", "valid_distance_m"):
            positive(name, getattr(self, name))
        if self.dt_s > self.duration_s:
            raise InvalidInputError("dt_s", self.dt_s, f"exceeds duration_s={self.duration_s}")
        if self.sensor.position_noise_m <= 0.0:
            raise InvalidInputError("sensor.position_noise_m", self.sensor.position_noise_m,
                                    "the trackers need a positive position noise")
        if not 0 <= self.seed <= MAX_SEED:
            raise InvalidInputError("seed", self.seed, f"must be in [0, {MAX_SEED}]")
        f = self.filter
        held = f.histories * self.target_count * f.particles
        if f.belief == "rbpf" and held > MAX_RBPF_PARTICLES:
            raise InvalidInputError("filter.particles", f.particles, f"{f.histories} histories × "
                                    f"{self.target_count} targets × {f.particles} particles = "
                                    f"{held:.3g}, above the {MAX_RBPF_PARTICLES} an RBPF may hold")
        steps = self.duration_s / self.dt_s
        if steps > MAX_STEPS:
            raise InvalidInputError("duration_s", self.duration_s, f"{steps:.3g} steps of dt_s="
                                    f"{self.dt_s:g}, above the {MAX_STEPS} a mission may take")

    @property
    def n_steps(self) -> int:
        """Number of time steps ``⌈duration / Δt⌉``."""
        return math.ceil(self.duration_s / self.dt_s - 1e-9)
