"""Read a car road network from an OpenStreetMap XML file (``.osm``, or bz2-compressed), offline.

Thesis 001 §2.3 keeps "roads accessible by cars" without listing the ``highway`` types (its
Overpass query, Fig. 2.3, is not in the text). :data:`CAR_HIGHWAYS` is our reading of that: the
public street hierarchy and its ``*_link`` ramps, as in osmnx's ``drive`` network. Service roads
(driveways, parking aisles, alleys), tracks, footways, paths, cycleways, pedestrian streets,
steps, bridleways, bus-only ways and roads under construction are left out, as are ways tagged
``area=yes``, ``access=no|private``, ``motor_vehicle=no`` or ``motorcar=no``. Pass
``highway_types`` to choose otherwise.

The thesis treats the road graph as undirected (a symmetric ``A``, a random walk both ways), so
``oneway`` tags are ignored. Ways are split at nodes they share (the junctions) and where they
reference nodes missing from the extract (clipped at the map edge); the pieces go to
:func:`~searchtrack.models.road_builder.network_from_polylines` after a local equirectangular
projection about the centre of the roads' bounding box
(:class:`~searchtrack.models.projection.LocalProjection`).
"""

from __future__ import annotations

import io
import logging
import math
import time
import xml.etree.ElementTree as ET
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core.errors import ParseError
from searchtrack.core.files import open_input
from searchtrack.models.projection import LocalProjection
from searchtrack.models.road_builder import network_from_polylines
from searchtrack.models.roads import RoadNetwork, validate_spacing

log = logging.getLogger("searchtrack.models.osm")

CAR_HIGHWAYS: frozenset[str] = frozenset(
    {
        "motorway", "trunk", "primary", "secondary", "tertiary",
        "unclassified", "residential", "living_street", "road",
        "motorway_link", "trunk_link", "primary_link", "secondary_link", "tertiary_link",
    }
)
"""``highway=*`` values kept by default: streets a car may use (``road`` = not yet classified)."""

NO_CARS: dict[str, frozenset[str]] = {
    "area": frozenset({"yes"}),
    "access": frozenset({"no", "private"}),
    "motor_vehicle": frozenset({"no"}),
    "motorcar": frozenset({"no"}),
}
"""Tag values that exclude a way even when its ``highway`` type is kept."""

Way = tuple[int, list[int]]  # (way id, node ids)


#: Largest map read (bytes, after bzip2): a city extract; a country needs a tiler, not this reader.
MAX_OSM_BYTES = 512 * 2**20


@contextmanager
def _open(path: Path) -> Iterator[io.BufferedReader[Any]]:
    """The file as bytes, decompressed when it starts with the bzip2 magic ``BZh``, at most
    :data:`MAX_OSM_BYTES` (errors name the file: see :func:`~searchtrack.core.files.open_input`).
    """
    with open_input(path, max_bytes=MAX_OSM_BYTES) as fh:
        if not fh.peek(1):
            raise ParseError(path, None, None, "empty file: not an OpenStreetMap file")
        yield fh


def _coordinate(path: Path, where: str, name: str, text: str | None, bound: float) -> float:
    try:
        value = float(text) if text is not None else math.nan
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or abs(value) > bound:
        raise ParseError(path, None, f"{where} {name}", f"not a valid {name}: {text!r}")
    return value


Bounds = tuple[float, float, float, float]  # min lat, min lon, max lat, max lon (degrees)


def _bounds(path: Path, elem: ET.Element) -> Bounds:
    names = ("minlat", "minlon", "maxlat", "maxlon")
    values = [_coordinate(path, "bounds", k, elem.get(k), 180.0) for k in names]
    return values[0], values[1], values[2], values[3]


def _parse(
    path: Path, highway_types: frozenset[str]
) -> tuple[dict[int, tuple[float, float]], list[Way], Counter[str], Bounds | None]:
    """Nodes (id → lat, lon in degrees), the kept ways, a count of every highway type seen, and
    the ``<bounds>`` of the extract if given."""
    nodes: dict[int, tuple[float, float]] = {}
    bounds: Bounds | None = None
    ways: list[Way] = []
    seen: Counter[str] = Counter()
    root: ET.Element | None = None
    with _open(path) as fh:
        try:
            for event, elem in ET.iterparse(fh, events=("start", "end")):
                if root is None:
                    root = elem
                    if elem.tag != "osm":
                        raise ParseError(
                            path, None, None,
                            f"root element is <{elem.tag}>, not <osm>: not an OpenStreetMap file",
                        )
                if event != "end":
                    continue
                if elem.tag == "node":
                    nid = elem.get("id", "?")
                    lat = _coordinate(path, f"node {nid}", "lat", elem.get("lat"), 90.0)
                    lon = _coordinate(path, f"node {nid}", "lon", elem.get("lon"), 180.0)
                    nodes[_int_id(path, "node", nid)] = (lat, lon)
                elif elem.tag == "way":
                    tags = {t.get("k", ""): t.get("v", "") for t in elem.iterfind("tag")}
                    highway = tags.get("highway")
                    if highway is not None:
                        seen[highway] += 1
                        if highway in highway_types and not any(
                            tags.get(k) in bad for k, bad in NO_CARS.items()
                        ):
                            wid = _int_id(path, "way", elem.get("id", "?"))
                            refs = [_int_id(path, f"way {wid} nd", nd.get("ref", "?"))
                                    for nd in elem.iterfind("nd")]
                            ways.append((wid, refs))
                elif elem.tag == "bounds":
                    bounds = _bounds(path, elem)
                elif elem.tag != "relation":
                    continue
                root.clear()  # keep memory flat: processed elements are not needed again
        except ET.ParseError as exc:
            line = exc.position[0] if exc.position else None
            raise ParseError(path, line, None, f"not well-formed XML: {exc}") from None
    return nodes, ways, seen, bounds


