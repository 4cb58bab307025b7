"""Campaign runner overhead: a 40-run campaign serially and on a 2-process LocalCluster.

    python benchmarks/campaign.py [--experiment toy|mission] [--runs 40] [--sleep 0.25]
                                  [--workers 2]

``toy``: each run sleeps ``--sleep`` seconds. ``mission``: each run is a 60-s track-mode road
mission on the 6 × 6 grid (3 UAVs, 4 targets; about 0.5 s of work), so the workers also pay
their imports and map build. Columns: runs, wall time (s, cluster start-up included, and
without it), speed-up over serial, and the scheduling + database overhead per run (ms) =
(wall − Σ run time / workers) / runs, with and without the cluster start-up (columns marked *).
The cluster start-up is the workers' process start; their imports and shared inputs are paid
inside their first run.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from tables import table

from searchtrack.sim.campaigns.runner import CampaignSummary, run_campaign
from searchtrack.sim.campaigns.spec import CampaignSpec


def _spec(experiment: str, runs: int, sleep_s: float) -> CampaignSpec:
    if experiment == "toy":
        return CampaignSpec("bench", "toy", {"sleep_s": sleep_s}, {"value": (1.0,)},
                            tuple(range(runs)))
    return CampaignSpec("bench", "mission", {"map": "grid-small"}, {"uavs": (3,)},
                        tuple(range(runs)))


def _run(spec: CampaignSpec, workers: int) -> CampaignSummary:
    with tempfile.TemporaryDirectory() as folder:
        return run_campaign(spec, Path(folder) / "bench.duckdb", workers=workers)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--experiment", choices=("toy", "mission"), default="toy")
    parser.add_argument("--runs", type=int, default=40)
    parser.add_argument("--sleep", type=float, default=0.25, help="seconds per toy run")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    spec = _spec(args.experiment, args.runs, args.sleep)
    serial = _run(spec, 0)
    parallel = _run(spec, args.workers)
    what = f"toy runs of {args.sleep} s" if args.experiment == "toy" else "road missions"
    print(f"{args.runs} {what}; mean run {serial.run_s / args.runs:.3f} s serially; "
          f"cluster start-up {parallel.startup_s:.2f} s")
    rows = []
    for name, s in (("0 (serial)", serial), (str(args.workers), parallel)):
        n, slots = s.ok + s.failed, max(s.slots, 1)
        busy = s.wall_s - s.startup_s
        rows.append([name, str(n), f"{s.wall_s:.2f}", f"{busy:.2f}",
                     f"{serial.wall_s / s.wall_s:.2f}", f"{serial.wall_s / busy:.2f}",
                     f"{1e3 * (s.wall_s - s.run_s / slots) / n:.1f}",
                     f"{1e3 * (busy - s.run_s / slots) / n:.1f}"])
    table(["workers", "runs", "wall s", "wall s*", "speed-up", "speed-up*", "overhead ms/run",
           "overhead ms/run*"], rows)
    print("* without the cluster start-up")


if __name__ == "__main__":
    main()
