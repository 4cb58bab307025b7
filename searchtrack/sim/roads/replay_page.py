"""The offline replay page of a road mission (thesis 001), drawn from its mission.json alone.

The page (:func:`write_replay`) is one HTML file embedding plotly.js (no network). Above, the
road map with, at each heat frame of the record, the LRT's evidence ``φ`` (3.3) and the trackers'
summed node probabilities as coloured nodes, the UAV and target paths to that time, and the
trackers' peaks sized and labelled by probability; below, the MOC and the running PVT (6.8) and
PVA (6.9) with a cursor at the frame's time. A slider and play / pause move through the frames.

The record is :meth:`~searchtrack.sim.roads.record.MissionLog.to_json`'s dictionary, with the
``"map"`` and ``"heat"`` blocks older records lack. Every field drawn is checked: a missing or
ill-typed one raises :class:`~searchtrack.core.errors.ParseError` naming it.
"""

from __future__ import annotations

import html
import logging
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import plotly.graph_objects as go
from numpy.typing import NDArray
from plotly.subplots import make_subplots

from searchtrack.core.errors import ParseError
from searchtrack.core.fields import TOP_LEVEL, JsonFields
from searchtrack.core.files import read_json, write_text_atomic
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.sim.roads.record import HeatFrame

log = logging.getLogger("searchtrack.sim.roads.replay_page")

UAV_COLOURS = ("#2ca02c", "#e377c2", "#17becf", "#8c564b", "#bcbd22", "#1f77b4", "#7f7f7f",
               "#9467bd")
"""UAV colours, in turn (none of the heat scales' hues)."""
LRT_SCALE = [[0.0, "#fed976"], [0.5, "#fd8d3c"], [1.0, "#bd0026"]]
TRACKER_SCALE = [[0.0, "#c6dbef"], [0.5, "#6a51a3"], [1.0, "#3f007d"]]
CURVES = (("MOC", "#1f3b73"), ("PVT (running)", "#ff7f0e"), ("PVA (running)", "#d62728"))
FRAME_MS = 100
"""Milliseconds per frame when playing."""
PATH_TOLERANCE_M = 2.0
"""Largest distance between a drawn path and the recorded one (m)."""
RECORD_KEYS = ("scenario", "summary", "time_s")
"""Fields every mission record has had (a document without one is not a mission record)."""


@dataclass(frozen=True, eq=False)
class Replay:
    """A checked mission record: what the page draws (``S`` steps; paths start before the
    first, ``S + 1`` rows; ``curves`` ``(3, S)``: MOC, running PVT, running PVA, NaN while
    undefined; ``tracks`` per step ``(k, 3)``: track id, peak node, peak probability)."""

    title: str
    nodes_xy_m: FloatArray
    edges: IntArray
    time_s: FloatArray
    curves: FloatArray
    uav_xy_m: FloatArray
    target_xy_m: FloatArray
    tracks: tuple[FloatArray, ...]
    heat: tuple[HeatFrame, ...]


_INT_LIMIT = 2.0**53
"""Integer fields hold whole numbers of magnitude below this: exact as floats, and in int64."""

_NUMBERS = np.frompyfunc(lambda v: isinstance(v, (int, float, np.integer, np.floating))
                         and not isinstance(v, bool), 1, 1)


