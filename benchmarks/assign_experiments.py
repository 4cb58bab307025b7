"""Short, idealised reproduction of paper 004's search comparison (no filter in the loop).

12 static targets uniform in the 280 m cube ``[−20, 260]³``; at each step the UAV senses once with
004's exponential field of view (G = 0.98, F = 25 m, printed non-squared norm) and every target is
detected with probability π; a target counts as found at its first detection (perfect
localisation: the SMC-PHD filter and the found-target logic are left out, so only the exploration
part of the planner is exercised). Planners: the receding-horizon exploration planner (τ = 1, 2, 3,
12 m lattice moves, refinement off) and the 3-D lawnmower (48 m line and layer spacing, 12 m
steps). Reports the steps to find all 12 targets (mean with a 95 % t-interval over seeds) and the
planner's time per step.

Run: ``.venv/bin/python benchmarks/assign_experiments.py [--seeds 10] [--max-steps 900]``
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from searchtrack.models.range_sensor import RangeBearingElevationSensor
from searchtrack.plan.assign.exploration import ExplorationBonus
from searchtrack.plan.search.lawnmower import lawnmower_3d
from searchtrack.plan.search.receding import RecedingConfig, plan_search_step

FloatArray = NDArray[np.float64]
BOX = np.array([[-20.0, 260.0]] * 3)
SENSOR = RangeBearingElevationSensor(gain=0.98, fov_m=25.0, sigma=1.0)


def run(planner: str, seed: int, max_steps: int, resolution_m: float) -> tuple[int, float]:
    """Steps until all targets are found (``max_steps + 1`` if not) and planner ms per step."""
    rng = np.random.default_rng(seed)
    targets = rng.uniform(BOX[:, 0], BOX[:, 1], size=(12, 3))
    found = np.zeros(12, dtype=bool)
    position = np.zeros(3)
    bonus = ExplorationBonus(BOX, resolution_m)
    path = lawnmower_3d(BOX, 48.0, 48.0, 12.0) if planner == "lawnmower" else None
    tau = int(planner[-1]) if planner.startswith("tau") else 1
    config = RecedingConfig(step_m=12.0, horizon=tau, refinement="none")
    spent = 0.0
    for k in range(max_steps):
        pd = SENSOR.detection_probability(position, targets)
        found |= rng.random(12) < pd
        if found.all():
            return k + 1, 1e3 * spent / max(k, 1)
        t0 = time.perf_counter()
        if path is not None:
            position = path[min(k + 1, len(path) - 1)]
        else:
            bonus.update(SENSOR, position)
            position = plan_search_step(position, BOX, bonus, SENSOR, config).waypoint
        spent += time.perf_counter() - t0
    return max_steps + 1, 1e3 * spent / max_steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--max-steps", type=int, default=900)
    parser.add_argument("--resolution", type=float, default=10.0, help="ι grid spacing (m)")
    args = parser.parse_args()
    print(f"lawnmower length: {len(lawnmower_3d(BOX, 48.0, 48.0, 12.0))} waypoints "
          "(paper: 812 steps)")
    print("\n| planner | steps to find 12 (mean ± 95 % CI) | min | max | not finished | "
          "planner ms/step |")
    print("|---|---|---|---|---|---|")
    for planner in ("tau1", "tau2", "tau3", "lawnmower"):
        results = [run(planner, seed, args.max_steps, args.resolution)
                   for seed in range(args.seeds)]
        steps = np.array([r[0] for r in results], dtype=float)
        ms = float(np.mean([r[1] for r in results]))
        half = stats.t.ppf(0.975, len(steps) - 1) * steps.std(ddof=1) / np.sqrt(len(steps)) \
            if len(steps) > 1 else float("nan")
        print(f"| {planner} | {steps.mean():.0f} ± {half:.0f} | {steps.min():.0f} | "
              f"{steps.max():.0f} | {int(np.sum(steps > args.max_steps))} | {ms:.2f} |")


if __name__ == "__main__":
    main()
