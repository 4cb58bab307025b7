"""``searchtrack mission run``: fly a scenario, print a summary, write JSON, PNG figures and the
replay page; ``searchtrack mission view``: the replay page of a written mission.json."""

from __future__ import annotations

import argparse
import dataclasses
import json
import threading
import time
from pathlib import Path

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from searchtrack.cli import export
from searchtrack.cli.common import add_group, positive_float, seed_arg
from searchtrack.cli.kernels import ready_kernels
from searchtrack.cli.output import OutputError, output_dir, output_file
from searchtrack.core.files import write_text_atomic
from searchtrack.core.interrupt import stop_requested
from searchtrack.sim.figure_style import pyplot
from searchtrack.sim.kernels import road_mission_kernels
from searchtrack.sim.roads.figures import plot_map, plot_moc
from searchtrack.sim.roads.mission import Mission
from searchtrack.sim.roads.record import PHASES, MissionLog
from searchtrack.sim.roads.scenario_file import load_scenario


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f} %"


def summary_table(log: MissionLog, wall_s: float) -> Table:
    """The end-of-mission summary."""
    sc, s = log.scenario, log.score
    table = Table(title=f"{sc.name}: {sc.guidance.strategy} on {sc.map.describe()} "
                  f"({log.network.n_nodes} nodes), {sc.uav_count} UAVs, {sc.target_count} "
                  f"targets", show_header=False)
    rows = [
        ("simulated", f"{log.time_s[-1]:.1f} s in {s.steps} steps ({wall_s:.1f} s wall)"),
        ("targets detected", f"{s.detected} / {s.targets}"),
        ("time to first detection", "-" if s.time_to_first_detection_s is None
         else f"{s.time_to_first_detection_s:.1f} s"),
        ("time to detect all", "-" if s.time_to_detect_all_s is None
         else f"{s.time_to_detect_all_s:.1f} s"),
        ("MOC mean / final", f"{_pct(s.moc_mean)} / {_pct(s.moc_final)}"),
        ("PVT (NVT, NST)", f"{_pct(s.pvt)} ({s.nvt}, {s.nst})"),
        ("PVA (NVA, NFA)", f"{_pct(s.pva)} ({s.nva}, {s.nfa})"),
        ("trackers born", str(len(log.births))),
    ]
    if s.steps:
        step = log.step_ms
        rows.append(("step ms median / p95",
                     f"{float(sorted(step)[len(step) // 2]):.1f} / "
                     f"{float(sorted(step)[int(0.95 * (len(step) - 1))]):.1f}"))
        means = log.phase_ms.mean(axis=0)
        rows.append(("phase ms (mean)", ", ".join(f"{p} {m:.1f}" for p, m in
                                                  zip(PHASES, means, strict=True))))
    for key, value in rows:
        table.add_row(key, value)
    return table


def run_mission(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack mission run``."""
    from searchtrack.sim.roads.replay_page import write_replay  # plotly: only when a page is drawn

    scenario = load_scenario(Path(args.scenario))
    if args.seed is not None:
        scenario = dataclasses.replace(scenario, seed=args.seed)
    if args.duration is not None:
        scenario = dataclasses.replace(scenario, duration_s=args.duration)
    out = output_dir("--out", args.out)
    exports = export.export_dir(args)
    ready_kernels(console, road_mission_kernels())
    with console.status(f"building {scenario.map.describe()}"):
        mission = Mission(scenario)
    export.require_frame(args, mission.world.network.projection)   # the map built, not flown
    # matplotlib's import overlaps the flight instead of delaying the figures after it, or
    # after Ctrl-C
    threading.Thread(target=pyplot, name="searchtrack-pyplot", daemon=True).start()
    started = time.perf_counter()
    with Progress(TextColumn("{task.description}"), BarColumn(),
                  TextColumn("{task.completed}/{task.total} steps"), TimeElapsedColumn(),
                  console=console, transient=True) as bar:
        task = bar.add_task(f"flying {scenario.name}", total=scenario.n_steps)
        log = mission.run(lambda done, _total: bar.update(task, completed=done))
    wall = time.perf_counter() - started
    if not log.score.steps:
        console.print("no step flown: nothing to write")
        return 0
    console.print(summary_table(log, wall))
    record = log.to_json()
    record["summary"]["wall_s"] = round(wall, 3)
    record["summary"]["interrupted"] = stop_requested()
    written = [write_text_atomic(out / "mission.json", json.dumps(record) + "\n"),
               plot_map(log, out / "map.png"), plot_moc(log, out / "moc.png")]
    with console.status("writing the replay page"):
        written.append(write_replay(record, out / "replay.html", source=written[0]))
    console.print("wrote " + ", ".join(str(p) for p in written))
    if exports is not None:
        from searchtrack.sim.export.plans import road_mission_files

        altitude = args.altitude or scenario.altitude_m or export.DEFAULT_ALTITUDE_M
        frame = export.geo_frame(args, log.network.projection, altitude)
        export.write_files(exports, road_mission_files(log, frame,
                                                       scenario.limits.speed_max_mps), console)
    return 0


def view_mission(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack mission view``: MISSION.json's replay page, by default
    ``replay.html`` beside it."""
    from searchtrack.sim.roads.replay_page import load_record, write_replay

    source = Path(args.mission)
    out = output_file("--out", args.out if args.out is not None
                      else source.with_name("replay.html"))
    if out.exists() and source.exists() and out.resolve() == source.resolve():
        raise OutputError("--out", out, "is the mission record itself; give another file")
    with console.status(f"drawing {source}"):
        written = write_replay(load_record(source), out, source=source)
    console.print(f"wrote {written}")
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``mission run`` and ``mission view`` on the top-level subparsers."""
    mission = add_group(sub, "mission")
    msub = mission.add_subparsers(dest="command", required=True)
    p_run = msub.add_parser("run", help="fly a TOML scenario; write JSON, PNG figures and "
                            "the replay page")
    p_run.add_argument("scenario", help="scenario TOML file")
    p_run.add_argument("--out", default="out/mission", metavar="DIR",
                       help="output directory (default: out/mission)")
    p_run.add_argument("--seed", type=seed_arg, default=None, help="override the scenario's seed")
    p_run.add_argument("--duration", type=positive_float, default=None, metavar="S",
                       help="override the scenario's duration (s)")
    export.add_arguments(p_run, altitude_m=None)
    p_run.set_defaults(run=run_mission)
    p_view = msub.add_parser("view", help="write the offline replay page (HTML) of a "
                             "mission.json")
    p_view.add_argument("mission", metavar="MISSION.json",
                        help="the mission.json that `searchtrack mission run` wrote")
    p_view.add_argument("--out", default=None, metavar="HTML",
                        help="page to write (default: replay.html beside MISSION.json)")
    p_view.set_defaults(run=view_mission)
