"""Read a :class:`~searchtrack.sim.roads.scenario.Scenario` from TOML; errors name file and key."""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.files import read_text
from searchtrack.models import CourierModel, DubinsLimits, SensorModel
from searchtrack.models.lrt_sensor import THESIS_ALTITUDES_M, AltitudeModel
from searchtrack.plan.guidance.view import STEERINGS
from searchtrack.plan.optw.solve import BACKENDS as OPTW_BACKENDS
from searchtrack.sim.roads.filter_spec import SEARCH_FIELDS
from searchtrack.sim.roads.filters import FILTERS
from searchtrack.sim.roads.scenario import (
    ASSOCIATORS,
    BUNDLED_MAPS,
    MODES,
    STARTS,
    STRATEGIES,
    FilterSpec,
    GuidanceSpec,
    MapSpec,
    Scenario,
    bundled_map,
)
from searchtrack.sim.toml_fields import Table

#: Largest scenario file read (bytes).
MAX_SCENARIO_BYTES = 2**20


def load_scenario(path: str | Path) -> Scenario:
    """The scenario in TOML file ``path``.

    Raises
    ------
    ParseError
        Naming the file and the dotted key: missing file, bad TOML, a missing, misspelt,
        mistyped or out-of-range field.
    """
    p = Path(path)
    text = read_text(p, max_bytes=MAX_SCENARIO_BYTES)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParseError(p, None, None, f"not valid TOML: {exc}") from None
    top = Table(data, p)
    d = Scenario  # the defaults: the dataclass's own
    section = ""
    try:
        section = "map"
        map_spec = _map(top.table("map", required=True), p.parent)
        section = "uavs"
        uavs = top.table("uavs")
        uav_count = uavs.integer("count", d.uav_count, minimum=1)
        uav_start = uavs.string("start", d.uav_start, choices=STARTS)
        limits = _limits(uavs)
        section = "sensor"
        sensor, altitude = _sensor(top.table("sensor"))
        section = "targets"
        targets = top.table("targets")
        target_count = targets.integer("count", d.target_count, minimum=1)
        courier = _courier(targets)
        section = "filter"
        filt = _filter(top.table("filter"))
        section = "guidance"
        guidance = _guidance(top.table("guidance"))
        section = ""
        scenario = Scenario(
            name=top.string("name", p.stem),
            map=map_spec,
            uav_count=uav_count,
            target_count=target_count,
            sensor=sensor,
            altitude_m=altitude,
            limits=limits,
            uav_start=uav_start,
            courier=courier,
            filter=filt,
            guidance=guidance,
            mode=top.string("mode", d.mode, choices=MODES),  # type: ignore[arg-type]
            duration_s=top.number("duration_s", d.duration_s),
            dt_s=top.number("dt_s", d.dt_s),
            seed=top.integer("seed", d.seed),
            valid_distance_m=top.number("valid_distance_m", d.valid_distance_m),
        )
        top.done()
    except InvalidInputError as exc:
        key = f"{section}.{exc.field}" if section else exc.field
        raise ParseError(p, None, key, f"{exc.value!r}: {exc.reason}") from None
    return scenario


def _map(t: Table, base: Path) -> MapSpec:
    spacing = t.number("spacing_m", MapSpec.spacing_m)
    kinds = [k for k in ("osm", "grid", "random") if t.has(k)]
    if len(kinds) != 1:
        raise t.fail("osm", "give exactly one of 'osm', 'grid' or 'random'")
    kind = kinds[0]
    if kind == "osm":
        name = t.string("osm")
        path = bundled_map(name) if name in BUNDLED_MAPS else (base / name)
        if not path.is_file():
            raise t.fail("osm", f"no such file {str(path)!r} (bundled maps: {list(BUNDLED_MAPS)})")
        t.done()
        return MapSpec("osm", path, spacing)
    sub = t.table(kind)
    if kind == "grid":
        spec = MapSpec("grid", None, spacing, rows=sub.integer("rows", minimum=2),
                       cols=sub.integer("cols", minimum=2),
                       block_m=sub.number("block_m", MapSpec.block_m))
    else:
        spec = MapSpec("random", None, spacing, junctions=sub.integer("junctions", minimum=2),
                       extent_m=sub.number("extent_m", MapSpec.extent_m),
                       map_seed=sub.integer("seed", MapSpec.map_seed))
    sub.done()
    t.done()
    return spec


def _limits(t: Table) -> DubinsLimits:
    d = DubinsLimits  # the defaults: the dataclass's own
    speed = t.number("speed_mps", d.speed_max_mps)
    limits = DubinsLimits(
        speed_max_mps=speed,
        speed_min_mps=t.number("min_speed_mps", speed),
        turn_rate_max_rps=math.radians(t.number("turn_rate_deg_s",
                                                   math.degrees(d.turn_rate_max_rps))),
    )
    t.done()
    return limits


