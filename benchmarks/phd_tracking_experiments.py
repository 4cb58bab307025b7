"""Paper 003 comparison: closed-loop PHD tracking with greedy END, greedy MI and a lawnmower.

``track``: 003's closed loop (:mod:`searchtrack.sim.particles.tracking`): greedy END vs
greedy MI vs lawnmower for R = 2, 4, 6 UAVs, GP (learned) vs random-walk filter motion, on
taxi-like traces; means over the second half of each episode and over seeds, printed as a Markdown
table with the paper's claim beside the measured numbers.

Run: ``.venv/bin/python benchmarks/phd_tracking_experiments.py track [--seeds N]`` (``--help`` on
the subcommand lists its options). Paper 004's search comparisons are
``benchmarks/phd_search_experiments.py``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tables import interval

from searchtrack.sim.particles.tracking import (
    TrackConfig,
    TrackEpisode,
    run_track_episode,
    taxi_world,
)

FloatArray = NDArray[np.float64]


CLAIMS_003 = {
    "end": "best overall: most targets tracked, lowest entropy/target; flies higher",
    "mi": "tracks the fewest targets; flies low (≈ LM altitude)",
    "lawnmower": "highest entropy/target; fixed altitude",
}


def track(args: argparse.Namespace) -> None:
    """003: END vs MI vs lawnmower for R = 2, 4, 6; GP vs random-walk filter motion."""
    robots = [int(r) for r in args.robots.split(",")]
    motions = args.motions.split(",")
    base = TrackConfig(horizon=args.horizon, steps=args.steps)
    print(f"closed loop, {args.seeds} seeds × {args.steps} steps of {base.dt_s:g} s, "
          f"{base.n_targets} taxis on a {base.area[0, 1]:g} m road grid, T = {args.horizon}; "
          "metrics averaged over the second half of each episode, ± = 95 % t-interval over "
          "seeds. 003 claim for motion: the GP tracks more targets with less uncertainty "
          "than the random walk.")
    print("| R | motion | planner | λ / n | entropy/target (nats) | in view | OSPA m (c = 50) | "
          "altitude m | planner ms/step | filter ms/step | paper 003 claim |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    worlds = {}
    for motion in motions:
        cfg = TrackConfig(motion=motion, horizon=args.horizon, steps=args.steps)  # type: ignore[arg-type]
        worlds[motion] = [taxi_world(cfg, seed) for seed in range(args.seeds)]
    for r in robots:
        for motion in motions:
            for planner in ("end", "mi", "lawnmower"):
                t0 = time.perf_counter()
                cfg = TrackConfig(planner=planner, motion=motion,  # type: ignore[arg-type]
                                  robots=r, horizon=args.horizon, steps=args.steps)
                eps: list[TrackEpisode] = [run_track_episode(cfg, worlds[motion][seed], seed)
                                           for seed in range(args.seeds)]
                cells = []
                for name, fmt in (("count_ratio", ".2f"), ("entropy", ".2f"),
                                  ("in_view", ".2f"), ("ospa_m", ".1f"), ("altitude_m", ".0f")):
                    mean, half = interval(np.array([e.tail_mean(name) for e in eps]))
                    cells.append(f"{mean:{fmt}} ± {half:{fmt}}")
                plan = np.mean([e.planner_ms for e in eps])
                filt = np.mean([e.filter_ms for e in eps])
                print(f"| {r} | {motion} | {planner} | {' | '.join(cells)} | {plan:.1f} | "
                      f"{filt:.1f} | {CLAIMS_003[planner]} |", flush=True)
                print(f"<!-- R{r} {motion} {planner}: {time.perf_counter() - t0:.1f} s -->",
                      file=sys.stderr)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("track", help=track.__doc__)
    p.add_argument("--seeds", type=int, default=3)
    p.add_argument("--steps", type=int, default=60)
    p.add_argument("--horizon", type=int, default=2, help="T, steps per action")
    p.add_argument("--robots", default="2,4,6")
    p.add_argument("--motions", default="gp,random_walk")
    p.set_defaults(func=track)
    args = parser.parse_args()
    args.func(args)


if __name__ == "__main__":
    main()
