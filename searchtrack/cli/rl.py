"""``searchtrack rl train|evaluate``: the deep-RL road planner of paper 000 (§4.3).

``train`` runs PPO (the ``rl`` extra: PyTorch and Stable-Baselines3) on the road search of the
paper's 3 × 3 grid and writes the actor as a NumPy ``.npz`` policy; Ctrl-C stops training and
writes the policy learnt so far. ``evaluate`` flies a policy (no deep-learning stack needed)
against the random planner on a few episodes and prints their mean combined entropy.
"""

from __future__ import annotations

import argparse
import dataclasses
from typing import TYPE_CHECKING

import numpy as np
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

from searchtrack.cli.common import add_group, description, int_at_least, positive_float, seed_arg
from searchtrack.cli.output import output_file
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested

if TYPE_CHECKING:
    from searchtrack.sim.road_particles.episode import RoadTrackingConfig


def _episode(base: RoadTrackingConfig, duration_s: float) -> RoadTrackingConfig:
    """``base`` with episodes of ``duration_s``; a duration the episode cannot take (over its
    step cap) is refused naming ``--duration``."""
    try:
        return dataclasses.replace(base, duration_s=duration_s)
    except InvalidInputError as exc:
        raise InvalidInputError("--duration", duration_s, exc.reason) from None


def train(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack rl train``."""
    from searchtrack.sim.road_particles.env import TRAINING_CONFIG
    from searchtrack.sim.road_particles.rl_training import TrainingConfig, train_policy

    out = output_file("--out", args.out)
    training = TrainingConfig(timesteps=args.timesteps)
    config = _episode(TRAINING_CONFIG, args.duration)
    with Progress(TextColumn("PPO"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                  TimeRemainingColumn(), console=console, transient=True) as bar:
        task = bar.add_task("train", total=args.timesteps)
        policy = train_policy(config, training, seed=args.seed,
                              progress=lambda done, total: bar.update(task, completed=done))
    policy.save(out)
    stopped = stop_requested()
    console.print(f"{'stopped early: ' if stopped else ''}policy ({policy.n_inputs} inputs, "
                  f"{policy.n_actions} actions); wrote {out}")
    return 130 if stopped else 0


def evaluate(args: argparse.Namespace, console: Console) -> int:
    """Handler of ``searchtrack rl evaluate``."""
    from searchtrack.models.road_particles import DirectedRoads
    from searchtrack.sim.road_particles.episode import (
        PAPER_GRID,
        RoadTrackingConfig,
        run_road_tracking,
    )
    from searchtrack.sim.road_particles.planners import flyable_policy

    base = _episode(RoadTrackingConfig(policy=args.policy or ""), args.duration)
    roads = DirectedRoads(PAPER_GRID.build())
    if args.policy:
        flyable_policy(args.policy, roads)  # a bad file: one line before any episode
    table = Table(title=f"mean combined entropy over {args.episodes} episodes of "
                        f"{args.duration:g} s (paper 000, 3 × 3 grid)")
    for col in ("planner", "mean entropy", "last third", "decision ms"):
        table.add_column(col, justify="right" if col != "planner" else "left")
    for planner in ("rl", "random"):
        logs = []
        for seed in range(args.seed, args.seed + args.episodes):
            if stop_requested():
                break
            config = dataclasses.replace(base, planner=planner)
            logs.append(run_road_tracking(config, seed, roads))
        if not logs:
            break
        third = [log.entropy[-max(1, log.entropy.size // 3):].mean() for log in logs]
        table.add_row(planner, f"{np.mean([log.mean_entropy for log in logs]):.3f}",
                      f"{np.mean(third):.3f}", f"{np.mean([log.planner_ms for log in logs]):.2f}")
    console.print(table)
    return 130 if stop_requested() else 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register ``rl train|evaluate`` on the top-level subparsers."""
    rl = add_group(sub, "rl", description(__doc__))
    rsub = rl.add_subparsers(dest="command", required=True)
    p_train = rsub.add_parser("train", help="train a policy with PPO (needs the rl extra)")
    p_train.add_argument("--timesteps", type=int_at_least(1), default=100_000, metavar="N",
                         help="agent steps (roads flown) to train for (default 100000)")
    p_train.add_argument("--duration", type=positive_float, default=120.0, metavar="S",
                         help="episode length in seconds (default 120)")
    p_train.add_argument("--seed", type=seed_arg, default=0, help="random seed (default 0)")
    p_train.add_argument("--out", required=True, metavar="POLICY.npz",
                         help="where to write the policy")
    p_train.set_defaults(run=train)
    p_eval = rsub.add_parser("evaluate", help="fly a policy against the random planner")
    p_eval.add_argument("--policy", default=None, metavar="POLICY.npz",
                        help="policy file (default: the shipped one)")
    p_eval.add_argument("--episodes", type=int_at_least(1), default=10, metavar="K",
                        help="episodes per planner (default 10)")
    p_eval.add_argument("--duration", type=positive_float, default=120.0, metavar="S",
                        help="episode length in seconds (default 120)")
    p_eval.add_argument("--seed", type=seed_arg, default=0, help="first episode seed")
    p_eval.set_defaults(run=evaluate)
