"""The replay page: what mission.json records for it (map, sparse heat frames, the frame cap),
the figure's frames, slider and time-linked cursor, the self-contained HTML, and bad records
failing with the field named."""

from __future__ import annotations

import copy
import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import ParseError
from searchtrack.estimate import LikelihoodField, TrackerBank
from searchtrack.models import grid_network
from searchtrack.sim.roads.metrics import StepScore
from searchtrack.sim.roads.mission import Mission
from searchtrack.sim.roads.record import (
    HEAT_MAX_NODES,
    MAX_HEAT_FRAMES,
    HeatFrame,
    Recorder,
    StepTimes,
    heat_steps,
    sparse_top,
)
from searchtrack.sim.roads.replay_page import (
    _kept,
    _road_lines,
    load_record,
    read_replay,
    replay_figure,
    write_replay,
)
from searchtrack.sim.roads.scenario import MapSpec, Scenario
from tests.sim.roads.mission_logs import SCENARIO, SENSOR, StepAnswer, two_step_log

GRID = MapSpec("grid", rows=4, cols=4, block_m=100.0, spacing_m=25.0)


def _mission(duration_s: float, mode: str = "track") -> dict[str, Any]:
    """The JSON record of a short mission on a 4 × 4 grid, through a JSON round trip."""
    sc = Scenario("replay", GRID, uav_count=2, target_count=2, sensor=SENSOR, altitude_m=None,
                  duration_s=duration_s, dt_s=0.3, seed=3, mode=mode)
    record: dict[str, Any] = json.loads(json.dumps(Mission(sc).run().to_json()))
    return record


@pytest.fixture(scope="module")
def record() -> dict[str, Any]:
    """A 20-step mission's record."""
    return _mission(6.0)


def test_heat_steps_are_even_capped_and_keep_both_ends() -> None:
    """At most the cap, evenly spaced, the first and last step always; every step when
    fewer."""
    steps = heat_steps(800)
    assert steps.size == MAX_HEAT_FRAMES and steps[0] == 0 and steps[-1] == 799
    assert set(np.diff(steps).tolist()) <= {5, 6}
    np.testing.assert_array_equal(heat_steps(20), np.arange(20))
    assert heat_steps(0).size == 0


def test_sparse_top_keeps_the_highest_above_the_threshold() -> None:
    """Only values above the threshold, at most the HEAT_MAX_NODES highest, nodes ascending."""
    values = np.zeros(2000)
    values[::2] = np.linspace(0.01, 1.0, 1000)
    nodes, kept = sparse_top(values, 0.05)
    assert nodes.size == HEAT_MAX_NODES and np.all(np.diff(nodes) > 0)
    assert kept.min() >= np.sort(values)[-HEAT_MAX_NODES] and kept.max() == 1.0
    nodes, kept = sparse_top(np.array([0.0, 0.2, 0.01, 3.0]), 0.05)
    assert nodes.tolist() == [1, 3] and kept.tolist() == [0.2, 3.0]


def test_heat_frame_json_is_sparse_and_rounded() -> None:
    """φ above 0.05 and tracker mass above 1e-3 only, values to 3 significant digits."""
    llr = np.array([-4.0, 0.01, 1.23456, 0.0, 123.456, 0.0612345, 0.0, 0.0])
    p = np.zeros(8)
    p[[2, 5]] = 0.000123456, 0.99876
    frame = HeatFrame.capture(4, LikelihoodField(llr), TrackerBank(8).with_birth(p / p.sum()))
    assert frame.to_json()["step"] == 4
    assert frame.to_json()["llr"] == {"nodes": [2, 4, 5], "values": [1.23, 123.0, 0.0612]}
    assert frame.to_json()["trackers"] == {"nodes": [5], "values": [1.0]}


def test_json_round_trip_holds_the_map_and_heat() -> None:
    """The map's nodes (to 0.1 m) and edges, and the beliefs after the last step as a heat
    frame (the hand-made log never asked for one)."""
    log = two_step_log()
    d = json.loads(json.dumps(log.to_json()))
    np.testing.assert_allclose(d["map"]["nodes_xy_m"], np.round(log.network.coords, 1))
    assert d["map"]["edges"] == log.network.edges.tolist()
    assert d["heat"]["llr_min"] == 0.05 and d["heat"]["tracker_min"] == 0.001
    assert d["heat"]["max_nodes"] == HEAT_MAX_NODES
    assert d["heat"]["frames"] == [{"step": 1, "llr": {"nodes": [2, 3, 7],
                                                       "values": [2.0, 5.0, 0.5]},
                                    "trackers": {"nodes": [2, 3], "values": [0.3, 0.7]}}]


