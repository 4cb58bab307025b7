"""Fly a unicycle past two obstacles with each controller and compare tracking and clearance."""

from __future__ import annotations

import numpy as np

from searchtrack.models.vehicles import unicycle
from searchtrack.plan.trajectory import Obstacles, waypoint_path
from searchtrack.sim.flight.loop import FlightConfig, fly


def main() -> None:
    """One line per controller: RMS tracking error, collisions, clearance, who answered."""
    course = waypoint_path([[0, 0], [100, 0], [100, 100]], speed_mps=10.0)
    trees = Obstacles(centers_m=[[45.0, -2.0], [100.0, 40.0]], radii_m=[3.0, 5.0])
    for backend in ("auto", "nmpc", "ltv_mpc", "closed_form"):
        log = fly(unicycle(), [0.0, -3.0, 0.0], course, trees, FlightConfig(backend=backend),
                  rng=np.random.default_rng(0))
        print(f"{backend:12s} rms {log.rms_error_m:5.2f} m  collisions {log.collisions}  "
              f"min clearance {log.min_clearance_m:5.2f} m  nmpc {log.count('nmpc')}  "
              f"qp {log.count('ltv_mpc')}  closed form {log.count('closed_form')}")


if __name__ == "__main__":
    main()
