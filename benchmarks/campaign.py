"""Campaign runner overhead: a 40-run toy campaign serially and on a 2-process LocalCluster.

    python benchmarks/campaign.py [--runs 40] [--sleep 0.25] [--workers 2]

Each toy run sleeps ``--sleep`` seconds (a stand-in for a short mission). Columns: runs, wall
time (s, cluster start-up included, and without it), speed-up over serial, and the scheduling +
database overhead per run (ms) = (wall − Σ run time / workers) / runs, with and without the
cluster start-up (columns marked *).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from tables import table

from searchtrack.sim.campaigns.runner import CampaignSummary, run_campaign
from searchtrack.sim.campaigns.spec import CampaignSpec


def _spec(runs: int, sleep_s: float) -> CampaignSpec:
    return CampaignSpec("bench", "toy", {"sleep_s": sleep_s}, {"value": (1.0,)},
                        tuple(range(runs)))


def _run(runs: int, sleep_s: float, workers: int) -> CampaignSummary:
    with tempfile.TemporaryDirectory() as folder:
        return run_campaign(_spec(runs, sleep_s), Path(folder) / "bench.duckdb", workers=workers)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=40)
    parser.add_argument("--sleep", type=float, default=0.25, help="seconds per toy run")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    serial = _run(args.runs, args.sleep, 0)
    parallel = _run(args.runs, args.sleep, args.workers)
    print(f"{args.runs} toy runs of {args.sleep} s; cluster start-up "
          f"{parallel.startup_s:.2f} s")
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
