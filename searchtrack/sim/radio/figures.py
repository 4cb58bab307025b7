"""PNG figures of a radio-tag mission (paper 002): the map of Fig. 7 (UAV path, true and
estimated tracks, the keep-out discs of radius r_min around the estimates at each planning
instant) and the time plots of Fig. 5 (OSPA with its localisation and cardinality parts,
cardinality mean ± 3σ against the truth)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from searchtrack.sim.figure_style import DPI, pyplot, save_png
from searchtrack.sim.radio.mission import RadioMissionLog


def plot_radio_map(log: RadioMissionLog, path: Path) -> Path:
    """The area with the UAV path, each object's true track (solid) and estimates (dots, same
    colour per label) and the r_min discs around the estimates at every planning instant."""
    plt = pyplot()
    from matplotlib.patches import Circle

    sc = log.scenario
    fig, ax = plt.subplots(figsize=(7.5, 7.0), dpi=DPI)
    colours = plt.get_cmap("tab10")
    truth = log.truth
    k = log.steps
    for lab in range(sc.signal.n_labels):
        c = colours(lab % 10)
        states = truth.states[:k, lab]
        if np.any(np.isfinite(states[:, 0])):
            ax.plot(states[:, 0], states[:, 2], "-", color=c, lw=1.6,
                    label=f"object {lab} (truth)")
        pts = np.array([xy for row in log.estimates for (lb, xy) in row if lb == lab])
        if pts.size:
            ax.plot(pts[:, 0], pts[:, 1], ".", color=c, ms=2.5, alpha=0.6)
    ax.plot(log.poses[:, 0], log.poses[:, 1], "-", color="0.25", lw=0.8, label="UAV")
    ax.plot(log.poses[:1, 0], log.poses[:1, 1], "k^", ms=7)
    interval = max(1, round(sc.uav.plan_interval_s / sc.uav.step_s))
    r_min = log.config.plan.r_min_m
    for step in range(0, k, interval):
        for _, xy in log.estimates[step]:
            ax.add_patch(Circle(xy, r_min, fill=False, color="crimson", lw=0.4, alpha=0.35))
    ax.plot([], [], ".", color="0.4", ms=5, label="estimates (dots, the object's colour)")
    ax.plot([], [], "o", mfc="none", color="crimson",
            label=f"keep-out r_min = {r_min:g} m (at planning instants)")
    w, h = sc.area_m
    ax.set_xlim(-0.05 * w, 1.05 * w)
    ax.set_ylim(-0.05 * h, 1.05 * h)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    c = log.config
    ax.set_title(f"{c.filter.upper()} + {c.planner}: UAV path, true and estimated tracks")
    ax.legend(fontsize=7, loc="upper left")
    return save_png(fig, path)


def plot_radio_ospa(log: RadioMissionLog, path: Path) -> Path:
    """OSPA (p, c) and its parts against time; below, the cardinality mean ± 3σ and the truth."""
    plt = pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 6.0), dpi=DPI, sharex=True)
    t = log.times_s
    c = log.config
    for col, name in enumerate(("OSPA", "localisation", "cardinality")):
        top.plot(t, log.ospa[:, col], lw=1.2 if col == 0 else 0.8, label=name)
    top.set_ylabel(f"OSPA (m), p = {c.ospa_p:g}, c = {c.ospa_c_m:g} m")
    top.legend(fontsize=8)
    top.set_title(f"{c.filter.upper()} + {c.planner}: mean OSPA {log.mean_ospa()[0]:.1f} m, "
                  f"unsafe {100 * log.unsafe_fraction():.1f} % of steps")
    mean, sd = log.cardinality_mean, np.sqrt(np.maximum(log.cardinality_var, 0.0))
    bottom.plot(t, log.truth.alive[: log.steps].sum(axis=1), "k-", lw=1.5, label="truth")
    bottom.plot(t, mean, "C0-", lw=1.0, label="mean")
    bottom.fill_between(t, mean - 3 * sd, mean + 3 * sd, color="C0", alpha=0.2, label="±3σ")
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("cardinality")
    bottom.legend(fontsize=8)
    return save_png(fig, path)