def test_mission_records_a_frame_per_step_when_short(record: dict[str, Any]) -> None:
    """A 20-step mission keeps every step as a heat frame, and the record draws."""
    assert [f["step"] for f in record["heat"]["frames"]] == list(range(20))
    assert len(record["map"]["nodes_xy_m"]) == record["network"]["nodes"]
    assert len(read_replay(record).heat) == 20


def test_long_mission_keeps_the_frame_cap() -> None:
    """200 steps: 150 evenly spaced frames, the last step among them."""
    steps = [f["step"] for f in _mission(60.0)["heat"]["frames"]]
    assert len(steps) == MAX_HEAT_FRAMES and steps[0] == 0 and steps[-1] == 199
    assert steps == sorted(set(steps))


def test_a_mission_ending_early_keeps_its_last_step() -> None:
    """A recorder stopped after 3 of 12 planned steps (frames planned at 0, 4, 7 and 11)
    keeps steps 0 and 2."""
    net = grid_network(2, 2, 100.0, 50.0)
    rec = Recorder(dataclasses.replace(SCENARIO, duration_s=3.6), net, np.zeros((2, 2)),
                   np.zeros((2, 2)), max_heat_frames=4)
    assert heat_steps(12, 4).tolist() == [0, 4, 7, 11]
    bank = TrackerBank(net.n_nodes)
    for k in range(3):
        rec.add(0.3 * (k + 1), np.zeros((2, 2)), np.zeros((2, 2)), StepScore(0, 0, 0, 0),
                StepAnswer(("search", "search"), 0.0), StepTimes(), bank, [])
        if rec.heat_due():
            rec.add_heat(LikelihoodField.neutral(net.n_nodes), bank)
    log = rec.finish(LikelihoodField.neutral(net.n_nodes), bank, np.full(2, np.nan))
    assert [h.step for h in log.heat] == [0, 2]


def test_roads_are_one_polyline_through_every_edge() -> None:
    """Each edge is a pair of consecutive points of the polyline; chains share their nodes."""
    net = grid_network(3, 3, 100.0, 25.0)
    line = _road_lines(net.coords, net.edges)
    segments = np.stack([line[:-1], line[1:]], axis=1)
    segments = segments[np.isfinite(segments).all(axis=(1, 2))]
    pairs = {tuple(sorted(map(tuple, seg))) for seg in segments.tolist()}
    assert pairs == {tuple(sorted(map(tuple, net.coords[e].astype(np.float32).tolist())))
                     for e in net.edges}
    assert len(line) < 3 * len(net.edges)


def test_paths_keep_their_ends_and_bends() -> None:
    """Straight runs and stops shrink to their ends; a bend above the tolerance stays."""
    path = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 0.0], [3.0, 0.0], [3.0, 5.0],
                     [3.0, 10.0]])
    assert _kept(path).tolist() == [0, 4, 6]
    assert _kept(path, tolerance_m=10.0).tolist() == [0, 6]


def test_figure_has_a_frame_and_slider_step_per_heat_frame(record: dict[str, Any]) -> None:
    """One plotly frame and one slider step per heat frame, a play / pause button, plain SVG
    scatter traces only, and the time cursor moving with the frames."""
    fig = replay_figure(record)
    frames = record["heat"]["frames"]
    assert len(fig.frames) == len(frames) == len(fig.layout.sliders[0].steps)
    assert [f.name for f in fig.frames] == [s.args[0][0] for s in fig.layout.sliders[0].steps]
    assert [b.label for b in fig.layout.updatemenus[0].buttons] == ["▶ play", "❚❚ pause"]
    assert {t.type for t in fig.data} == {"scatter"}
    cursor = len(fig.data) - 2
    for frame, heat in zip(fig.frames, frames, strict=True):
        assert cursor in frame.traces and len(frame.data) == len(frame.traces)
        t = record["time_s"][heat["step"]]
        assert list(frame.data[frame.traces.index(cursor)].x) == [t, t]
    title = fig.layout.title.text
    assert all(w in title for w in ("replay", "grid 4x4", record["scenario"]["strategy"]))


def test_page_is_self_contained_and_deterministic(record: dict[str, Any],
                                                  tmp_path: Path) -> None:
    """plotly.js is embedded (no script loaded from the network); the same record writes the
    same bytes, atomically."""
    a = write_replay(record, tmp_path / "a.html")
    b = write_replay(copy.deepcopy(record), tmp_path / "b.html")
    page = a.read_text(encoding="utf-8")
    assert page.startswith("<!doctype html>") and "<title>replay: mission replay</title>" in page
    assert '<script src="http' not in page and "<script src=" not in page
    assert "plotly.js v" in page and len(page) > 3_000_000
    assert a.read_bytes() == b.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.html", "b.html"]