class _Reader(JsonFields):
    """Field checks raising :class:`ParseError` naming the record's source and the field: the
    common ones and numeric arrays."""

    def array(self, value: Any, field: str, shape: tuple[int | None, ...], what: str, *,
              integer: Any = False, low: Any = -math.inf, high: Any = math.inf) -> NDArray[Any]:
        """A numeric array of ``shape`` (``None``: any length), finite, in ``[low, high]``
        and integral where ``integer`` (the three broadcast against the array)."""
        if not isinstance(value, list):
            raise self.fail(field, f"must be {what}, got {type(value).__name__}")
        try:
            leaves = np.array(value, dtype=object)
        except ValueError:
            raise self.fail(field, f"must be {what} (rows of equal length)") from None
        if leaves.size == 0 and leaves.shape[0] == 0:
            leaves = leaves.reshape((0, *[d or 0 for d in shape[1:]]))
        if leaves.ndim != len(shape) or any(d not in (None, n)
                                            for d, n in zip(shape, leaves.shape, strict=True)):
            raise self.fail(field, f"must be {what}, got a list of shape {leaves.shape}")
        bad = ~_NUMBERS(leaves).astype(bool)
        if not bad.any():
            with np.errstate(over="ignore"):
                x = leaves.astype(np.float64)
            whole = (x == np.round(x)) & (np.abs(x) < _INT_LIMIT)
            bad = ~np.isfinite(x) | (x < low) | (x > high) | (integer & ~whole)
        if bad.any():
            where = tuple(int(i) for i in np.argwhere(bad)[0])
            raise self.fail(field + "".join(f"[{i}]" for i in where),
                            f"bad value {leaves[where]!r:.40}: {field} must be {what}")
        return x.astype(np.int64) if integer is True else x


#: Largest coordinate a record may hold (m): far beyond any map, within the page's 32-bit floats.
MAX_COORD_M = 1e9


def read_replay(record: Mapping[str, Any], source: str | Path = "mission record") -> Replay:
    """Check a mission record and gather what the page draws; :class:`ParseError` names
    ``source`` and the field at fault (and says to re-run a mission recorded without a map)."""
    r = _Reader(source)
    top = r.obj(record, TOP_LEVEL)
    missing = [key for key in RECORD_KEYS if key not in top]
    if missing:
        raise r.fail(missing[0], "missing: not a mission record (`searchtrack mission run` writes "
                     f"one, with {', '.join(RECORD_KEYS)} among its fields)")
    if "map" not in top:
        raise r.fail("map", "missing: the record predates the replay page; re-run `searchtrack "
                     "mission run` on its scenario to record the map and heat frames it draws")
    sc = r.obj(r.get(top, "scenario"), "scenario")
    title = "{}: {} on {}".format(*(r.text(r.get(sc, k, "scenario."), f"scenario.{k}")
                                    for k in ("name", "strategy", "map")))
    time_s = r.array(r.get(top, "time_s"), "time_s", (None,), "a list of times (s)")
    s = time_s.size
    if s == 0:
        raise r.fail("time_s", "is empty: a replay needs at least one step")
    moc = r.array(r.get(top, "moc"), "moc", (s,), f"a list of {s} fractions in [0, 1]",
                  low=0.0, high=1.0)
    nvt, trk, nva, nfa = (np.cumsum(r.array(r.get(top, k), k, (s,), f"a list of {s} counts "
                                            "(integers ≥ 0)", integer=True, low=0.0))
                          for k in ("valid_trackers", "trackers", "valid_associations",
                                    "false_associations"))
    mp = r.obj(top["map"], "map")
    nodes = r.array(r.get(mp, "nodes_xy_m", "map."), "map.nodes_xy_m", (None, 2),
                    f"a list of [x, y] node positions (m, |x|, |y| ≤ {MAX_COORD_M:g})",
                    low=-MAX_COORD_M, high=MAX_COORD_M)
    n = nodes.shape[0]
    edges = r.array(r.get(mp, "edges", "map."), "map.edges", (None, 2),
                    f"a list of [i, j] node index pairs (in [0, {n}))", integer=True, low=0.0,
                    high=n - 1)
    if n < 2 or edges.shape[0] == 0:
        raise r.fail("map", "must hold at least 2 nodes and 1 edge")
    uav, target = (r.array(r.get(top, k), k, (s + 1, None, 2), f"{s + 1} lists (the start, "
                           f"then each step) of [x, y] per vehicle (m, |x|, |y| ≤ "
                           f"{MAX_COORD_M:g})", low=-MAX_COORD_M, high=MAX_COORD_M)
                   for k in ("uav_xy_m", "target_xy_m"))
    if uav.shape[1] == 0 or target.shape[1] == 0:
        raise r.fail("uav_xy_m" if uav.shape[1] == 0 else "target_xy_m", "holds no vehicle")
    raw_tracks = r.get(top, "tracks")
    if not isinstance(raw_tracks, list) or len(raw_tracks) != s:
        raise r.fail("tracks", f"must be a list of {s} lists (one per step)")
    tracks = tuple(r.array(t, f"tracks[{i}]", (None, 3), f"a list of [track id, node in [0, "
                           f"{n}), probability in [0, 1]]", integer=np.array([1, 1, 0]) > 0,
                           low=0.0, high=np.array([math.inf, n - 1, 1.0]))
                   for i, t in enumerate(raw_tracks))
    heat = _heat_frames(r, r.obj(r.get(top, "heat"), "heat"), s, n)
    with np.errstate(invalid="ignore", divide="ignore"):
        curves = np.vstack([moc, np.where(trk > 0, nvt / trk, np.nan),
                            np.where(nva + nfa > 0, nva / (nva + nfa), np.nan)])
    return Replay(title, nodes, edges, time_s, curves, uav, target, tracks, heat)


