"""Fly the shipped demo scenario for a minute with each tracking strategy and print the scores."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from searchtrack.sim.roads.mission import Mission, World
from searchtrack.sim.roads.scenario import GuidanceSpec
from searchtrack.sim.roads.scenario_file import load_scenario

DEMO = Path(__file__).resolve().parents[1] / "searchtrack" / "data" / "scenarios" / "demo.toml"


def main() -> None:
    """One line per strategy: targets detected, MOC, PVT, PVA and the step time."""
    base = dataclasses.replace(load_scenario(DEMO), duration_s=60.0)
    world = World.build(base)  # the map and the diffusion operators, built once
    for strategy in ("loiter", "search_and_loiter", "search_and_reacquire"):
        sc = dataclasses.replace(base, guidance=GuidanceSpec(strategy=strategy))
        s = Mission(sc, world).run().score
        pvt = "-" if s.pvt is None else f"{s.pvt:.2f}"
        pva = "-" if s.pva is None else f"{s.pva:.2f}"
        print(f"{strategy:21s} detected {s.detected}/{s.targets}  MOC {s.moc_mean:.2f}  "
              f"PVT {pvt}  PVA {pva}")


if __name__ == "__main__":
    main()
