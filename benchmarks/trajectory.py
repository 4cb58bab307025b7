"""Trajectory tracking (issue 5): NMPC / OSQP solve times and closed-loop quality on two courses.

    python benchmarks/trajectory.py solve     # NMPC option variants + OSQP, warm-started, N = 20
    python benchmarks/trajectory.py courses   # lawnmower + random-waypoint courses, all controllers
    python benchmarks/trajectory.py step      # NumPy vs CasADi model stepping

solve: median / 95th-percentile warm-started solve along a closed-loop run (unicycle/Dubins with 5
obstacles; fixed wing and 7-state UAV with 3), per CasADi option variant, and the OSQP LTV-MPC.
courses: collisions, RMS tracking error, input effort, min clearance and fallback counts per
controller, with wind (1, −0.5) m/s and process noise; ``auto`` gets 50 ms per step.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable

import numpy as np

from searchtrack.models.vehicles import VehicleModel, fixed_wing, uav7, unicycle
from searchtrack.plan.result import Result
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
from searchtrack.sim.flight import FlightConfig, fly

Solver = Callable[[TrackingProblem], Result[ControlPlan]]


def table(header: list[str], rows: list[list[str]]) -> None:
    """Print an aligned text table."""
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    print("  ".join(h.rjust(w) for h, w in zip(header, widths, strict=True)))
    print("  ".join("-" * w for w in widths))
    for r in rows:
        print("  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)))
    sys.stdout.flush()


def square_course() -> tuple[Reference, Obstacles]:
    """A 100 m square flown at 10 m/s past five cylinders, two of them on the path."""
    return (waypoint_path([[0, 0], [100, 0], [100, 100], [0, 100]], 10.0),
            Obstacles(centers_m=[[30, 2], [60, -3], [100, 40], [70, 100], [40, 95]],
                      radii_m=[5, 4, 6, 5, 4]))


def course_3d(model: VehicleModel) -> tuple[np.ndarray, Reference, Obstacles]:
    """A climbing square with two cylinders and a sphere (NED for the 7-state UAV)."""
    up = -1.0 if model.name == "uav7" else 1.0
    speed = 15.0 if model.name == "uav7" else 12.0
    ref = waypoint_path([[0, 0, 20 * up], [100, 0, 30 * up], [100, 100, 30 * up],
                         [0, 100, 20 * up]], speed)
    obs = Obstacles(centers_m=[[30, 2, 0], [60, -3, 25 * up], [100, 40, 0]], radii_m=[5, 4, 6],
                    cylinder=np.array([True, False, True]))
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


def _cells(run: tuple[np.ndarray, np.ndarray, np.ndarray, str]) -> list[str]:
    ms, cpu, it, fails = run
    return [f"{np.median(ms):.2f}", f"{np.percentile(ms, 95):.2f}", f"{np.median(cpu):.2f}",
            f"{np.median(it):.0f}", fails]


NMPC_VARIANTS: list[tuple[str, NmpcOptions]] = [
    ("ipopt exact, tol 1e-4, mu_init 1e-2 (default)", NmpcOptions()),
    ("ipopt exact, Ipopt defaults (tol 1e-6, mu_init 0.1)", NmpcOptions(tol=1e-6, mu_init=0.1)),
    ("ipopt exact, jit (gcc -O1)", NmpcOptions(jit=True)),
    ("ipopt exact, expand=False (MX)", NmpcOptions(expand=False)),
    ("ipopt exact, mu_strategy monotone", NmpcOptions(mu_strategy="monotone")),
    ("ipopt limited-memory Hessian", NmpcOptions(hessian="limited-memory")),
    ("ipopt linear_solver ma27", NmpcOptions(linear_solver="ma27")),
    ("sqpmethod + qrqp (first 20 steps only)", NmpcOptions(solver="sqpmethod", max_iter=20)),
    ("sqpmethod + osqp (first 20 steps only)", NmpcOptions(solver="sqpmethod", qpsol="osqp",
                                                          max_iter=20)),
]


def bench_solve(steps: int) -> None:
    """NMPC variants and the OSQP QP, warm-started, horizon 20."""
    ref, obs = square_course()
    start = np.array([0.0, -5.0, 0.0])
    rows = []
    model = unicycle()
    for name, opts in NMPC_VARIANTS:
        def nmpc(p: TrackingProblem, o: NmpcOptions = opts) -> Result[ControlPlan]:
            return solve_nmpc(p, time_limit_s=0.5, options=o)
        n_steps = 20 if opts.solver == "sqpmethod" else steps
        try:
            cells = _cells(timed_run(model, start, ref, obs, nmpc, n_steps))
        except RuntimeError as err:  # a CasADi plugin failing outright
            cells = ["-", "-", "-", "-", "error: " + str(err).strip().splitlines()[-1][:40]]
        rows.append([f"unicycle NMPC: {name}", *cells])
    rows.append(["unicycle LTV-MPC (OSQP, 1 QP/step)", *_cells(timed_run(
        model, start, ref, obs, lambda p: solve_ltv_mpc(p, time_limit_s=0.5), steps))])
    for make in (fixed_wing, uav7):
        m = make()
        x0, ref3, obs3 = course_3d(m)
        for label, solver in (
                ("NMPC (default)", lambda p: solve_nmpc(p, time_limit_s=0.5)),
                ("NMPC (jit)", lambda p: solve_nmpc(p, time_limit_s=0.5,
                                                    options=NmpcOptions(jit=True))),
                ("LTV-MPC (OSQP)", lambda p: solve_ltv_mpc(p, time_limit_s=0.5))):
            rows.append([f"{m.name} {label}", *_cells(timed_run(m, x0, ref3, obs3, solver,
                                                                 steps))])
    print(f"\nWarm-started solve time, horizon 20, {steps} receding-horizon steps "
          "(unicycle: 5 obstacles; 3-D models: 3)")
    table(["controller / options", "median ms", "p95 ms", "median CPU ms", "median iters",
           "fails"], rows)


def lawnmower() -> tuple[Reference, Obstacles]:
    """Four 120 m lanes 30 m apart, with obstacles on and beside the lanes."""
    pts = []
    for i in range(4):
        xs = (0.0, 120.0) if i % 2 == 0 else (120.0, 0.0)
        pts += [[xs[0], 30.0 * i], [xs[1], 30.0 * i]]
    obs = Obstacles(centers_m=[[40, 1], [90, -2], [70, 31], [20, 58], [100, 62], [60, 90]],
                    radii_m=[4, 3, 5, 4, 3, 4])
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


def bench_courses(seeds: int, jit: bool) -> None:
    """Closed-loop comparison of the controllers on the two courses (and a 3-D one for uav7)."""
    rows = []
    flat = unicycle()
    start = np.array([0.0, -3.0, 0.0])
    courses: list[tuple[str, VehicleModel, np.ndarray, Reference, Obstacles]] = [
        ("lawnmower", flat, start, *lawnmower())]
    courses += [(f"random #{s}", flat, start, *random_course(s)) for s in range(seeds)]
    big = uav7()
    courses.append(("uav7 3-D square", big, *course_3d(big)))
    options = NmpcOptions(jit=jit)
    for label, model, x0, ref, obs in courses:
        for backend in ("auto", "nmpc", "ltv_mpc", "closed_form"):
            cfg = FlightConfig(backend=backend, time_limit_s=0.05,
                               wind_mps=(1.0, -0.5, 0.0)[:model.n_wind],
                               process_noise=(0.05, 0.05, 0.005, 0, 0, 0, 0)[:model.nx],
                               nmpc_options=options)
            started = time.perf_counter()
            log = fly(model, x0, ref, obs, cfg, rng=np.random.default_rng(0))
            counts = "/".join(str(log.count(c)) for c in ("nmpc", "ltv_mpc", "closed_form"))
            rows.append([label, backend, str(log.collisions), f"{log.rms_error_m:.2f}",
                         f"{log.input_effort:.3f}", f"{log.min_clearance_m:.2f}",
                         str(log.fallbacks), counts, str(log.count("none")),
                         f"{1e3 * np.median(log.solve_s):.1f}",
                         f"{time.perf_counter() - started:.1f}"])
    print("\nClosed loop, unicycle 5–15 m/s, |ω| ≤ 1 rad/s (uav7: 8–25 m/s), wind (1, −0.5) m/s, "
          f"noise, margin 1 m, 50 ms/step, NMPC jit={jit}")
    table(["course", "controller", "collisions", "RMS m", "effort", "min clear m", "fallbacks",
           "answered nmpc/qp/cf", "no plan", "median ms", "wall s"], rows)


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


def main(argv: list[str] | None = None) -> None:
    """Parse the arguments and run the chosen benchmark."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=["solve", "courses", "step", "all"])
    parser.add_argument("--steps", type=int, default=150)
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--jit", action="store_true", help="courses: NMPC with jit=True")
    args = parser.parse_args(argv)
    print("load average at start: {:.2f} {:.2f} {:.2f} (2 shared cores)".format(*os.getloadavg()))
    if args.what in ("step", "all"):
        bench_step()
    if args.what in ("solve", "all"):
        bench_solve(args.steps)
    if args.what in ("courses", "all"):
        bench_courses(args.seeds, args.jit)


if __name__ == "__main__":
    main()
