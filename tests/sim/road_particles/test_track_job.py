"""Offline road RBPF jobs: DETECTIONS.json read and validated, filtered, EST.json written; every
malformed file is a ParseError naming the JSON key."""

from __future__ import annotations

import copy
import importlib.util
import itertools
import json
import math
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import ParseError
from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.sim.road_particles.track_job import (
    read_road_job,
    run_road_track_job,
    write_road_estimates,
)
from searchtrack.sim.roads.scenario import MapSpec

ROOT = Path(__file__).parents[3]
EXAMPLE = ROOT / "examples" / "problems" / "road_detections.json"
TINY_OSM = ROOT / "tests" / "data" / "osm" / "tiny.osm"

#: A valid 3-step document: the 3×3 grid of 100 m roads, two targets, a small filter.
GOOD: dict[str, Any] = {
    "map": {"grid": [3, 3], "spacing_m": 100.0}, "dt": 0.1, "targets": 2,
    "target_speed_mps": 10.0, "speed_sigma_mps": 4.0,
    "sensor": {"fov_radius_m": 30.0, "sigma2_m2": 5.0, "p_fa": 0.01, "p_fn": 0.1},
    "filter": {"histories": 4, "particles": 100},
    "uav_xy": [[100.0, 100.0], [100.0, 105.0], [100.0, 110.0]],
    "detections": [[], [[101.0, 104.0]], [[100.0, 111.0], [99.0, 90.0]]],
}