def _heat_frames(r: _Reader, heat: Mapping[str, Any], steps: int,
                 nodes: int) -> tuple[HeatFrame, ...]:
    """The heat frames, at increasing steps in ``[0, steps)``, on nodes in ``[0, nodes)``."""
    raw = r.items(r.get(heat, "frames", "heat."), "heat.frames", "frame objects")
    out: list[HeatFrame] = []
    for i, value in enumerate(raw):
        where = f"heat.frames[{i}]"
        step = r.get(r.obj(value, where), "step", where + ".")
        if isinstance(step, bool) or not isinstance(step, int) or not 0 <= step < steps:
            raise r.fail(where + ".step", f"must be a step index in [0, {steps}), got {step!r}")
        if out and step <= out[-1].step:
            raise r.fail(where + ".step", "must be after the previous frame's step")
        parts = []
        for key in ("llr", "trackers"):
            at = f"{where}.{key}."
            part = r.obj(r.get(value, key, where + "."), at[:-1])
            idx = r.array(r.get(part, "nodes", at), at + "nodes", (None,),
                          f"a list of node indices in [0, {nodes})", integer=True, low=0.0,
                          high=nodes - 1)
            parts += [idx, r.array(r.get(part, "values", at), at + "values", (idx.size,),
                                   f"a list of {idx.size} finite numbers (one per node)"
                                   + (" ≥ 0" if key == "trackers" else ""),
                                   low=0.0 if key == "trackers" else -math.inf)]
        out.append(HeatFrame(step, *parts))
    return tuple(out)


def _road_lines(nodes: FloatArray, edges: IntArray) -> NDArray[np.float32]:
    """The roads as one ``(m, 2)`` polyline with NaN breaks (edges in a chain join up)."""
    joins = np.r_[False, edges[1:, 0] == edges[:-1, 1]]
    seq = np.column_stack([edges, np.full(len(edges), -1)])
    keep = np.column_stack([~joins, np.ones_like(joins), np.r_[~joins[1:], True]]).ravel()
    order = seq.ravel()[keep][:-1]
    return np.where((order >= 0)[:, None], nodes[order], np.nan).astype(np.float32)


def _kept(path: FloatArray, tolerance_m: float = PATH_TOLERANCE_M) -> IntArray:
    """The points drawing a path ``(n, 2)`` within ``tolerance_m`` (Ramer–Douglas–Peucker)."""
    keep = np.zeros(len(path), dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, len(path) - 1)]
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        chord, rel = path[b] - path[a], path[a + 1:b] - path[a]
        length = float(np.hypot(*chord))
        dist = (np.abs(chord[0] * rel[:, 1] - chord[1] * rel[:, 0]) / length if length > 0
                else np.hypot(rel[:, 0], rel[:, 1]))
        i = int(np.argmax(dist))
        if dist[i] > tolerance_m:
            keep[a + 1 + i] = True
            stack += [(a, a + 1 + i), (a + 1 + i, b)]
    return np.flatnonzero(keep)