def _edit(path: str, value: Any) -> Any:
    """An edit of the record at a dotted/indexed path (``map.edges.0.1``); ``...`` deletes."""
    def apply(record: dict[str, Any]) -> None:
        *parents, last = path.split(".")
        node: Any = record
        for key in parents:
            node = node[int(key)] if isinstance(node, list) else node[key]
        key: Any = int(last) if isinstance(node, list) else last
        if value is ...:
            del node[key]
        else:
            node[key] = value
    return apply


BAD = [
    ("map", ..., "map", "re-run `searchtrack mission run`"),
    ("heat", ..., "heat", "missing key"),
    ("scenario.name", 3, "scenario.name", "must be a string"),
    ("map.nodes_xy_m", "x", "map.nodes_xy_m", "must be a list"),
    ("map.nodes_xy_m.1", [0.0], "map.nodes_xy_m", "[x, y] node positions"),
    ("map.edges.0.1", 10**6, "map.edges[0][1]", "node index"),
    ("uav_xy_m.1.0.0", math.nan, "uav_xy_m[1][0][0]", "nan"),
    ("uav_xy_m.1.0.1", 1e300, "uav_xy_m[1][0][1]", "≤ 1e+09"),
    ("map.nodes_xy_m.0.0", -1e39, "map.nodes_xy_m[0][0]", "≤ 1e+09"),
    ("target_xy_m.2.1.1", "5", "target_xy_m[2][1][1]", "'5'"),
    ("moc.3", 1.5, "moc[3]", "fractions"),
    ("trackers.0", True, "trackers[0]", "True"),
    ("valid_trackers.0", 0.5, "valid_trackers[0]", "counts"),
    ("valid_trackers.1", 1e19, "valid_trackers[1]", "counts"),
    ("time_s", [], "time_s", "is empty"),
    ("tracks", [], "tracks", "one per step"),
    ("heat.frames", [], "heat.frames", "non-empty"),
    ("heat.frames.0.step", 99, "heat.frames[0].step", "step index"),
    ("heat.frames.1.step", 0, "heat.frames[1].step", "after the previous"),
    ("heat.frames.0.llr.values", [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0],
     "heat.frames[0].llr.values", "shape"),
    ("heat.frames.0.trackers", {"nodes": [0], "values": [-1.0]},
     "heat.frames[0].trackers.values[0]", "≥ 0"),
    ("heat.frames.0.trackers", {"nodes": [0], "values": [math.inf]},
     "heat.frames[0].trackers.values[0]", "inf"),
]


@pytest.mark.parametrize(("path", "value", "field", "words"), BAD, ids=[b[0] for b in BAD])
def test_bad_records_name_the_field(record: dict[str, Any], path: str, value: Any,
                                    field: str, words: str) -> None:
    """A missing, ill-typed or out-of-range field raises ParseError naming the source and the
    field."""
    bad = copy.deepcopy(record)
    _edit(path, value)(bad)
    with pytest.raises(ParseError) as info:
        replay_figure(bad, source="m.json")
    assert info.value.field == field
    assert str(info.value).startswith("m.json, field ") and words in str(info.value)


def test_tracks_are_checked_per_column(record: dict[str, Any]) -> None:
    """A tracker's peak node must be on the map and its probability at most 1; its id may be
    any integer ≥ 0."""
    good = copy.deepcopy(record)
    good["tracks"][0] = [[10**6, 0, 0.5]]
    read_replay(good)
    for row, field in (([0, 10**6, 0.5], "tracks[0][0][1]"), ([0, 1, 1.5], "tracks[0][0][2]"),
                       ([0.5, 1, 0.5], "tracks[0][0][0]")):
        good["tracks"][0] = [row]
        with pytest.raises(ParseError) as info:
            read_replay(good)
        assert info.value.field == field


@pytest.mark.parametrize(("text", "words"), [
    (None, "no such file"), ("{\"a\": ", "not valid JSON"), ("[1, 2]", "JSON object"),
    ("{\"a\": " * 100_000, "not valid JSON")])
def test_load_record_reports_bad_files(tmp_path: Path, text: str | None, words: str) -> None:
    """A missing file, malformed JSON, or JSON that is not an object: ParseError naming the
    file."""
    path = tmp_path / "mission.json"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    with pytest.raises(ParseError, match=words) as info:
        load_record(path)
    assert str(path) in str(info.value)
