"""PNG figures of a mission: the road map with likelihood and tracker heat and the UAV and target
paths (thesis Figs. 3.1, 4.2, 6.1), and MOC over time (Fig. 6.5)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from searchtrack.sim.figure_style import DPI, pyplot, save_png
from searchtrack.sim.roads.record import MissionLog


def plot_map(mission: MissionLog, path: Path) -> Path:
    """Roads coloured by the final LRT field, tracker mass as heat, UAV and target paths."""
    plt = pyplot()
    from matplotlib.collections import LineCollection
    from matplotlib.colors import TwoSlopeNorm

    net = mission.network
    xy = net.coords
    fig, ax = plt.subplots(figsize=(9, 8), dpi=DPI)
    segments = xy[net.edges]
    ax.add_collection(LineCollection(list(segments), colors="0.8", linewidths=0.6, zorder=1))
    llr = mission.final_llr
    span = max(float(np.abs(llr).max()), 1e-9)
    shown = np.abs(llr) > 1e-3 * span
    if np.any(shown):
        sc = ax.scatter(xy[shown, 0], xy[shown, 1], c=llr[shown], s=3, cmap="RdYlBu_r",
                        norm=TwoSlopeNorm(0.0, -span, span), zorder=2)
        fig.colorbar(sc, ax=ax, shrink=0.6, label="LRT log-likelihood ratio φ")
    heat = mission.final_trackers
    hot = heat > 1e-3 * max(float(heat.max()), 1e-12)
    if np.any(hot):
        ax.scatter(xy[hot, 0], xy[hot, 1], c=heat[hot], s=16, cmap="magma_r", zorder=5,
                   label="tracker probability")
    for j in range(mission.uav_xy_m.shape[1]):
        p = mission.uav_xy_m[:, j]
        line, = ax.plot(p[:, 0], p[:, 1], lw=1.0, zorder=4, label=f"UAV {j + 1}")
        ax.plot(p[-1, 0], p[-1, 1], marker="^", ms=8, color=line.get_color(), zorder=5,
                ls="none", label="UAVs at the end" if j == 0 else None)
    for i in range(mission.target_xy_m.shape[1]):
        p = mission.target_xy_m[:, i]
        ax.plot(p[:, 0], p[:, 1], "k--", lw=0.8, zorder=4,
                label="targets" if i == 0 else None)
        ax.plot(p[-1, 0], p[-1, 1], "ks", ms=5, zorder=5,
                label="targets at the end" if i == 0 else None)
    paths = [xy, *(a.reshape(-1, 2) for a in (mission.uav_xy_m, mission.target_xy_m))]
    every = np.vstack([a for a in paths if a.size])
    lo, hi = every.min(axis=0), every.max(axis=0)   # roads and every path: nothing cropped
    pad = 0.03 * (hi - lo)
    ax.set_xlim(lo[0] - pad[0], hi[0] + pad[0])
    ax.set_ylim(lo[1] - pad[1], hi[1] + pad[1])
    ax.set_aspect("equal")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    sc_ = mission.scenario
    title = f"{sc_.name}: {sc_.guidance.strategy}"
    if mission.time_s.size:
        title += f", t = {mission.time_s[-1]:.1f} s"
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=7)
    return save_png(fig, path, tight_bbox=True)


def plot_moc(mission: MissionLog, path: Path) -> Path:
    """MOC and the number of trackers over time."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.5), dpi=DPI)
    ax.plot(mission.time_s, mission.moc, label="MOC (valid trackers / targets)")
    ax.set_ylim(-0.02, 1.25)   # headroom: the legend sits above MOC = 1
    ax.set_xlabel("time (s)")
    ax.set_ylabel("MOC")
    ax2 = ax.twinx()
    ax2.step(mission.time_s, [s.trackers for s in mission.steps], where="post", color="0.5",
             lw=0.8, label="trackers")
    ax2.set_ylabel("trackers")
    most = max((s.trackers for s in mission.steps), default=0)
    ax2.set_ylim(-0.02 * max(most, 1), 1.25 * max(most, 1))   # the same headroom as MOC
    ax2.yaxis.get_major_locator().set_params(integer=True)
    ax.set_title(f"{mission.scenario.name}: measure of completeness")
    handles = ax.get_legend_handles_labels()[0] + ax2.get_legend_handles_labels()[0]
    ax.set_yticks([0.0, 0.25, 0.5, 0.75, 1.0])
    ax.legend(handles=handles, loc="upper center", ncol=2, fontsize=7)   # over MOC = 1
    return save_png(fig, path)