@cache
def simulator() -> ModuleType:
    """``examples/make_road_detections.py`` as a module (its ``simulate`` makes recordings)."""
    spec = importlib.util.spec_from_file_location("make_road_detections",
                                                  ROOT / "examples" / "make_road_detections.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_json(tmp_path: Path, doc: object, name: str = "detections.json") -> Path:
    """``doc`` written as JSON to ``tmp_path / name``."""
    path = tmp_path / name
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def mutated(path: str, value: object, base: dict[str, Any] | None = None) -> dict[str, Any]:
    """A copy of ``base`` (default :data:`GOOD`) with the dotted ``path`` (digits index lists)
    set to ``value``, or deleted for ``KeyError``."""
    doc = copy.deepcopy(GOOD if base is None else base)
    keys = path.split(".")
    target: Any = doc
    for key in keys[:-1]:
        target = target[int(key)] if key.isdigit() else target[key]
    last: Any = int(keys[-1]) if keys[-1].isdigit() else keys[-1]
    if value is KeyError:
        del target[last]
    else:
        target[last] = value
    return doc


#: ``(dotted path, value or KeyError to delete, the field the error must name)``.
BAD_INPUTS: list[tuple[str, object, str]] = [
    # missing and unknown keys, at every level
    ("dt", KeyError, "dt"), ("map", KeyError, "map"), ("targets", KeyError, "targets"),
    ("sensor.p_fn", KeyError, "sensor.p_fn"), ("filter.particles", KeyError, "filter.particles"),
    ("map.spacing_m", KeyError, "map.spacing_m"), ("uav_xy", KeyError, "uav_xy"),
    ("detections", KeyError, "detections"), ("dtt", 0.1, "dtt"), ("map.rows", 3, "map.rows"),
    ("sensor.pd", 0.9, "sensor.pd"), ("filter.resample", "always", "filter.resample"),
    # wrong types and shapes
    ("uav_xy.0", [1.0, 2.0, 3.0], "uav_xy[0]"), ("uav_xy", {"0": [1, 2]}, "uav_xy"),
    ("uav_xy", [], "uav_xy"), ("detections.1", [101.0, 104.0], "detections[1][0]"),
    ("detections.1", 5, "detections[1]"), ("detections.2.0", [1.0], "detections[2][0]"),
    ("detections.1.0.1", "x", "detections[1][0][1]"), ("map.grid", [3], "map.grid"),
    ("map.grid", [3, 1], "map.grid[1]"), ("map.grid", [3, 2.5], "map.grid[1]"),
    ("sensor", [30.0], "sensor"), ("filter", None, "filter"), ("targets", 2.0, "targets"),
    ("targets", True, "targets"), ("dt", "0.1", "dt"),
    # steps of uav_xy and detections differ
    ("detections", [[], []], "detections"), ("uav_xy", [[100.0, 100.0]] * 4, "detections"),
    # NaN, inf, overflow
    ("dt", math.nan, "dt"), ("detections.1.0.1", math.inf, "detections[1][0][1]"),
    ("uav_xy.2.0", math.nan, "uav_xy[2][0]"), ("target_speed_mps", math.inf, "target_speed_mps"),
    ("sensor.sigma2_m2", 10**400, "sensor.sigma2_m2"),
    # negative or zero values
    ("dt", -0.1, "dt"), ("dt", 0, "dt"), ("target_speed_mps", -1.0, "target_speed_mps"),
    ("speed_sigma_mps", -0.5, "speed_sigma_mps"), ("sensor.fov_radius_m", 0.0,
                                                    "sensor.fov_radius_m"),
    ("sensor.sigma2_m2", -5.0, "sensor.sigma2_m2"), ("targets", 0, "targets"),
    ("filter.histories", -1, "filter.histories"), ("filter.particles", 0, "filter.particles"),
    ("map.spacing_m", -100.0, "map.spacing_m"), ("seed", -1, "seed"),
    ("measure_every", 0, "measure_every"),
    # probabilities out of range
    ("sensor.p_fa", 1.0, "sensor.p_fa"), ("sensor.p_fn", -0.1, "sensor.p_fn"),
    ("sensor.p_fn", 1.5, "sensor.p_fn"), ("sensor.negative_radius_factor", 0.0,
                                          "sensor.negative_radius_factor"),
    # off the map area (the 0–200 m grid enlarged by the 30 m view)
    ("detections.1.0", [500.0, 100.0], "detections[1][0]"), ("uav_xy.2", [-100.0, 0.0],
                                                             "uav_xy[2]"),
    ("detections.2.1", [100.0, 231.0], "detections[2][1]"),
    # maps that cannot be read or built
    ("map", {"osm": "no-such-map.osm"}, "map.osm"), ("map", {"osm": 5}, "map.osm"),
    ("map", {}, "map"), ("map", {"grid": [3, 3], "osm": "West-Oakland"}, "map"),
    ("map", {"grid": [1000, 1000], "spacing_m": 1.0}, "map.grid"),
    ("map", {"osm": "West-Oakland", "spacing_m": 0.5}, "map.spacing_m"),
    # options
    ("filter.association", "greedy", "filter.association"),
    ("sensor.clutter", "sky", "sensor.clutter"),
    ("filter", {"histories": 1000, "particles": 10000}, "filter.particles"),
    ("measure_every", 2, "detections[2]"),  # step 2 is no scan but has detections
    # sizes
    ("detections.1", [[100.0, 100.0]] * 10_001, "detections[1]"),
]


@pytest.fixture
def stop_cleared() -> Iterator[None]:
    """The process-wide stop flag cleared before and after the test."""
    clear_stop()
    yield
    clear_stop()


def test_a_simulated_recording_is_tracked(tmp_path: Path) -> None:
    """Once a target is seen, the MAP estimate at each of its detections lies within a few
    metres of it (filter labels matched to the truth by the best permutation)."""
    doc, truth, sources = simulator().simulate(3, 300, uav_speed_mps=40.0)
    doc["filter"] = {"histories": 4, "particles": 300}
    job = read_road_job(write_json(tmp_path, doc))
    result = run_road_track_job(job, seed=3)
    assert result.steps == 300 and not result.interrupted
    seen = [(k, j) for k, src in enumerate(sources) if k >= 50 for j in src[src >= 0]]
    assert len(seen) > 100
    best = min((np.array([np.hypot(*(result.estimates[k, perm[j]] - truth[k, j]))
                          for k, j in seen]) for perm in itertools.permutations(range(2))),
               key=np.median)
    assert np.median(best) < 3.0 and best.max() < 10.0
    assert np.all(result.entropy[-1] < 3.0)  # both targets localised (uniform: about 6 nats)


def test_the_example_is_what_its_script_makes() -> None:
    """``examples/problems/road_detections.json`` is ``make_road_detections.py``'s output."""
    doc, truth, _ = simulator().simulate()
    shipped = json.loads(EXAMPLE.read_text(encoding="utf-8"))
    assert shipped == json.loads(json.dumps(doc))
    assert truth.shape == (200, 2, 2)
    job = read_road_job(EXAMPLE)
    assert (job.n_steps, job.n_scans, job.config.n_targets) == (200, 200, 2)


def test_a_seed_fixes_the_estimates(tmp_path: Path) -> None:
    """The same seed gives the same estimates and entropies; another seed other ones."""
    job = read_road_job(write_json(tmp_path, GOOD))
    a, b, c = (run_road_track_job(job, seed) for seed in (5, 5, 6))
    np.testing.assert_array_equal(a.estimates, b.estimates)
    np.testing.assert_array_equal(a.entropy, b.entropy)
    np.testing.assert_array_equal(a.combined_entropy, b.combined_entropy)
    assert not np.array_equal(a.estimates, c.estimates)


def test_only_scan_steps_update(tmp_path: Path) -> None:
    """With ``measure_every = 5`` steps 4 and 9 are scans: the entropy of target 0 stays
    uniform until its detection at step 4; the file's seed is kept."""
    doc = dict(GOOD, measure_every=5, seed=7, uav_xy=[[100.0, 100.0]] * 10,
               detections=[[]] * 4 + [[[100.0, 101.0]]] + [[]] * 5)
    job = read_road_job(write_json(tmp_path, doc))
    assert [k for k in range(10) if job.is_scan(k)] == [4, 9]
    assert (job.n_scans, job.n_detections, job.seed) == (2, 1, 7)
    ent = run_road_track_job(job, job.seed).entropy
    assert np.all(ent[:4, 0] > 4.0) and ent[4, 0] < 3.0  # 100 particles: at most 4.6 nats


def test_osm_maps_bundled_and_by_path(tmp_path: Path) -> None:
    """``map.osm`` takes a bundled map name or a file relative to the JSON file."""
    doc = mutated("map", {"osm": "West-Oakland", "spacing_m": 20.0},
                  dict(GOOD, uav_xy=[[0.0, 0.0]] * 3, detections=[[], [], []]))
    job = read_road_job(write_json(tmp_path, doc))
    assert job.map_label.startswith("West-Oakland") and job.roads.n_edges > 100
    assert run_road_track_job(job, 0).steps == 3
    (tmp_path / "maps").mkdir()
    (tmp_path / "maps" / "tiny.osm").write_bytes(TINY_OSM.read_bytes())
    node = MapSpec("osm", TINY_OSM, 10.0).build().coords[0].tolist()
    doc = mutated("map", {"osm": "maps/tiny.osm"}, dict(doc, uav_xy=[node] * 3))
    job = read_road_job(write_json(tmp_path, doc, "tiny.json"))
    assert job.map_label == "tiny.osm" and run_road_track_job(job, 0).steps == 3


def test_a_stop_request_keeps_the_steps_done(tmp_path: Path, stop_cleared: None) -> None:
    """A stop request during step 2 ends the run before step 3; EST.json holds 3 steps."""
    doc = dict(GOOD, uav_xy=GOOD["uav_xy"] * 3, detections=GOOD["detections"] * 3)
    job = read_road_job(write_json(tmp_path, doc))

    def progress(done: int, total: int) -> None:
        assert total == 9
        if done == 3:
            request_stop()

    result = run_road_track_job(job, 0, progress)
    assert result.steps == 3 and result.interrupted
    out = write_road_estimates(result, tmp_path / "est.json")
    record = json.loads(out.read_text(encoding="utf-8"))
    assert set(record) == {"estimates", "entropy", "combined_entropy", "ms_per_step",
                           "interrupted"}
    assert np.shape(record["estimates"]) == (3, 2, 2) and np.shape(record["entropy"]) == (3, 2)
    assert len(record["combined_entropy"]) == 3 and record["interrupted"] is True


@pytest.mark.parametrize(("path", "value", "field"), BAD_INPUTS,
                         ids=[f"{p}={v!r}"[:60] for p, v, _ in BAD_INPUTS])
def test_malformed_files_name_the_key(tmp_path: Path, path: str, value: object,
                                      field: str) -> None:
    """Every malformed DETECTIONS.json raises ParseError naming the file and the JSON key."""
    bad = write_json(tmp_path, mutated(path, value))
    with pytest.raises(ParseError) as err:
        read_road_job(bad)
    assert err.value.field == field
    assert str(bad) in str(err.value) and "\n" not in str(err.value)


def test_unreadable_documents_name_the_file(tmp_path: Path) -> None:
    """Not JSON, not an object, a corrupt OSM file: a ParseError naming the file (and line or
    key)."""
    broken = tmp_path / "broken.json"
    broken.write_text('{"dt": 0.1,\n "map": [', encoding="utf-8")
    with pytest.raises(ParseError, match="line 2"):
        read_road_job(broken)
    with pytest.raises(ParseError) as err:
        read_road_job(write_json(tmp_path, [GOOD]))
    assert err.value.field == "(top level)"
    (tmp_path / "junk.osm").write_text("<osm><way", encoding="utf-8")
    with pytest.raises(ParseError) as err:
        read_road_job(write_json(tmp_path, mutated("map", {"osm": "junk.osm"})))
    assert err.value.field == "map.osm" and "junk.osm" in str(err.value)
    with pytest.raises(ParseError, match="no such file"):
        read_road_job(tmp_path / "missing.json")


def test_an_output_too_large_is_refused(tmp_path: Path) -> None:
    """More than 5 million step × target estimates: an error naming ``uav_xy``."""
    doc = dict(GOOD, targets=1000, filter={"histories": 1, "particles": 1},
               uav_xy=[[100.0, 100.0]] * 5001, detections=[[]] * 5001)
    with pytest.raises(ParseError) as err:
        read_road_job(write_json(tmp_path, doc))
    assert err.value.field == "uav_xy"
