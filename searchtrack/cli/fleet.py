"""``searchtrack fleet-size --map MAP``: the fewest UAVs whose entropy bound meets a
variance requirement.

Paper 000's Theorem 1 (Moore et al. 2021) bounds the average tracking entropy for ``M`` targets
and ``Q`` UAVs on a road map; Corollary 1 turns the bound into a positional variance. The command
prints, for ``Q = 1…max-uavs``, the revisit time, the post-update variance, ``B_L`` and the variance
bound, then the smallest ``Q`` with ``B_L`` at most the entropy of the required variance. MAP is
``grid:RxC[:BLOCK]`` (an ``R × C`` grid of intersections ``BLOCK`` m apart, default 100 m, nodes at
the intersections only) or a bundled OpenStreetMap extract by name.
"""

from __future__ import annotations

import argparse
import json
import math
import re
from collections.abc import Sequence

from rich.console import Console
from rich.markup import escape
from rich.table import Table

from searchtrack.cli.common import add_group, description, int_at_least, int_in, positive_float
from searchtrack.cli.output import output_file
from searchtrack.core.checks import finite_or_none
from searchtrack.core.errors import SearchtrackError
from searchtrack.core.files import write_text_atomic
from searchtrack.core.interrupt import StopRequested, stop_requested, stops_raise
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.fleet import (
    BoundConfig,
    BoundMap,
    ChainGraph,
    FleetSizing,
    chain_graph,
    fleet_size,
    s_node,
    subdivisions,
)
from searchtrack.plan.fleet.entropy_bound import BINNINGS, WINDOW_SIGMAS
from searchtrack.plan.fleet.mode_split import profile_refusal
from searchtrack.sim.roads.scenario import BUNDLED_MAPS, MapSpec, bundled_map

#: Most Dijkstra sources for ``S_node`` on a large map (a seeded sample beyond this).
S_NODE_SOURCES = 2000

#: Largest fleet the command will size.
MAX_FLEET = 1000

#: Most step × bin terms of the entropy sums for one fleet size (about ten seconds of work).
MAX_ENTROPY_CELLS = 1_000_000_000

_GRID = re.compile(r"grid:(\d+)x(\d+)(?::([0-9.eE+-]+))?")


def map_arg(text: str) -> MapSpec:
    """An argument type: ``grid:RxC[:BLOCK]`` or a bundled map name as a :class:`MapSpec`, else
    an :class:`argparse.ArgumentTypeError`."""
    if text in BUNDLED_MAPS:
        return MapSpec("osm", bundled_map(text))
    match = _GRID.fullmatch(text.strip())
    if match is None:
        raise argparse.ArgumentTypeError(f"{text!r}: expected grid:RxC[:BLOCK] or one of "
                                         f"{list(BUNDLED_MAPS)}")
    rows, cols = int(match[1]), int(match[2])
    block = positive_float(match[3]) if match[3] else 100.0
    if rows < 2 or cols < 2 or not math.isfinite(block):
        raise argparse.ArgumentTypeError(f"{text!r}: a grid needs R, C ≥ 2 and a finite BLOCK")
    try:
        return MapSpec("grid", rows=rows, cols=cols, block_m=block, spacing_m=block)
    except SearchtrackError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: {exc}") from None


def sizing_table(sizing: FleetSizing, title: str) -> Table:
    """One row per fleet size: revisit time, ``σ²_{p0}``, ``B_L`` and the variance bound."""
    table = Table(title=title)
    for name in ("Q", "revisit (s)", "σ²_p0 (m²)", "B_L (nats)", "σ_p² bound (m²)", "meets"):
        table.add_column(name, justify="right")
    for option in sizing.options:
        b = option.bound
        var = "-" if math.isnan(option.variance_m2) else f"{option.variance_m2:.2f}"
        table.add_row(str(b.uavs), f"{b.revisit_s:.2f}", f"{b.variance0_m2:.3f}",
                      f"{b.bound:.4f}", var, "yes" if option.meets else "no")
    return table


def _config_record(config: BoundConfig) -> dict[str, object]:
    return {"targets": config.targets, "uav_speed_mps": config.uav_speed_mps,
            "target_speed_mps": config.target_speed_mps, "sigma_v_mps": config.sigma_v_mps,
            "meas_var_m2": config.meas_var_m2, "dt_s": config.dt_s, "bin_m": config.bin_m,
            "binning": config.binning}