def _paths_upto(xy: FloatArray, kept: list[IntArray], k: int) -> dict[str, Any]:
    """Paths to step ``k`` (``kept`` points before ``k``, then ``xy[k]``), NaN between them."""
    parts = []
    for j, idx in enumerate(kept):
        parts += [xy[idx[: np.searchsorted(idx, k)], j], xy[k, j][None], np.full((1, 2), np.nan)]
    flat = np.concatenate(parts[:-1]).astype(np.float32)
    return {"x": flat[:, 0], "y": flat[:, 1]}


@dataclass(frozen=True, eq=False)
class _Scene:
    """A replay with what every frame shares: the paths' kept points and the colour ranges."""

    rp: Replay
    uav_kept: list[IntArray]
    target_kept: list[IntArray]
    lrt_max: float
    tracker_max: float

    @classmethod
    def of(cls, rp: Replay) -> _Scene:
        return cls(rp, [_kept(p) for p in rp.uav_xy_m.transpose(1, 0, 2)],
                   [_kept(p) for p in rp.target_xy_m.transpose(1, 0, 2)],
                   max([1.0, *(float(h.llr.max()) for h in rp.heat if h.llr.size)]),
                   max([0.05, *(float(h.trackers.max()) for h in rp.heat if h.trackers.size)]))

    def frame_data(self, frame: HeatFrame) -> list[dict[str, Any]]:
        """The changing traces at one heat frame, in the order of :meth:`traces`."""
        rp, s = self.rp, frame.step
        k, t, uav, peaks = s + 1, float(rp.time_s[s]), rp.uav_xy_m, rp.tracks[s]
        move = uav[k] - uav[k - 1]

        def at(nodes: IntArray, **more: Any) -> dict[str, Any]:
            """Points at ``nodes``, a NaN one first (an empty trace loses its legend entry)."""
            xy = np.vstack([[np.nan, np.nan], rp.nodes_xy_m[nodes]]).astype(np.float32)
            return {"x": xy[:, 0], "y": xy[:, 1], **more}

        return [
            at(frame.llr_nodes, marker={"color": np.r_[0.0, frame.llr].astype(np.float32),
                                        "cmin": 0.0, "cmax": self.lrt_max}),
            at(frame.tracker_nodes, marker={"color": np.r_[0.0, frame.trackers].astype(
                np.float32), "cmin": 0.0, "cmax": self.tracker_max}),
            _paths_upto(rp.target_xy_m, self.target_kept, k),
            {"x": rp.target_xy_m[k, :, 0], "y": rp.target_xy_m[k, :, 1]},
            *(_paths_upto(uav[:, j:j + 1], [kept], k) for j, kept in enumerate(self.uav_kept)),
            {"x": uav[k, :, 0], "y": uav[k, :, 1], "marker": {"angle": [  # clockwise from north
                round(float(a), 1) for a in np.degrees(np.arctan2(move[:, 0], move[:, 1]))]}},
            at(peaks[:, 1].astype(np.int64),
               marker={"size": [10.0, *(round(10 + 20 * p, 1) for p in peaks[:, 2].tolist())]},
               text=["", *(f"T{int(i)} {p:.2f}" for i, _, p in peaks.tolist())]),
            {"x": [t, t], "y": [0.0, 1.05]},
            {"x": [t, t, t], "y": [None if math.isnan(v) else v for v in rp.curves[:, s].tolist()]},
        ]

    def traces(self) -> list[go.Scatter]:
        """Every trace but the roads, styled; the changing ones hold the first frame."""
        first, u = self.frame_data(self.rp.heat[0]), self.rp.uav_xy_m.shape[1]

        def styled(i: int, marker: dict[str, Any], **style: Any) -> go.Scatter:
            return go.Scatter(**{**first[i], **style,
                                 "marker": {**first[i].get("marker", {}), **marker}})

        node = "node (%{x:.0f}, %{y:.0f}) m<br>"
        bar = {"yanchor": "top", "x": 1.0, "len": 0.3, "thickness": 12}
        colours = [UAV_COLOURS[j % len(UAV_COLOURS)] for j in range(u)]
        on_time = {"xaxis": "x2", "yaxis": "y2"}
        return [
            styled(0, {"size": 5, "colorscale": LRT_SCALE, "colorbar": {
                **bar, "title": {"text": "LRT φ"}, "y": 1.0}}, name="LRT evidence φ",
                mode="markers", hovertemplate=node + "φ = %{marker.color:.3g}<extra></extra>"),
            styled(1, {"size": 7, "colorscale": TRACKER_SCALE, "colorbar": {
                **bar, "title": {"text": "tracker p"}, "y": 0.62}}, name="tracker probability",
                mode="markers", hovertemplate=node + "p = %{marker.color:.3g}<extra></extra>"),
            styled(2, {}, name="target paths", mode="lines", hoverinfo="skip",
                   line={"color": "black", "width": 1, "dash": "dash"}),
            styled(3, {"symbol": "square", "size": 9, "color": "black"}, name="targets",
                   mode="markers", hovertemplate="target (%{x:.0f}, %{y:.0f}) m<extra></extra>"),
            *(styled(4 + j, {}, name=f"UAV {j + 1}", mode="lines", hoverinfo="skip",
                     line={"color": colours[j], "width": 1.5}) for j in range(u)),
            styled(4 + u, {"symbol": "triangle-up", "size": 14, "color": colours,
                           "line": {"color": "black", "width": 1}}, name="UAVs now",
                   mode="markers", hovertemplate="UAV (%{x:.0f}, %{y:.0f}) m<extra></extra>"),
            styled(5 + u, {"symbol": "circle-open", "color": "#3f007d", "line": {"width": 2}},
                   name="tracker peaks", mode="markers+text", textposition="top right",
                   textfont={"size": 11, "color": "#3f007d"},
                   hovertemplate="%{text}<extra></extra>"),
            *(go.Scatter(x=self.rp.time_s, y=curve, name=label, mode="lines",
                         line={"color": colour, "width": 1.5}, **on_time)
              for (label, colour), curve in zip(CURVES, self.rp.curves, strict=True)),
            styled(6 + u, {}, mode="lines", showlegend=False, hoverinfo="skip",
                   line={"color": "#555555", "width": 1, "dash": "dot"}, **on_time),
            styled(7 + u, {"size": 9, "color": [c for _, c in CURVES]}, mode="markers",
                   showlegend=False, hovertemplate="%{y:.3f}<extra></extra>", **on_time),
        ]


