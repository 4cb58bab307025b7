"""Trajectory tracking: NMPC / OSQP solve times and closed-loop quality on two courses.

    python benchmarks/trajectory.py solve     # NMPC option variants + OSQP, warm-started, N = 20
    python benchmarks/trajectory.py courses   # lawnmower + random-waypoint courses, all controllers
    python benchmarks/trajectory.py step      # NumPy vs CasADi model stepping
    python benchmarks/trajectory.py routes    # OPTW / potential-field road routes, paper 004 E7

solve: median / 95th-percentile warm-started solve along a closed-loop run (Dubins, i.e. the
unicycle at a constant 10 m/s, with 5 obstacles; fixed wing and 7-state UAV with 3), per CasADi
option variant, the real-time iteration (``ltv_mpc``, OSQP) and do-mpc on the same NLP
(``trajectory_dompc.py``), against the real-time targets: NMPC ≤ 10 ms median; the real-time
iteration ≤ 1 ms median, ≤ 2 ms p95 and ≤ 0.25× do-mpc's median. A linear solver Ipopt cannot
load (ma27 without HSL) is reported as unavailable.
courses: collisions, RMS tracking error, input effort, min clearance and fallback counts per
controller, with wind (1, −0.5) m/s and process noise; ``auto`` gets 50 ms per step. routes: the
same for a Dubins UAV (80 mph, 70 °/s) on an OPTW route and a potential-field mission track past
buildings, and for the 7-state UAV on 004's 3-D search waypoints (E7: 3 spheres, d_l = 6 m, wind
3 m/s). The run ends by checking that auto, NMPC and the real-time iteration never collided
(exit status 1 otherwise).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections.abc import Callable
from functools import partial

import numpy as np
import trajectory_dompc
from tables import table

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result
from searchtrack.models import SensorModel
from searchtrack.models.road_synthetic import grid_network
from searchtrack.models.vehicles import VehicleModel, fixed_wing, uav7, unicycle
from searchtrack.plan.trajectory import (
    ControlPlan,
    NmpcOptions,
    Obstacles,
    Reference,
    TrackingProblem,
    solve_ltv_mpc,
    solve_nmpc,
    waypoint_path,
)
from searchtrack.plan.trajectory.symbolic import step_function
from searchtrack.sim.flight.e7 import E7Setup, fly_e7
from searchtrack.sim.flight.loop import FlightConfig, FlightLog, fly
from searchtrack.sim.flight.routes import (
    fly_optw_route,
    fly_xy_path,
    plan_optw_route,
    road_obstacles,
    route_deviation_m,
    route_waypoints,
)
from searchtrack.sim.roads.mission import Mission
from searchtrack.sim.roads.scenario import GuidanceSpec, MapSpec, Scenario

Solver = Callable[[TrackingProblem], Result[ControlPlan]]




def square_course() -> tuple[Reference, Obstacles]:
    """A 100 m square flown at 10 m/s past five cylinders, two of them on the path."""
    return (waypoint_path([[0, 0], [100, 0], [100, 100], [0, 100]], 10.0),
            Obstacles(centers_m=np.array([[30, 2], [60, -3], [100, 40], [70, 100], [40, 95]],
                                         dtype=float),
                      radii_m=np.array([5, 4, 6, 5, 4], dtype=float)))


def course_3d(model: VehicleModel) -> tuple[np.ndarray, Reference, Obstacles]:
    """A climbing square with two cylinders and a sphere (NED for the 7-state UAV)."""
    up = -1.0 if model.name == "uav7" else 1.0
    speed = 15.0 if model.name == "uav7" else 12.0
    ref = waypoint_path([[0, 0, 20 * up], [100, 0, 30 * up], [100, 100, 30 * up],
                         [0, 100, 20 * up]], speed)
    obs = Obstacles(centers_m=np.array([[30, 2, 0], [60, -3, 25 * up], [100, 40, 0]]),
                    radii_m=np.array([5.0, 4.0, 6.0]), cylinder=np.array([True, False, True]))
    x0 = np.zeros(model.nx)
    x0[1], x0[2] = -5.0, 20.0 * up
    if model.name == "uav7":
        x0[3] = 15.0
    return x0, ref, obs


def timed_run(model: VehicleModel, x0: np.ndarray, ref: Reference, obs: Obstacles,
              solver: Solver, steps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """Warm-started receding-horizon run: wall and CPU ms per solve after 5 warm-up steps,
    iterations, fails; a failed step holds the input, a run that enters an obstacle stops."""
    x, warm, u = np.array(x0, dtype=float), None, None
    times, cpu, iters, fails, note = [], [], [], 0, ""
    lo, hi = np.asarray(model.state_lower), np.asarray(model.state_upper)
    for k in range(steps):
        if obs.clearance_m(model.position(x)[None, :])[0] <= 0.0:
            note += f" (crashed at step {k})"
            break
        problem = TrackingProblem(model, np.clip(x, lo, hi), ref, time_s=0.1 * k, obstacles=obs,
                                  horizon=20, dt_s=0.1, previous_input=u, warm=warm)
        c0 = time.process_time()
        result = solver(problem)
        cpu.append(time.process_time() - c0)
        times.append(result.runtime_s)
        iters.append(result.stats.get("iterations", result.stats.get("qp_rounds", 0.0)))
        if result.plan is None:
            fails += 1
            note = note or f" ({result.message.split(': ', 1)[-1][:28]})"
            warm = None
            u = np.asarray(model.nominal_input) if u is None else u
        else:
            warm, u = result.plan, result.plan.first_input
        x = model.step(x, model.clip_input(u), 0.1)
    return (np.asarray(times[5:]) * 1e3, np.asarray(cpu[5:]) * 1e3, np.asarray(iters[5:]),
            f"{fails}{note}")


def _cells(run: tuple[np.ndarray, np.ndarray, np.ndarray, str], target_ms: float | None
           ) -> list[str]:
    ms, cpu, it, fails = run
    median = float(np.median(ms))
    verdict = "-" if target_ms is None else ("PASS" if median <= target_ms else "FAIL")
    return [f"{median:.2f}", f"{np.percentile(ms, 95):.2f}", f"{np.median(cpu):.2f}",
            f"{np.median(it):.0f}", fails, "report" if target_ms is None else
            f"<= {target_ms:g}", verdict]


NMPC_TARGET_MS = 10.0  # real-time target of the full NMPC: median solve time (ms)
# the real-time iteration: median and 95th percentile (ms), and its median over do-mpc's
RTI_TARGET_MS, RTI_P95_MS, RTI_PEER_RATIO = 1.0, 2.0, 0.25

NMPC_VARIANTS: list[tuple[str, NmpcOptions]] = [
    ("ipopt exact, tol 1e-4, mu_init 1e-2 (default)", NmpcOptions()),
    ("ipopt exact, Ipopt defaults (tol 1e-6, mu_init 0.1)", NmpcOptions(tol=1e-6, mu_init=0.1)),
    ("ipopt exact, jit (gcc -O1)", NmpcOptions(jit=True)),
    ("ipopt exact, expand=False (MX)", NmpcOptions(expand=False)),
    ("ipopt exact, mu_strategy monotone", NmpcOptions(mu_strategy="monotone")),
    ("ipopt limited-memory Hessian", NmpcOptions(hessian="limited-memory")),
    ("ipopt linear_solver ma27", NmpcOptions(linear_solver="ma27")),
    ("sqpmethod + qrqp (first 20 steps only)", NmpcOptions(solver="sqpmethod", max_iter=20)),
    # sqpmethod + osqp is left out: with the exact, indefinite Hessian OSQP rejects the KKT
    # matrix ("not quasidefinite") on the first step and CasADi dumps the whole QP to stdout.
]


def dubins() -> VehicleModel:
    """The Dubins car of the solve targets: the unicycle at a constant 10 m/s, |ω| ≤ 1 rad/s."""
    return unicycle(speed_min_mps=10.0, speed_max_mps=10.0)


def linear_solver_missing(options: NmpcOptions) -> str | None:
    """Why Ipopt cannot use ``options.linear_solver`` (ma27 without HSL), else ``None``."""
    if options.solver != "ipopt" or options.linear_solver == "mumps":
        return None
    problem = TrackingProblem(dubins(), np.array([0.0, -3.0, 0.0]),
                              waypoint_path([[0, 0], [50, 0]], 10.0))
    try:
        solve_nmpc(problem, time_limit_s=1.0, options=options)
    except InvalidInputError:  # the build refuses a linear solver Ipopt cannot load
        return f"Ipopt cannot load {options.linear_solver} (no HSL library)"
    except RuntimeError as err:
        return str(err).strip().splitlines()[-1][:60]
    return None


def bench_solve(steps: int) -> None:
    """NMPC variants and the OSQP QP, warm-started, horizon 20, against the real-time targets."""
    ref, obs = square_course()
    start = np.array([0.0, -5.0, 0.0])
    rows = []
    model = dubins()
    for name, opts in NMPC_VARIANTS:
        def nmpc(p: TrackingProblem, o: NmpcOptions = opts) -> Result[ControlPlan]:
            return solve_nmpc(p, time_limit_s=0.5, options=o)
        missing = linear_solver_missing(opts)
        if missing is not None:
            rows.append([f"Dubins NMPC: {name}", "-", "-", "-", "-", "-", "-",
                         "unavailable: " + missing])
            continue
        n_steps = 20 if opts.solver == "sqpmethod" else steps
        try:
            cells = _cells(timed_run(model, start, ref, obs, nmpc, n_steps), NMPC_TARGET_MS)
        except RuntimeError as err:  # a CasADi plugin failing outright
            cells = ["-", "-", "-", "-", "-", "-",
                     "error: " + str(err).strip().splitlines()[-1][:40]]
        rows.append([f"Dubins NMPC: {name}", *cells])
    rti = timed_run(model, start, ref, obs, lambda p: solve_ltv_mpc(p, time_limit_s=0.5), steps)
    rows.append(["Dubins real-time iteration (ltv_mpc: OSQP, 1 QP/step)",
                 *_cells(rti, RTI_TARGET_MS)])
    missing = trajectory_dompc.available()
    peer = "Dubins do-mpc 5 (Ipopt, the same NLP without rate limits)"
    peer_ms = math.nan
    if missing is not None:
        rows.append([peer, "-", "-", "-", "-", "-", "-", "unavailable: " + missing])
    else:
        tracker = trajectory_dompc.DoMpcTracker(model, ref, obs)
        run = timed_run(model, start, ref, obs, tracker, steps)
        peer_ms = float(np.median(run[0]))
        rows.append([peer, *_cells(run, None)])
    flat = unicycle()
    for label, solve_one in (("NMPC (default)", partial(solve_nmpc, time_limit_s=0.5)),
                             ("LTV-MPC (OSQP)", partial(solve_ltv_mpc, time_limit_s=0.5))):
        rows.append([f"unicycle 5-15 m/s {label}",
                     *_cells(timed_run(flat, start, ref, obs, solve_one, steps), None)])
    for make in (fixed_wing, uav7):
        m = make()
        x0, ref3, obs3 = course_3d(m)
        for label, solver in (
                ("NMPC (default)", lambda p: solve_nmpc(p, time_limit_s=0.5)),
                ("NMPC (jit)", lambda p: solve_nmpc(p, time_limit_s=0.5,
                                                    options=NmpcOptions(jit=True))),
                ("LTV-MPC (OSQP)", lambda p: solve_ltv_mpc(p, time_limit_s=0.5))):
            rows.append([f"{m.name} {label}", *_cells(timed_run(m, x0, ref3, obs3, solver,
                                                                 steps), None)])
    print(f"\nWarm-started solve time, horizon 20, {steps} receding-horizon steps "
          "(Dubins/unicycle: 5 obstacles; 3-D models: 3); real-time targets")
    table(["controller / options", "median ms", "p95 ms", "median CPU ms", "median iters",
           "fails", "target ms", "verdict"], rows)
    median, p95 = float(np.median(rti[0])), float(np.percentile(rti[0], 95))
    ratio = median / peer_ms
    print(f"\nCHECK real-time iteration (auto's first stage), Dubins: median {median:.2f} ms "
          f"(<= {RTI_TARGET_MS:g}), p95 {p95:.2f} ms (<= {RTI_P95_MS:g}), {ratio:.2f} x do-mpc "
          f"(<= {RTI_PEER_RATIO:g}), {rti[3]} fails: " + (
              "PASS" if median <= RTI_TARGET_MS and p95 <= RTI_P95_MS and rti[3] == "0"
              and (math.isnan(ratio) or ratio <= RTI_PEER_RATIO) else "FAIL"))


def lawnmower() -> tuple[Reference, Obstacles]:
    """Four 120 m lanes 30 m apart, with obstacles on and beside the lanes."""
    pts = []
    for i in range(4):
        xs = (0.0, 120.0) if i % 2 == 0 else (120.0, 0.0)
        pts += [[xs[0], 30.0 * i], [xs[1], 30.0 * i]]
    obs = Obstacles(centers_m=np.array([[40, 1], [90, -2], [70, 31], [20, 58], [100, 62],
                                        [60, 90]], dtype=float),
                    radii_m=np.array([4, 3, 5, 4, 3, 4], dtype=float))
    return waypoint_path(pts, 10.0), obs


def random_course(seed: int) -> tuple[Reference, Obstacles]:
    """Seven random waypoints in a 150 m square and six random cylinders clear of them."""
    rng = np.random.default_rng(seed)
    pts = np.vstack([[0.0, 0.0], rng.uniform(0, 150, (6, 2))])
    centers: list[np.ndarray] = []
    while len(centers) < 6:
        c = rng.uniform(10, 140, 2)
        if np.min(np.linalg.norm(pts - c, axis=1)) > 12.0:
            centers.append(c)
    return waypoint_path(pts, 10.0), Obstacles(centers_m=np.array(centers),
                                               radii_m=rng.uniform(3, 6, 6))


FLIGHT_HEADER = ["course", "controller", "collisions", "RMS m", "effort", "min clear m",
                 "fallbacks", "answered nmpc/qp/cf", "no plan", "median ms", "wall s"]
BACKENDS = ("auto", "nmpc", "ltv_mpc", "closed_form")
CHECKED = ("auto", "nmpc", "ltv_mpc")   # the optimising controllers: never to collide


def flight_row(label: str, backend: str, log: FlightLog, wall_s: float) -> list[str]:
    """One table row of a closed-loop flight."""
    counts = "/".join(str(log.count(c)) for c in ("nmpc", "ltv_mpc", "closed_form"))
    return [label, backend, str(log.collisions), f"{log.rms_error_m:.2f}",
            f"{log.input_effort:.3f}", f"{log.min_clearance_m:.2f}", str(log.fallbacks), counts,
            str(log.count("none")), f"{1e3 * np.median(log.solve_s):.1f}", f"{wall_s:.1f}"]


def bench_courses(seeds: int, jit: bool) -> int:
    """Closed-loop comparison of the controllers on the two courses (and a 3-D one for uav7);
    returns the number of auto, NMPC and real-time-iteration flights that collided."""
    rows = []
    flat = unicycle()
    start = np.array([0.0, -3.0, 0.0])
    courses: list[tuple[str, VehicleModel, np.ndarray, Reference, Obstacles]] = [
        ("lawnmower", flat, start, *lawnmower())]
    courses += [(f"random #{s}", flat, start, *random_course(s)) for s in range(seeds)]
    big = uav7()
    courses.append(("uav7 3-D square", big, *course_3d(big)))
    options = NmpcOptions(jit=jit)
    crashed = 0
    for label, model, x0, ref, obs in courses:
        for backend in BACKENDS:
            cfg = FlightConfig(backend=backend, time_limit_s=0.05,
                               wind_mps=(1.0, -0.5, 0.0)[:model.n_wind],
                               process_noise=(0.05, 0.05, 0.005, 0, 0, 0, 0)[:model.nx],
                               nmpc_options=options)
            started = time.perf_counter()
            log = fly(model, x0, ref, obs, cfg, rng=np.random.default_rng(0))
            crashed += int(backend in CHECKED and log.collisions > 0)
            rows.append(flight_row(label, backend, log, time.perf_counter() - started))
    print("\nClosed loop, unicycle 5–15 m/s, |ω| ≤ 1 rad/s (uav7: 8–25 m/s), wind (1, −0.5) m/s, "
          f"noise, margin 1 m, 50 ms/step, NMPC jit={jit}")
    table(FLIGHT_HEADER, rows)
    return crashed


def cross_track(log: FlightLog, path: np.ndarray) -> str:
    """RMS distance (m) from the flown positions to the polyline ``path``."""
    return f"{np.sqrt(np.mean(route_deviation_m(log, path) ** 2)):.2f}"


def bench_routes(e7_steps: int, mission_s: float) -> int:
    """Road routes (OPTW, potential field) with the Dubins UAV and E7 with the 7-state UAV;
    returns the number of auto, NMPC and real-time-iteration flights that collided."""
    net = grid_network(6, 6, 100.0, 10.0)
    scores = np.random.default_rng(0).random(net.n_nodes) ** 4
    route = plan_optw_route(net, scores, 0, speed_mps=35.76, horizon_s=40.0, max_nodes=25)
    sensor = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=150.0, position_noise_m=5.0)
    scenario = Scenario("pf", MapSpec("grid", rows=6, cols=6, block_m=100.0), uav_count=1,
                        target_count=2, sensor=sensor, altitude_m=None, duration_s=mission_s,
                        seed=3, guidance=GuidanceSpec(strategy="search_and_loiter"))
    track = Mission(scenario).run().uav_xy_m[:, 0]
    starts = np.vstack([net.coords[route[0]], track[0]])
    buildings = road_obstacles(net, 6, radius_m=15.0, clearance_m=10.0, keep_clear_xy_m=starts,
                               keep_clear_m=60.0, rng=np.random.default_rng(1))
    rows, crashed = [], 0
    for label, along in ((f"OPTW route ({len(route)} nodes)", False), ("OPTW along roads", True)):
        legs = route_waypoints(net, route, along_roads=along)
        for backend in BACKENDS:
            started = time.perf_counter()
            log = fly_optw_route(net, route, obstacles=buildings, along_roads=along,
                                 config=FlightConfig(backend=backend, time_limit_s=0.05),
                                 rng=np.random.default_rng(0))
            crashed += int(backend in CHECKED and log.collisions > 0)
            rows.append([*flight_row(label, backend, log, time.perf_counter() - started),
                         cross_track(log, legs)])
    for backend in BACKENDS:
        started = time.perf_counter()
        log = fly_xy_path(track, limits=scenario.limits, obstacles=buildings,
                          config=FlightConfig(backend=backend, time_limit_s=0.05),
                          rng=np.random.default_rng(0))
        crashed += int(backend in CHECKED and log.collisions > 0)
        rows.append([*flight_row(f"potential field {mission_s:g} s", backend, log,
                                 time.perf_counter() - started),
                     cross_track(log, track)])
    setup = E7Setup(steps=e7_steps)
    for backend in BACKENDS:
        started = time.perf_counter()
        run = fly_e7(0, setup=setup, config=FlightConfig(backend=backend, time_limit_s=0.05))
        crashed += int(backend in CHECKED and run.flight.collisions > 0)
        rows.append([*flight_row(f"E7 uav7 {e7_steps} steps", backend, run.flight,
                                 time.perf_counter() - started),
                     cross_track(run.flight, run.reference.positions_m)])
    print(f"\nRoutes: Dubins UAV 35.8 m/s, 70°/s, on a 6 × 6 grid of 100 m blocks past "
          f"{buildings.k} buildings (calm air); E7: uav7, 3 spheres r = 5 m, wind (3, 0, 0) "
          f"m/s, d_l = 6 m; {run.targets_found}/12 targets found "
          f"({'all by step ' + str(run.all_found_step) if run.all_found_step else 'not all'})"
          "; 50 ms/step; cross-track to the route's polyline (E7: to the climb-limited "
          "reference)")
    table([*FLIGHT_HEADER, "cross-track RMS m"], rows)
    return crashed


def bench_step() -> None:
    """Cost of one RK4 step: NumPy namespace vs the CasADi function evaluated numerically."""
    rows = []
    for model in (unicycle(), fixed_wing(), uav7()):
        x = np.zeros(model.nx)
        if model.name == "uav7":
            x[3] = 15.0
        u = np.asarray(model.nominal_input)
        w = np.zeros(model.n_wind)
        f = step_function(model)
        reps = 2000
        t0 = time.perf_counter()
        for _ in range(reps):
            model.step(x, u, 0.1, w)
        t1 = time.perf_counter()
        for _ in range(reps):
            np.asarray(f(x, u, w, 0.1))
        t2 = time.perf_counter()
        batch = np.tile(x[:, None], (1, 1000))
        t3 = time.perf_counter()
        model.step(batch, np.tile(u[:, None], (1, 1000)), 0.1, w[:, None])
        t4 = time.perf_counter()
        rows.append([model.name, f"{(t1 - t0) / reps * 1e6:.1f}", f"{(t2 - t1) / reps * 1e6:.1f}",
                     f"{(t4 - t3) / 1000 * 1e6:.2f}"])
    print("\nOne RK4 step (µs)")
    table(["model", "NumPy", "CasADi Function", "NumPy batch of 1000 (per state)"], rows)


def main(argv: list[str] | None = None) -> int:
    """Parse the arguments, run the chosen benchmark; 1 if an NMPC flight collided."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=["solve", "courses", "step", "routes", "all"])
    parser.add_argument("--steps", type=int, default=150, help="solve: receding-horizon steps")
    parser.add_argument("--seeds", type=int, default=2, help="courses: random courses")
    parser.add_argument("--jit", action="store_true", help="courses: NMPC with jit=True")
    parser.add_argument("--e7-steps", type=int, default=200, help="routes: E7 planner steps")
    parser.add_argument("--mission-s", type=float, default=60.0,
                        help="routes: potential-field mission length (s)")
    args = parser.parse_args(argv)
    print("load average at start: {:.2f} {:.2f} {:.2f} (2 shared cores)".format(*os.getloadavg()))
    crashed, flown = 0, False
    if args.what in ("step", "all"):
        bench_step()
    if args.what in ("solve", "all"):
        bench_solve(args.steps)
    if args.what in ("courses", "all"):
        crashed += bench_courses(args.seeds, args.jit)
        flown = True
    if args.what in ("routes", "all"):
        crashed += bench_routes(args.e7_steps, args.mission_s)
        flown = True
    if flown:
        print(f"\nCHECK zero collisions for auto, NMPC and the real-time iteration on every "
              "course and route: "
              f"{'PASS' if crashed == 0 else f'FAIL ({crashed} flights collided)'}")
    return 1 if crashed else 0


if __name__ == "__main__":
    sys.exit(main())
