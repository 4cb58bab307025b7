"""``searchtrack radio simulate|track|mission``: radio-tagged objects tracked before detection
(paper 002, Nguyen et al.).

``simulate`` flies the straight sweep over a scenario and records every interval's spectrogram
(RUN.npz, the truth written apart); ``track`` runs the TBD-LMB or the detection-then-track
filter over a recorded run (EST.json); ``mission`` flies the closed loop (filter + planner) and
writes its log, the map and the OSPA-against-time figures. File formats:
:mod:`searchtrack.sim.radio.run` and :mod:`searchtrack.sim.radio.track_job`.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING

from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

from searchtrack.cli import export
from searchtrack.cli.common import add_group, description, float_in, int_at_least, seed_arg
from searchtrack.cli.kernels import ready_kernels
from searchtrack.cli.output import output_dir, output_file
from searchtrack.core.errors import InvalidInputError
from searchtrack.models.radio.calibration import CALIBRATIONS
from searchtrack.models.radio.signal import MAX_NOISE_VAR_V2
from searchtrack.plan.radio import RadioPlanSettings
from searchtrack.plan.radio.problem import MAX_SPREAD_INFLATION
from searchtrack.sim.kernels import RADIO_KERNELS
from searchtrack.sim.radio.config import (
    FILTERS,
    MAX_ROUGHENING_M,
    MEASUREMENTS,
    PLAN_BACKENDS,
    PLANNERS,
    RadioMissionConfig,
)

if TYPE_CHECKING:
    from searchtrack.models.radio import RadioScenario

#: Largest ``--noise`` (V): the root of the largest noise variance a signal takes.
MAX_NOISE_SIGMA_V = math.sqrt(MAX_NOISE_VAR_V2)

#: ``--noise``: a standard deviation in ``(0, MAX_NOISE_SIGMA_V]`` volts.
_noise_sigma = float_in(0.0, MAX_NOISE_SIGMA_V, low_open=True, unit=" V")
#: ``--explore``: an existence in ``[0, 1)``.
_explore = float_in(0.0, 1.0, high_open=True)
#: ``--spread-inflation``: a multiple of the spread in ``[0, MAX_SPREAD_INFLATION]``.
_spread_inflation = float_in(0.0, MAX_SPREAD_INFLATION)
#: ``--roughening``: a floor in ``[0, MAX_ROUGHENING_M]`` metres.
_roughening = float_in(0.0, MAX_ROUGHENING_M, unit=" m")

#: The defaults of the options: a mission's and its planner's settings (the dataclasses' field
#: defaults, read from the classes so that no filter module is loaded).
MISSION, PLAN = RadioMissionConfig, RadioPlanSettings



def _particles(args: argparse.Namespace) -> int:
    """``--particles``, or :class:`InvalidInputError` naming it above the filter's limit."""
    from searchtrack.estimate.radio.filter import MAX_PARTICLES_PER_LABEL

    n: int = args.particles
    if n > MAX_PARTICLES_PER_LABEL:
        raise InvalidInputError("--particles", n,
                                f"must be an integer in [10, {MAX_PARTICLES_PER_LABEL}]")
    return n


def _scenario(args: argparse.Namespace) -> RadioScenario:
    import dataclasses

    from searchtrack.models.radio import RadioScenario
    from searchtrack.models.radio.calibration import calibrated

    scenario = RadioScenario.from_toml(args.scenario)
    if getattr(args, "noise", None) is not None:
        scenario = dataclasses.replace(scenario, signal=scenario.signal.with_noise(args.noise**2))
    if getattr(args, "calibration", None) is not None:
        scenario = dataclasses.replace(scenario,
                                       signal=calibrated(scenario.signal, args.calibration))
    return scenario


def _range_note(scenario: RadioScenario) -> str:
    """The calibration in words: its gain and the tags' range at 0 dB per-cell SNR."""
    from searchtrack.models.radio.calibration import zero_db_range_m

    reach = zero_db_range_m(scenario.signal)
    return (f"calibration gain {scenario.signal.calibration_gain_db:g} dB: a tag ahead reaches "
            f"0 dB per-cell SNR at {reach.min():.0f}–{reach.max():.0f} m")