def sizing_record(spec: MapSpec, bound_map: BoundMap, config: BoundConfig,
                  sizing: FleetSizing) -> dict[str, object]:
    """The JSON document ``--json`` writes."""
    return {
        "map": spec.describe(),
        "config": _config_record(config),
        "s_node_m": bound_map.s_node_m,
        "length_m": bound_map.length_m,
        "round_trip_s": bound_map.round_trip_s(config),
        "max_variance_m2": sizing.required_variance_m2,
        "required_entropy": sizing.required_entropy,
        "rows": [{"uavs": o.bound.uavs, "revisit_s": o.bound.revisit_s, "steps": o.bound.steps,
                  "variance0_m2": o.bound.variance0_m2, "bound": o.bound.bound,
                  "variance_bound_m2": finite_or_none(o.variance_m2), "meets": o.meets}
                 for o in sizing.options],
        "uavs": sizing.uavs,
    }


def _refuse_work(spec: MapSpec, chains: ChainGraph, config: BoundConfig, steps: float,
                 length_m: float) -> None:
    """Refuse, naming ``--map``, a map whose bound would not fit in memory or minutes:
    :func:`profile_refusal` for ``steps`` (the steps of one round trip), then the entropy sums
    of one UAV, ``steps`` variances × the bins within ±12 σ of the last one (or the map)."""
    reason = profile_refusal(chains, config.target_speed_mps, config.dt_s, steps)
    spread = config.sigma_v_mps * config.dt_s
    sigma = math.sqrt(config.meas_var_m2 + spread * spread * steps)
    cells = steps * min(length_m, 2.0 * WINDOW_SIGMAS * sigma) / config.bin_m
    if reason is None and cells > MAX_ENTROPY_CELLS:
        reason = (f"{steps:.3g} steps × {cells / max(steps, 1.0):.3g} bins are {cells:.3g} "
                  f"entropy terms per fleet size, above the {MAX_ENTROPY_CELLS:.3g} evaluated")
    if reason is not None:
        raise SearchtrackError(f"--map {spec.describe()}: {reason}; give a smaller map or a "
                               "larger --dt (or other speeds and noise)")


def _measure(spec: MapSpec, network: RoadNetwork, config: BoundConfig) -> BoundMap:
    """The map's terms, each step refused before it starts if it would not fit."""
    chains = chain_graph(network)
    _refuse_work(spec, chains, config, 0.0, network.total_length_m)
    sources = S_NODE_SOURCES if network.n_nodes > S_NODE_SOURCES else None
    bound_map = BoundMap(s_node(network, include_diagonal=config.include_diagonal,
                                sources=sources), network.total_length_m, chains)
    _refuse_work(spec, chains, config, bound_map.round_trip_s(config) / config.dt_s,
                 network.total_length_m)
    return bound_map