def _int_id(path: Path, what: str, text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise ParseError(path, None, what, f"not an integer id: {text!r}") from None


def _runs(ways: list[Way], nodes: dict[int, tuple[float, float]]) -> list[list[int]]:
    """Each way cut into runs of ≥ 2 consecutive nodes present in the file."""
    runs: list[list[int]] = []
    for _, refs in ways:
        run: list[int] = []
        for ref in [*refs, None]:
            if ref is not None and ref in nodes:
                run.append(ref)
                continue
            if len(run) >= 2:
                runs.append(run)
            run = []
    return runs


def _split_at_junctions(runs: list[list[int]]) -> list[list[int]]:
    """Cut runs at every node used more than once (shared by ways, or revisited by one way)."""
    uses = Counter(ref for run in runs for ref in run)
    for run in runs:
        uses[run[0]] += 1
        uses[run[-1]] += 1
    pieces: list[list[int]] = []
    for run in runs:
        start = 0
        for k in range(1, len(run)):
            if uses[run[k]] > 1 or k == len(run) - 1:
                pieces.append(run[start : k + 1])
                start = k
    return pieces


def read_osm(
    path: str | Path,
    spacing_m: float = 10.0,
    *,
    highway_types: frozenset[str] = CAR_HIGHWAYS,
    largest_component: bool = True,
    clip_to_bounds: bool = False,
) -> RoadNetwork:
    """The car road network of an OSM XML file, resampled every ``spacing_m`` metres.

    Parameters
    ----------
    path
        An ``.osm`` file, plain or bzip2-compressed (detected from its content).
    spacing_m
        Largest node spacing along a road (m); 10 m in the thesis (Table 6.2).
    highway_types
        ``highway=*`` values to keep; :data:`CAR_HIGHWAYS` by default.
    largest_component
        Keep only the largest connected component (the default).
    clip_to_bounds
        Drop the nodes outside the file's ``<bounds>`` (extracts often hold whole ways reaching
        far outside the snapshot), cutting roads at their last node inside. Off by default.

    Raises
    ------
    ParseError
        Naming the file: missing or unreadable, not XML, not OSM, or no road of the kept types.
    InvalidInputError
        For a bad ``spacing_m``.
    """
    spacing = validate_spacing(spacing_m)
    p = Path(path)
    t0 = time.perf_counter()
    nodes, ways, seen, bounds = _parse(p, frozenset(highway_types))
    t_parse = time.perf_counter() - t0
    if clip_to_bounds:
        if bounds is None:
            raise ParseError(p, None, "bounds", "clip_to_bounds needs a <bounds> element")
        lat0, lon0, lat1, lon1 = bounds
        nodes = {k: v for k, v in nodes.items() if lat0 <= v[0] <= lat1 and lon0 <= v[1] <= lon1}
    if not seen:
        raise ParseError(p, None, "highway", "no roads: no way is tagged highway=*")
    if not ways:
        raise ParseError(
            p, None, "highway",
            f"no car-accessible roads: highway types present are {sorted(seen)}, "
            f"kept types are {sorted(highway_types)} (and not access=no/private)",
        )
    pieces = _split_at_junctions(_runs(ways, nodes))
    if not pieces:
        raise ParseError(p, None, "nd", "the kept roads reference no two nodes present in the file")
    used = np.array(sorted({ref for piece in pieces for ref in piece}), dtype=np.int64)
    latlon = np.radians(np.array([nodes[int(ref)] for ref in used]))
    projection = LocalProjection.about(latlon[:, 0], latlon[:, 1])
    xy = projection.forward(latlon[:, 0], latlon[:, 1])
    polylines = [xy[np.searchsorted(used, piece)] for piece in pieces]
    network = network_from_polylines(
        polylines, spacing, source=p.name, projection=projection,
        largest_component=largest_component,
    )
    log.info(
        "%s: %d kept ways of %d roads; %d nodes, %d edges, %.0f m, %d intersections; "
        "parse %.3f s, total %.3f s, projection scale error ≤ %.1e",
        p.name, len(ways), sum(seen.values()), network.n_nodes, network.n_edges,
        network.total_length_m, network.n_intersections, t_parse, time.perf_counter() - t0,
        projection.max_scale_error(network.coords),
    )
    return network
