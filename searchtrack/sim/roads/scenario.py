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
from searchtrack.estimate.association import BACKENDS as ASSOCIATION_BACKENDS
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
from searchtrack.plan.guidance.solve import BACKENDS as GUIDANCE_BACKENDS
from searchtrack.plan.guidance.view import StrategyConfig, check_search_settings
from searchtrack.plan.optw.solve import BACKENDS as OPTW_BACKENDS

Mode = Literal["track", "detect"]
MODES: tuple[Mode, ...] = ("track", "detect")
ASSOCIATORS: tuple[str, ...] = tuple(ASSOCIATION_BACKENDS.names())
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
class FilterSpec:
    """The graph LRT and node trackers (Tables 6.2 and 6.4).

    Parameters
    ----------
    alpha
        Target diffusivity ``α`` (on the unweighted Laplacian: hops²/s).
    decay_c
        LRT decay term ``C``.
    phi_max
        Detection threshold ``φ_max``.
    p_min
        Tracker dissolution threshold ``P_min``.
    gate_m
        EMD gate ``ℰ`` (m of road distance).
    associator
        The pairing backend of the EMD association, a name of
        :data:`searchtrack.estimate.association.BACKENDS`: ``"greedy"`` (Algorithm 1),
        ``"optimal"`` (gated assignment) or ``"auto"``.
    birth_weighting
        ``"llr"`` or ``"likelihood_ratio"`` (see :class:`~searchtrack.estimate.LRTInitiator`).
    merge_radius_m
        A detection within this distance of a live tracker's peak is suppressed without a birth
        (100 m, the default validity distance: a second tracker that close to the same target
        would count as spurious; 0 births every detection, the thesis read literally).
    llr_floor
        Lower bound on ``φ`` where the sensors update it: −20 (−2 φ_max) by default; ``-inf`` is
        the thesis read literally. Without it, negative evidence piles up to hundreds of nats
        where the UAVs fly and buries a target that later drives there: in experiment 1 on the
        small maps over half the runs then never find every target (see
        :func:`~searchtrack.estimate.lrt.update_likelihood_field`).
    negative_information
        Trackers a UAV covers without an associated fix lose ``P_d`` of their probability on
        the footprint (renormalised; a rule of this library, the thesis has none). On by default:
        with the floor, a tracker that lost its target spreads and dissolves instead of lingering
        as a spurious track while the target is found again (demo, 4 seeds: MOC 36 % → 53 %,
        PVT 85 % → 92 %).
    belief
        What the mission estimates with: ``"lrt"`` (default), the thesis's likelihood-ratio
        field and node trackers (every setting above), or ``"rbpf"``, the Rao-Blackwellized
        particle filter of Moore et al. 2021 (paper 000) for the known number of targets, read
        by the same guidance (:mod:`searchtrack.sim.roads.rbpf_belief`; of the settings above
        it uses only ``p_min``, and ``alpha`` — or ``tracker_alpha`` when set — for the
        reacquisition horizon).
    histories, particles
        The RBPF's association histories ``H`` and particles per target filter ``N`` (10 and
        500, the paper's); integers ≥ 1, used when ``belief = "rbpf"``.
    jump_rate_per_s
        ``λ ≥ 0`` of the RBPF's robust prior (:mod:`searchtrack.estimate.road_jumps`, beyond
        paper 000): the rate at which a target may leave its predicted cloud; 0 (default): the
        paper's prior. Used when ``belief = "rbpf"``.
    kld_epsilon
        KLD-sampling of the RBPF (beyond paper 000; Fox 2003, see
        :class:`~searchtrack.estimate.road_resampling.KLDSampling`): each target filter's
        particle count follows its spread, at most ``particles``, bounding the
        Kullback-Leibler error by this ``ε`` in ``(0, 1)`` on road bins of the sensor's position
        noise. ``None`` (default): every filter keeps ``particles``. Used when
        ``belief = "rbpf"``.
    node_resolution_m
        The RBPF's node beliefs as the guidance reads them (``belief = "rbpf"``): each
        localised target's node belief blurred along the roads by a Gaussian of this standard
        deviation (m; :mod:`searchtrack.estimate.road_kernel`). ``None`` (default): the
        sensor's position noise ``s``, the resolution the thesis's trackers and its ``ϱ`` work
        at; 0: the cloud's own nearer-end-node beliefs (paper 000's binning), whose peak stays
        near 1 while a tight cloud drives on unseen, so under (5.16) a UAV comes back only once
        the cloud has split. Localisation (``p_min``) reads the cloud's own beliefs either way.
    tracker_alpha
        Diffusivity of the node trackers' prediction (4.2) (hops²/s), ``None`` (default): the
        thesis's one ``alpha`` for the LRT and the trackers. It also sets the reacquisition
        horizon ``T_r`` (the time a tracker's peak takes to fall to ``P_min`` under that same
        prediction). The courier targets spread far faster than ``alpha`` = 0.447: the mean
        square road distance they cover grows as ``2·α·t`` with α ≈ 14 hops²/s on the
        Aguascalientes map (t = 20–120 s), while the LRT's slow spread is what keeps search
        evidence local.
    handover
        Identity hand-over on re-detection (a rule of this library, the thesis has none): a
        tracker born where a live tracker has lost its target (no fix for 1 s, half its mass
        within ``2·gate_m`` road distance of the birth) replaces that tracker's distribution,
        which keeps its ``track_id``, instead of becoming a second tracker (see
        :mod:`searchtrack.estimate.handover`; ``belief = "lrt"`` only). On by default:
        in experiment 2 (10 seeds × 4 altitudes × 2 strategies per fleet) it raised PVT from
        0.82 to 0.88 (3 UAVs / 2 targets) and 0.84 to 0.88 (1 / 4) at an unchanged MOC;
        ``false`` is the thesis read literally.
    """

    alpha: float = 0.447
    decay_c: float = 50.0
    phi_max: float = 10.0
    p_min: float = 0.07
    gate_m: float = 300.0
    associator: str = "greedy"
    birth_weighting: Literal["llr", "likelihood_ratio"] = "llr"
    merge_radius_m: float = 100.0
    llr_floor: float = -20.0
    negative_information: bool = True
    belief: str = "lrt"
    histories: int = 10
    particles: int = 500
    jump_rate_per_s: float = 0.0
    kld_epsilon: float | None = None
    node_resolution_m: float | None = None
    tracker_alpha: float | None = None
    handover: bool = True

    def __post_init__(self) -> None:
        for name in ("alpha", "decay_c", "phi_max", "gate_m"):
            positive(name, getattr(self, name))
        if self.tracker_alpha is not None:
            positive("tracker_alpha", self.tracker_alpha)
        non_negative("jump_rate_per_s", self.jump_rate_per_s)
        if self.kld_epsilon is not None and not (
                isinstance(self.kld_epsilon, (int, float)) and 0.0 < self.kld_epsilon < 1.0):
            raise InvalidInputError("kld_epsilon", self.kld_epsilon, "must be in (0, 1) or unset")
        if self.node_resolution_m is not None:
            non_negative("node_resolution_m", self.node_resolution_m)
        if not isinstance(self.handover, bool):
            raise InvalidInputError("handover", self.handover, "must be true or false")
        from searchtrack.sim.roads.filters import FILTERS  # the registry imports this module

        if self.belief not in FILTERS.names():
            raise InvalidInputError("belief", self.belief, f"must be one of {FILTERS.names()}")
        for name in ("histories", "particles"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise InvalidInputError(name, value, "must be an integer ≥ 1")
        if math.isnan(self.llr_floor) or self.llr_floor >= 0.0:
            raise InvalidInputError("llr_floor", self.llr_floor, "must be < 0 (or -inf: none)")
        if not (math.isfinite(self.merge_radius_m) and self.merge_radius_m >= 0.0):
            raise InvalidInputError("merge_radius_m", self.merge_radius_m, "must be finite, ≥ 0")
        if not 0.0 < self.p_min < 1.0:
            raise InvalidInputError("p_min", self.p_min, "must be in (0, 1)")
        if self.associator not in ASSOCIATORS:
            raise InvalidInputError("associator", self.associator,
                                    f"must be one of {list(ASSOCIATORS)}")
        if self.birth_weighting not in ("llr", "likelihood_ratio"):
            raise InvalidInputError("birth_weighting", self.birth_weighting,
                                    "must be 'llr' or 'likelihood_ratio'")

    @property
    def tracker_diffusivity(self) -> float:
        """The trackers' diffusivity: ``tracker_alpha`` when set, else ``alpha``."""
        return self.alpha if self.tracker_alpha is None else self.tracker_alpha


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
    """

    strategy: str = "search_and_loiter"
    spring_k: float | None = None
    loiter_k: float | None = None
    revisit_threshold: float = 0.3
    optw_backend: str = "auto"
    optw_budget_s: float = 0.03
    coverage_weight: float = 0.0
    search_iterations: int = StrategyConfig.search_iterations
    search_horizon_s: float = StrategyConfig.search_horizon_s
    search_replan_s: float = StrategyConfig.search_replan_s
    search_route_nodes: int = StrategyConfig.search_route_nodes
    search_cell_m: float | None = StrategyConfig.search_cell_m
    search_serve_m: float | None = StrategyConfig.search_serve_m

    def __post_init__(self) -> None:
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