def _bar(console: Console, what: str) -> Progress:
    return Progress(TextColumn(what), BarColumn(), TextColumn("{task.completed}/{task.total} s"),
                    TimeElapsedColumn(), console=console, transient=True)


def simulate(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack radio simulate``."""
    from searchtrack.core.interrupt import stop_requested
    from searchtrack.sim.radio.run import check_run_size, simulate_run, write_run, write_truth

    out = output_file("--out", args.out)
    truth_out = output_file("--truth", args.truth) if args.truth else None
    scenario = _scenario(args)
    check_run_size(scenario, source=str(args.scenario))
    run, truth = simulate_run(scenario, args.seed, measurement=args.measurement)
    if stop_requested() and not run.n_steps:
        console.print("no interval simulated before the interrupt: nothing written")
        return 0
    write_run(run, out)
    shown = f"{run.n_steps} intervals of {scenario.signal.frames}×{scenario.signal.fft_size} " \
            f"frames, {scenario.signal.n_labels} tags; wrote {out}"
    if truth_out is not None:
        write_truth(truth, truth_out)
        shown += f", {truth_out} (the truth)"
    console.print(escape(shown))
    return 0


def track(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack radio track``."""
    from searchtrack.sim.radio.run import read_run
    from searchtrack.sim.radio.track_job import run_radio_track, write_radio_estimates

    particles = _particles(args)
    out = output_file("--out", args.out)
    run = read_run(args.run_file)
    seed = run.seed if args.seed is None else args.seed
    ready_kernels(console, (RADIO_KERNELS,))
    with _bar(console, f"{args.filter} filter") as bar:
        task = bar.add_task("filter", total=run.n_steps)
        result = run_radio_track(run, args.filter, particles, seed,
                                 lambda done, _n: bar.update(task, completed=done))
    write_radio_estimates(result, out)
    final = (f", {len(result.estimates[-1])} objects at the end (mean cardinality "
             f"{result.cardinality[-1]:.2f})" if result.steps else "")
    console.print(escape(f"{result.steps} of {run.n_steps} intervals, {args.filter.upper()} "
                         f"with {args.particles} particles per label, "
                         f"{result.ms_per_step:.1f} ms/step{final}; wrote {out}"))
    return 0


def mission(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack radio mission``."""
    from searchtrack.core.files import write_text_atomic
    from searchtrack.sim.radio.figures import plot_radio_map, plot_radio_ospa
    from searchtrack.sim.radio.mission import run_radio_mission

    particles = _particles(args)
    folder = output_dir("--out", args.out)
    exports = export.export_dir(args)
    export.require_frame(args, None)   # the radio scenario is in a local frame
    scenario = _scenario(args)
    plan = RadioPlanSettings(horizon=args.horizon, plan_particles=args.plan_particles,
                             r_min_m=args.r_min, p_void_min=args.p_void,
                             spread_inflation=args.spread_inflation,
                             explore_existence=args.explore)
    config = RadioMissionConfig(filter=args.filter, planner=args.planner, backend=args.backend,
                                particles_per_label=particles, plan=plan,
                                measurement=args.measurement, keep_out=args.keep_out,
                                replan_on_breach=args.replan_on_breach,
                                temper_correlated=not args.untempered,
                                roughening_m=args.roughening)
    ready_kernels(console, (RADIO_KERNELS,))
    with _bar(console, f"{args.filter} + {args.planner}") as bar:
        task = bar.add_task("mission", total=scenario.n_steps)
        log = run_radio_mission(scenario, config, args.seed,
                                lambda done, _n: bar.update(task, completed=done))
    written = [write_text_atomic(folder / "mission.json", json.dumps(log.to_json()) + "\n")]
    if log.steps:
        written += [plot_radio_map(log, folder / "map.png"),
                    plot_radio_ospa(log, folder / "ospa.png")]
    total, loc, card = log.mean_ospa()
    plans = ", ".join(f"{k} {v}" for k, v in sorted(log.plan_status.items()))
    if log.breach_replans:
        plans += f" ({log.breach_replans} early, on a breach)"
    console.print(escape(_range_note(scenario)))
    console.print(escape(
        f"{log.steps} of {scenario.n_steps} s: mean OSPA {total:.1f} m (localisation "
        f"{loc:.1f}, cardinality {card:.1f}); cardinality within 0.5 of the truth "
        f"{100 * log.cardinality_hit_fraction():.0f} % of seconds; objects detected "
        f"{log.objects_detected()} of {len(scenario.tags)}; unsafe "
        f"{100 * log.unsafe_fraction():.1f} % of steps; filter {log.filter_ms:.1f} ms/step; "
        f"plans: {plans}"))
    console.print(escape("wrote " + ", ".join(str(Path(p)) for p in written)))
    if exports is not None and log.steps:
        from searchtrack.sim.export.radio_files import radio_mission_files

        frame = export.geo_frame(args, None, export_altitude(args, scenario))
        export.write_files(exports, radio_mission_files(log, frame), console)
    return 0


def export_altitude(args: argparse.Namespace, scenario: RadioScenario) -> float:
    """The altitude an exported radio mission flies at (m): ``--altitude``, else the scenario's
    own, the height its UAV flies above the tags (``[signal] height_difference_m``), else (a
    scenario at the tags' height) :data:`~searchtrack.cli.export.DEFAULT_ALTITUDE_M`."""
    given: float | None = args.altitude
    return given or scenario.signal.height_difference_m or export.DEFAULT_ALTITUDE_M


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--noise", type=_noise_sigma, default=None, metavar="SIGMA_V",
                   help="receiver noise standard deviation σ_η in volts (Σ_η = σ_η²; at most "
                        f"{MAX_NOISE_SIGMA_V:g}; default: the scenario's)")
    p.add_argument("--calibration", choices=tuple(CALIBRATIONS), default=None,
                   help="the signal model's calibration: " + "; ".join(
                       f"{name}, {cal.about}" for name, cal in CALIBRATIONS.items())
                   + " (default: the scenario's)")
    direct, windows = (f"{m}, default" if m == MISSION.measurement else m for m in MEASUREMENTS)
    p.add_argument("--measurement", choices=MEASUREMENTS, default=MISSION.measurement,
                   help=f"simulate the spectrogram directly ({direct}) or from time-domain "
                        f"windows ({windows})")


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``radio simulate|track|mission`` on the top-level subparsers."""
    radio = add_group(sub, "radio", description(__doc__))
    rsub = radio.add_subparsers(dest="command", required=True)
    p_sim = rsub.add_parser("simulate", help="record a straight-sweep run's spectrograms")
    p_sim.add_argument("scenario", metavar="SCENARIO.toml",
                       help="radio scenario (e.g. searchtrack/data/scenarios/radio_paper.toml)")
    p_sim.add_argument("--seed", type=seed_arg, default=0, help="random seed (default 0)")
    p_sim.add_argument("--out", required=True, metavar="RUN.npz",
                       help="where to write the spectrograms and poses")
    p_sim.add_argument("--truth", default=None, metavar="TRUTH.json",
                       help="also write the truth (kept out of RUN.npz)")
    _common(p_sim)
    p_sim.set_defaults(run=simulate)
    p_track = rsub.add_parser("track", help="filter a recorded run")
    p_track.add_argument("run_file", metavar="RUN.npz",
                         help="a run written by radio simulate")
    tbd, dtt = FILTERS
    p_track.add_argument("--filter", choices=FILTERS, default=MISSION.filter,
                         help=f"{tbd}: track before detect on the raw STFT; {dtt}: detect, then "
                         f"track (default {MISSION.filter})")
    p_track.add_argument("--out", required=True, metavar="EST.json",
                         help="where to write the estimates")
    p_track.add_argument("--particles", type=int_at_least(10),
                         default=MISSION.particles_per_label, metavar="N",
                         help=f"particles per label (default {MISSION.particles_per_label}, "
                         "the paper's)")
    p_track.add_argument("--seed", type=seed_arg, default=None,
                         help="filter seed (default: the run's)")
    p_track.set_defaults(run=track)
    p_mis = rsub.add_parser("mission", help="fly the closed loop: filter + planner")
    p_mis.add_argument("scenario", metavar="SCENARIO.toml",
                       help="radio scenario (e.g. searchtrack/data/scenarios/radio_paper.toml)")
    p_mis.add_argument("--filter", choices=FILTERS, default=MISSION.filter,
                       help=f"{tbd} or {dtt}, as in radio track (default {MISSION.filter})")
    p_mis.add_argument("--planner", choices=PLANNERS, default=MISSION.planner,
                       help="reward: Rényi or Cauchy–Schwarz divergence, or a straight sweep "
                       f"(default {MISSION.planner})")
    p_mis.add_argument("--backend", default=MISSION.backend, choices=PLAN_BACKENDS,
                       help=f"planning backend (default {MISSION.backend})")
    p_mis.add_argument("--particles", type=int_at_least(10),
                       default=MISSION.particles_per_label, metavar="N",
                       help=f"filter particles per label (default {MISSION.particles_per_label})")
    p_mis.add_argument("--plan-particles", type=int_at_least(10), default=PLAN.plan_particles,
                       metavar="N", help="particles per label the planner draws (default "
                       f"{PLAN.plan_particles})")
    p_mis.add_argument("--horizon", type=int_at_least(1), default=PLAN.horizon, metavar="H",
                       help=f"look-ahead planning intervals (default {PLAN.horizon})")
    p_mis.add_argument("--r-min", type=float, default=PLAN.r_min_m, metavar="M",
                       help=f"keep-out radius r_min of the void constraint (default "
                       f"{PLAN.r_min_m:g} m)")
    p_mis.add_argument("--p-void", type=float, default=PLAN.p_void_min, metavar="P",
                       help=f"least void probability P_vmin (default {PLAN.p_void_min:g})")
    p_mis.add_argument("--spread-inflation", type=_spread_inflation, default=PLAN.spread_inflation,
                       metavar="K", help="keep each object's void disc r_min + K times its "
                       f"estimate's spread away (default {PLAN.spread_inflation:g}: r_min alone)")
    p_mis.add_argument("--replan-on-breach", action="store_true",
                       help="plan again as soon as a measurement shows the void constraint broken "
                       "ahead, not only every planning interval")
    p_mis.add_argument("--explore", type=_explore, default=PLAN.explore_existence, metavar="R",
                       help="existence the reward gives a tag not heard yet, in [0, 1): how much "
                       "finding tags weighs against tracking those found; 0 is the paper's "
                       f"reward (default {PLAN.explore_existence:g})")
    p_mis.add_argument("--keep-out", action="store_true",
                       help="also keep r_min from every estimate in the flown trajectory")
    p_mis.add_argument("--roughening", type=_roughening, default=MISSION.roughening_m, metavar="M",
                       help="jitter the filter's particles by M metres (σ per axis) after each "
                       "resampling, so a cloud that collapsed on one point can follow its "
                       f"object again (default {MISSION.roughening_m:g}: none, the paper's)")
    p_mis.add_argument("--untempered", action="store_true",
                       help="with --measurement time, read the correlated bins as independent "
                       "evidence (eq. 22 as printed) instead of tempering the TBD likelihood")
    p_mis.add_argument("--seed", type=seed_arg, default=0, help="random seed (default 0)")
    p_mis.add_argument("--out", required=True, metavar="DIR",
                       help="folder for mission.json, map.png and ospa.png")
    _common(p_mis)
    export.add_arguments(p_mis, altitude_m=None,
                         own_altitude="the scenario's height of the UAV above the tags, "
                                      "[signal] height_difference_m")
    p_mis.set_defaults(run=mission)