def _sensor(t: Table) -> tuple[SensorModel, float | None]:
    altitude = t.optional_number("altitude_m")
    fa = t.optional_number("false_alarms_per_scan")
    cell = t.number("cell_radius_m", SensorModel.cell_radius_m, minimum=0.0)
    if altitude is not None:
        for name in ("pd", "pf", "footprint_radius_m", "position_noise_m"):
            if t.has(name):
                raise t.fail(name, "give either altitude_m or the sensor's parameters, not both")
        t.done()
        sensor = AltitudeModel().sensor(altitude, fa)
    elif not t.has("pd"):
        t.done()
        altitude = THESIS_ALTITUDES_M[0]   # the scenario default (1500 ft)
        sensor = AltitudeModel().sensor(altitude, fa)
    else:
        sensor = SensorModel(
            pd=t.number("pd"),
            pf=t.number("pf"),
            footprint_radius_m=t.number("footprint_radius_m"),
            position_noise_m=t.number("position_noise_m"),
            false_alarms_per_scan=fa,
        )
        t.done()
    return dataclasses.replace(sensor, cell_radius_m=cell), altitude


def _courier(t: Table) -> CourierModel:
    d = CourierModel  # the defaults: the dataclass's own
    model = CourierModel(
        max_speed_mps=t.number("max_speed_mps", d.max_speed_mps),
        min_speed_fraction=t.number("min_speed_fraction", d.min_speed_fraction),
        mean_drive_s=t.number("mean_drive_s", d.mean_drive_s),
        dwell_min_s=t.number("dwell_min_s", d.dwell_min_s),
        dwell_max_s=t.number("dwell_max_s", d.dwell_max_s),
    )
    t.done()
    return model


def _filter(t: Table) -> FilterSpec:
    d = FilterSpec  # the defaults: the dataclass's own
    spec = FilterSpec(
        alpha=t.number("alpha", d.alpha),
        decay_c=t.number("decay_c", d.decay_c),
        phi_max=t.number("phi_max", d.phi_max),
        p_min=t.number("p_min", d.p_min),
        gate_m=t.number("gate_m", d.gate_m),
        associator=t.string("associator", d.associator, choices=ASSOCIATORS),
        birth_weighting=t.string("birth_weighting", d.birth_weighting,  # type: ignore[arg-type]
                                 choices=("llr", "likelihood_ratio")),
        merge_radius_m=t.number("merge_radius_m", d.merge_radius_m, minimum=0.0),
        llr_floor=_floor(t),
        negative_information=t.boolean("negative_information", d.negative_information),
        belief=t.string("belief", d.belief, choices=tuple(FILTERS.names())),
        histories=t.integer("histories", d.histories, minimum=1),
        particles=t.integer("particles", d.particles, minimum=1),
        jump_rate_per_s=t.number("jump_rate_per_s", d.jump_rate_per_s, minimum=0.0),
        kld_epsilon=t.optional_number("kld_epsilon", positive=True, maximum=1.0),
        search_field=t.string("search_field", d.search_field, choices=SEARCH_FIELDS),
        node_resolution_m=t.optional_number("node_resolution_m", minimum=0.0),
        tracker_alpha=t.optional_number("tracker_alpha"),
        handover=t.boolean("handover", d.handover),
    )
    t.done()
    return spec


def _floor(t: Table) -> float:
    """``llr_floor``: a negative number, or the string ``"none"`` for no floor."""
    if t.raw("llr_floor", None) == "none":
        return -math.inf
    value = t.number("llr_floor", FilterSpec.llr_floor)
    if value >= 0.0:
        raise t.fail("llr_floor", f"must be < 0 or \"none\", got {value!r}")
    return value


def _guidance(t: Table) -> GuidanceSpec:
    d = GuidanceSpec  # the defaults: the dataclass's own
    spec = GuidanceSpec(
        strategy=t.string("strategy", d.strategy, choices=STRATEGIES),
        spring_k=t.optional_number("spring_k"),
        loiter_k=t.optional_number("loiter_k"),
        revisit_threshold=t.number("revisit_threshold", d.revisit_threshold),
        optw_backend=t.string("optw_backend", d.optw_backend,
                              choices=tuple(OPTW_BACKENDS.names())),
        optw_budget_s=t.number("optw_budget_s", d.optw_budget_s),
        optw_iterations=(t.integer("optw_iterations", minimum=1) if t.has("optw_iterations")
                         else None),
        coverage_weight=t.number("coverage_weight", d.coverage_weight),
        search_iterations=t.integer("search_iterations", d.search_iterations, minimum=1),
        search_horizon_s=t.number("search_horizon_s", d.search_horizon_s, positive=True),
        search_replan_s=t.number("search_replan_s", d.search_replan_s, positive=True),
        search_route_nodes=t.integer("search_route_nodes", d.search_route_nodes, minimum=1),
        search_cell_m=t.optional_number("search_cell_m", positive=True),
        search_serve_m=t.optional_number("search_serve_m", minimum=0.0),
        steering=t.string("steering", d.steering, choices=STEERINGS),
    )
    t.done()
    return spec