def fleet_size_command(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack fleet-size``: 0 when some fleet meets the requirement, 1 if none
    up to ``--max-uavs`` does, 130 on Ctrl-C (bad input raises, which the caller reports with
    status 2)."""
    out = None if args.json is None else output_file("--json", args.json)
    config = BoundConfig(targets=args.targets, uav_speed_mps=args.uav_speed,
                         target_speed_mps=args.target_speed, sigma_v_mps=args.sigma_v,
                         meas_var_m2=args.R, dt_s=args.dt, binning=args.binning)
    spread = args.sigma_v * args.dt
    if not 0.0 < spread * spread < math.inf:  # the variance a target gains per step (Eq. 32)
        raise SearchtrackError(f"--sigma-v {args.sigma_v:g} with --dt {args.dt:g}: σ_v·δ_t "
                               "must square to a positive finite variance (m²)")
    spec: MapSpec = args.map
    try:
        with stops_raise(), console.status(f"measuring {spec.describe()}"):
            network = spec.build()
            bound_map = _measure(spec, network, config)
            sizing = fleet_size(bound_map, config, max_variance_m2=args.max_variance,
                                max_uavs=args.max_uavs)
    except StopRequested:
        console.print(f"stopped after 0 fleet sizes, while measuring {escape(spec.describe())}")
        if out is not None:  # what was done: nothing
            nothing: dict[str, object] = {"map": spec.describe(), "rows": [], "uavs": None,
                                          "config": _config_record(config), "interrupted": True}
            written = write_text_atomic(out, json.dumps(nothing, indent=1) + "\n")
            console.print(f"wrote {written}")
        return 130
    try:
        with stops_raise():
            groups = ("" if stop_requested() else
                      f" in {len(subdivisions(bound_map.chains))} subdivisions")
    except StopRequested:
        groups = ""
    console.print(f"{escape(spec.describe())}: {network.n_nodes} nodes, "
                  f"{bound_map.length_m:.0f} m of road, {bound_map.chains.n_chains} directed "
                  f"chains{groups}, S_node {bound_map.s_node_m:.2f} m, round "
                  f"trip T {bound_map.round_trip_s(config):.2f} s for {config.targets} targets")
    console.print(sizing_table(sizing, f"entropy bound (Theorem 1), σ² ≤ {args.max_variance:g} "
                               f"m² ⇔ B_L ≤ {sizing.required_entropy:.4f} nats"))
    stopped = stop_requested()
    if stopped:
        console.print(f"stopped after {len(sizing.options)} fleet sizes")
    elif sizing.uavs is None:
        console.print(f"no fleet of up to {args.max_uavs} UAVs meets σ² ≤ {args.max_variance:g} "
                      "m²")
    else:
        many = sizing.uavs > 1
        console.print(f"[bold]{sizing.uavs} UAV{'s' if many else ''}[/] meet{'' if many else 's'} "
                      f"σ² ≤ {args.max_variance:g} m²")
    if out is not None:
        record = {**sizing_record(spec, bound_map, config, sizing), "interrupted": stopped}
        written = write_text_atomic(out, json.dumps(record, indent=1) + "\n")
        console.print(f"wrote {written}")
    if stopped:
        return 130
    return 0 if sizing.uavs is not None else 1


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the arguments of ``fleet-size`` to ``parser``."""
    parser.add_argument("--map", required=True, metavar="MAP", type=map_arg,
                        help=f"grid:RxC[:BLOCK] (BLOCK in m, default 100) or one of "
                        f"{', '.join(BUNDLED_MAPS)}")
    parser.add_argument("--targets", type=int_at_least(2), required=True, metavar="M",
                        help="number of targets (≥ 2)")
    parser.add_argument("--max-variance", type=positive_float, required=True, metavar="V",
                        help="required bound on a mode's positional variance (m²)")
    parser.add_argument("--uav-speed", type=positive_float, default=BoundConfig.uav_speed_mps,
                        metavar="MPS", help="UAV airspeed V_a (m/s, default "
                        f"{BoundConfig.uav_speed_mps:g})")
    parser.add_argument("--target-speed", type=positive_float,
                        default=BoundConfig.target_speed_mps, metavar="MPS",
                        help=f"target speed (m/s, default {BoundConfig.target_speed_mps:g})")
    parser.add_argument("--sigma-v", type=positive_float, default=BoundConfig.sigma_v_mps,
                        metavar="MPS", help="target velocity noise σ_v (m/s, default "
                        f"{BoundConfig.sigma_v_mps:g})")
    parser.add_argument("--R", type=positive_float, default=BoundConfig.meas_var_m2,
                        metavar="M2", help="measurement variance along the road (m², default "
                        f"{BoundConfig.meas_var_m2:g})")
    parser.add_argument("--dt", type=positive_float, default=BoundConfig.dt_s, metavar="S",
                        help=f"time step δ_t (s, default {BoundConfig.dt_s:g})")
    parser.add_argument("--binning", choices=BINNINGS, default=BoundConfig.binning,
                        help="Gaussian on 1 m bins: density at bin points as in Eq. 47 (default; "
                        "needs variances ≥ 0.25 m²) or bin probabilities")
    parser.add_argument("--max-uavs", type=int_in(1, MAX_FLEET), default=10, metavar="Q",
                        help="largest fleet to consider (default 10)")
    parser.add_argument("--json", default=None, metavar="OUT", help="write the table as JSON")
    parser.set_defaults(run=fleet_size_command)


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``fleet-size`` on the top-level subparsers."""
    p = add_group(sub, "fleet-size", description(__doc__))
    configure(p)


def run(argv: Sequence[str], console: Console | None = None) -> int:
    """Run ``fleet-size`` with its own parser (arguments after the subcommand name); the exit
    status as ``searchtrack fleet-size`` would give it (2 for bad input)."""
    parser = argparse.ArgumentParser(prog="searchtrack fleet-size")
    configure(parser)
    try:
        args = parser.parse_args(list(argv))
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else 2
    try:
        code: int = args.run(args, console or Console())
    except (SearchtrackError, ValueError) as exc:
        Console(stderr=True).print("[bold red]error:[/]", escape(str(exc)), soft_wrap=True)
        return 2
    return code
