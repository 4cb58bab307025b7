"""Where the expected count of paper 004's closed loop goes: the PHD mass split by target.

The lawnmower loop of :mod:`searchtrack.sim.particles.search` (12 static targets in
``[−20, 260]³`` m, no clutter), run step by step with ``_filter_step`` as
``run_search_episode`` runs it, for seeds ``0 … n−1``. After steps 50, 100, 200, 300 and 400 it
reports the *count*: the expected number of targets ``λ = Σ w`` of the PHD plus the estimates
saved as found. At the last step the count is split into

- ``λ`` near unfound targets, near found ones and far from every target (a particle is *near*
  a target within ``--near`` metres, 10 m by default);
- saved estimates that find a target, *duplicates* (a second estimate within ``match_m`` of an
  already found target) and *false* ones (farther than ``match_m`` from every target);

with the detections of found targets and the share of them that passed the found-target gate,
and the birth mass those passing detections seeded. Variants switch one thing at a time:

- ``printed``: 004's printed gate, a ball of ``T_z = 5`` m (``gate_sigmas = 0``);
- ``oracle``: the printed gate, and every detection of an already found target is dropped (the
  ideal gate);
- ``no-found-birth``: the printed gate, but detections of found targets seed no births;
- ``innovation``: the loop's default gate (4 standard deviations of the innovation);
- each with the renormalised birth (``birth_mass = 0.5``, ``T_m = 0.7``, the loop's default) or
  ``adaptive`` birth (``adaptive_birth``, ``birth_mass = 1``, ``T_m = 1``).

Run: ``.venv/bin/python benchmarks/phd_count_drift.py [--seeds 3] [--steps 400]
[--variants printed,innovation,...] [--birth both]`` (5–15 s per 400-step run on one core,
under 2 minutes for the default eight variants × three seeds).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tables import table

from searchtrack.estimate.phd import PHDState, gate_found
from searchtrack.plan.search import lawnmower_3d
from searchtrack.sim.particles.search import SearchConfig, _filter_step

FloatArray = NDArray[np.float64]
STEPS = (50, 100, 200, 300, 400)
GATES = ("printed", "oracle", "no-found-birth", "innovation")


@dataclass
class Split:
    """The count and its parts after one step (sums over seeds are taken by the caller)."""

    count: float
    near_unfound: float
    near_found: float
    far: float
    unfound: int
    found: int
    duplicate: int
    false: int
    found_detections: int
    passed: int
    found_birth: float


def config(gate: str, adaptive: bool, steps: int) -> SearchConfig:
    """The lawnmower loop of a variant."""
    base = SearchConfig(planner="lawnmower", max_steps=steps)
    sigmas = base.found.gate_sigmas if gate == "innovation" else 0.0
    phd, mass = base.phd, base.found.mass
    if adaptive:
        phd, mass = replace(phd, adaptive_birth=True, birth_mass=1.0), 1.0
    return replace(base, phd=phd, found=replace(base.found, mass=mass, gate_sigmas=sigmas))


def _found_targets(targets: FloatArray, saved: FloatArray, match_m: float) -> NDArray[np.bool_]:
    if saved.shape[0] == 0:
        return np.zeros(targets.shape[0], dtype=bool)
    d = np.linalg.norm(targets[:, None, :] - saved[None, :, :], axis=2)
    return np.asarray(d.min(axis=1) <= match_m)


def _split(state: PHDState, saved: FloatArray, targets: FloatArray, match_m: float,
           near_m: float, tallies: tuple[int, int, float]) -> Split:
    hit = _found_targets(targets, saved, match_m)
    w = state.weights
    if state.n_particles:
        d = np.linalg.norm(state.positions[:, None, :] - targets[None, :, :], axis=2)
        nearest = np.argmin(d, axis=1)
        close = d[np.arange(d.shape[0]), nearest] <= near_m
    else:
        nearest, close = np.zeros(0, dtype=np.int64), np.zeros(0, dtype=bool)
    lam = float(w.sum())
    unf = float(w[close & ~hit[nearest]].sum())
    fnd = float(w[close & hit[nearest]].sum())
    if saved.shape[0]:
        ds = np.linalg.norm(saved[:, None, :] - targets[None, :, :], axis=2)
        false = int((ds.min(axis=1) > match_m).sum())
    else:
        false = 0
    n_found = int(hit.sum())
    return Split(lam + saved.shape[0], unf, fnd, lam - unf - fnd, int((~hit).sum()), n_found,
                 saved.shape[0] - n_found - false, false, *tallies)


def run(cfg: SearchConfig, gate: str, seed: int, near_m: float) -> dict[int, Split]:
    """One lawnmower episode of ``cfg`` (gate variant ``gate``), split at :data:`STEPS`."""
    targets = np.random.default_rng([seed, 0]).uniform(
        cfg.bounds[:, 0], cfg.bounds[:, 1], size=(cfg.n_targets, 3))
    rng = np.random.default_rng([seed, 1])
    sensor = cfg.sensor
    route = lawnmower_3d(np.array(cfg.bounds), cfg.lawnmower_spacing_m,
                         cfg.lawnmower_spacing_m, cfg.step_m)
    state, saved, position = PHDState.empty(3, 3), np.empty((0, 3)), np.array(cfg.start)
    detections = passed = 0
    birth = 0.0
    out: dict[int, Split] = {}
    for k in range(cfg.max_steps):
        z, origin = sensor.measure(position, targets, rng)
        of_found = _found_targets(targets, saved, cfg.match_m)[origin]
        detections += int(of_found.sum())
        if gate == "oracle":
            z, origin, of_found = z[~of_found], origin[~of_found], of_found[~of_found]
        keep = gate_found(saved, sensor, position, z, cfg.found)
        passed += int((keep & of_found).sum())
        state, saved, _ = _filter_step(state, saved, z, position, cfg, rng)
        seeds = state.record.seed_masses
        if seeds.shape[0]:
            mine = of_found[keep]
            if gate == "no-found-birth":
                seeds = np.where(mine, 0.0, seeds)
                state = replace(state, record=replace(state.record, seed_masses=seeds))
            birth += float(seeds[mine].sum())
        if k + 1 in STEPS or k + 1 == cfg.max_steps:
            out[k + 1] = _split(state, saved, targets, cfg.match_m, near_m,
                                (detections, passed, birth))
        position = route[min(k + 1, route.shape[0] - 1)]
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--near", type=float, default=10.0, help="near a target within (m)")
    ap.add_argument("--variants", default=",".join(GATES),
                    help=f"comma-separated gates from {GATES}")
    ap.add_argument("--birth", default="both", choices=("renormalised", "adaptive", "both"))
    args = ap.parse_args(argv)
    births = {"renormalised": [False], "adaptive": [True], "both": [False, True]}[args.birth]
    steps = [s for s in STEPS if s <= args.steps] or [args.steps]
    count_rows, split_rows = [], []
    for gate in args.variants.split(","):
        if gate not in GATES:
            ap.error(f"unknown variant {gate!r}: choose from {GATES}")
        for adaptive in births:
            cfg = config(gate, adaptive, args.steps)
            runs = [run(cfg, gate, s, args.near) for s in range(args.seeds)]
            name = f"{gate}, {'adaptive' if adaptive else 'renormalised'}"

            def mean(step: int, field: str, runs: list[dict[int, Split]] = runs) -> float:
                return float(np.mean([getattr(r[step], field) for r in runs]))

            count_rows.append([name] + [f"{mean(s, 'count'):.1f}" for s in steps])
            last = steps[-1]
            det = mean(last, "found_detections")
            share = 100.0 * mean(last, "passed") / det if det else 0.0
            split_rows.append([name, f"{mean(last, 'count'):.1f}"] + [
                f"{mean(last, f):.2f}" for f in ("near_unfound", "unfound", "near_found", "far",
                                                 "found", "duplicate", "false")] + [
                f"{det:.0f}", f"{share:.0f} %", f"{mean(last, 'found_birth'):.2f}"])
    print(f"Count = expected number λ + saved estimates (12 targets), lawnmower, "
          f"mean of seeds 0–{args.seeds - 1}")
    table(["variant"] + [f"step {s}" for s in steps], count_rows)
    print(f"\nSplit after step {steps[-1]} (near: within {args.near:g} m of a target)")
    table(["variant", "count", "λ near unfound", "unfound targets", "λ near found", "λ far",
           "found", "duplicates", "false", "found-target detections", "passed the gate",
           "birth from them"], split_rows)


if __name__ == "__main__":
    main()