def replay_figure(record: Mapping[str, Any], *,
                  source: str | Path = "mission record") -> go.Figure:
    """The replay figure of a mission record (see the module docstring); a bad field raises
    :class:`ParseError` naming it and ``source`` (see :func:`read_replay`)."""
    return go.Figure(replay_spec(record, source=source))


def replay_spec(record: Mapping[str, Any], *,
                source: str | Path = "mission record") -> dict[str, Any]:
    """:func:`replay_figure` as plotly's JSON form, its frames as plain dicts: plotly checks
    the figure once instead of every frame's traces, the bulk of the page's time (the frames
    carry only keys of the traces checked with the figure)."""
    rp = read_replay(record, source)
    roads, scene = _road_lines(rp.nodes_xy_m, rp.edges), _Scene.of(rp)
    fig = make_subplots(rows=2, cols=1, row_heights=[0.72, 0.28], vertical_spacing=0.06)
    fig.add_traces([go.Scatter(x=roads[:, 0], y=roads[:, 1], mode="lines", name="roads",
                               hoverinfo="skip", line={"color": "#c8c8c8", "width": 1}),
                    *scene.traces()])
    last = len(fig.data)
    changing = [*range(1, last - len(CURVES) - 2), last - 2, last - 1]
    names = [str(h.step) for h in rp.heat]
    frames = [{"name": name, "traces": changing,
               "data": [{"type": "scatter", **data} for data in scene.frame_data(h)]}
              for name, h in zip(names, rp.heat, strict=True)]
    if frames:   # the page opens on the last frame: the whole mission, not an empty start
        for k, data in zip(changing, frames[-1]["data"], strict=True):
            fig.data[k].update({key: value for key, value in data.items() if key != "type"})
    every = np.vstack([rp.nodes_xy_m, rp.uav_xy_m.reshape(-1, 2), rp.target_xy_m.reshape(-1, 2)])
    lo, hi = every.min(axis=0), every.max(axis=0)
    pad = 0.03 * np.maximum(hi - lo, 1.0)
    still = {"frame": {"duration": 0, "redraw": False}, "mode": "immediate",
             "transition": {"duration": 0}}
    play = {**still, "frame": {"duration": FRAME_MS, "redraw": False}, "fromcurrent": True}
    u, m, g = rp.uav_xy_m.shape[1], rp.target_xy_m.shape[1], rp.time_s
    fig.update_layout(
        title={"text": f"{html.escape(rp.title)}<br><sup>{u} UAVs, {m} targets, {g.size} "
               f"steps to t = {g[-1]:.1f} s: beliefs, paths and tracker peaks at the slider's "
               "time</sup>", "x": 0.01, "y": 0.975, "yanchor": "top"},
        # 840 px: map, curves and slider fit a 1400 × 900 window with the browser's bars
        template="plotly_white", height=840, margin={"l": 60, "r": 20, "t": 110, "b": 80},
        xaxis={"range": [lo[0] - pad[0], hi[0] + pad[0]], "title": {"text": "east (m)"}},
        yaxis={"range": [lo[1] - pad[1], hi[1] + pad[1]], "title": {"text": "north (m)"},
               "scaleanchor": "x", "scaleratio": 1.0},
        xaxis2={"range": [0.0, float(g[-1])], "title": {"text": "time (s)"}},
        yaxis2={"range": [-0.02, 1.07], "title": {"text": "fraction"}},
        legend={"orientation": "h", "x": 0.0, "y": 1.01, "yanchor": "bottom"},
        updatemenus=[{"type": "buttons", "direction": "left", "x": 0.0, "y": -0.06,
                      "xanchor": "left", "yanchor": "top", "showactive": False, "buttons": [
                          {"label": "▶ play", "method": "animate", "args": [None, play]},
                          {"label": "❚❚ pause", "method": "animate", "args": [[None], still]}]}],
        sliders=[{"active": max(len(names) - 1, 0), "x": 0.14, "y": -0.03, "len": 0.86,
                  "yanchor": "top",
                  "font": {"color": "rgba(0,0,0,0)"}, "ticklen": 3, "minorticklen": 0,
                  "currentvalue": {"prefix": "t = ", "suffix": " s",
                                   "font": {"size": 13, "color": "#2a3f5f"}},
                  "steps": [{"label": f"{g[h.step]:.1f}", "method": "animate",
                             "args": [[name], still]}
                            for name, h in zip(names, rp.heat, strict=True)]}],
    )
    spec: dict[str, Any] = fig.to_plotly_json()
    spec["frames"] = frames
    return spec


def write_replay(record: Mapping[str, Any], path: str | Path, *,
                 source: str | Path = "mission record") -> Path:
    """Write the self-contained replay page of ``record`` (plotly.js embedded; the same record
    gives the same bytes) to ``path`` atomically; returns ``path``."""
    import plotly.io as pio

    spec = replay_spec(record, source=source)
    page: str = pio.to_html(spec, validate=False, include_plotlyjs=True, full_html=True,
                            auto_play=False, div_id="replay", config={"displaylogo": False})
    title = html.escape(f"{record['scenario']['name']}: mission replay")
    out = write_text_atomic(path, page.replace("<head>", f"<head><title>{title}</title>", 1))
    log.info("replay page %s: %d frames, %.1f MB", out, len(spec["frames"]), len(page) / 1e6)
    return out


def load_record(path: str | Path) -> dict[str, Any]:
    """A mission.json file's record, checked when drawn; :class:`ParseError` when the file is
    missing, unreadable or not a JSON object."""
    p = Path(path)
    value = read_json(p)  # ParseError naming the file when missing, unreadable or not JSON
    if not isinstance(value, dict):
        raise ParseError(p, None, None, f"must hold a JSON object, got {type(value).__name__}")
    return value
