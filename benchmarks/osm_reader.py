"""The OSM reader against the ecosystem's tools: osmnx (OSM XML → networkx) and pyproj (UTM).

    python benchmarks/osm_reader.py [--repeats 3]

Needs ``pip install osmnx`` (it brings pyproj, geopandas and shapely; searchtrack does not depend
on them). For each bundled map it times

* ``read_osm``: searchtrack's reader (iterparse, car highway filter, split at junctions, local
  equirectangular projection, largest component, 10 m resampling), end to end;
* ``osmnx``: ``graph_from_xml`` (its parser, unsimplified), the same car filter on the edges'
  ``highway`` tag, largest component, then ``project_graph`` (pyproj, UTM) — no resampling, so
  it does less work than ``read_osm``;

and compares the road lengths: total length of the kept roads by each (osmnx measures great-circle
lengths on the unprojected graph), and the largest relative error of the distance between 1000
random pairs of OSM nodes against the WGS84 geodesic, for the local equirectangular projection
and for UTM (whose scale factor alone is off by up to 4e-4).
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

import networkx as nx
import numpy as np

from searchtrack.models.osm import CAR_HIGHWAYS, read_osm
from searchtrack.models.projection import LocalProjection
from searchtrack.sim.roads.scenario import BUNDLED_MAPS, bundled_map


def _car(highway: object) -> bool:
    tags = highway if isinstance(highway, list) else [highway]
    return any(str(t) in CAR_HIGHWAYS for t in tags)


def osmnx_graph(path: str) -> tuple[nx.MultiDiGraph, nx.MultiDiGraph]:
    """osmnx's parse, the car filter, the largest component, projected to UTM with pyproj."""
    import osmnx as ox

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = ox.graph_from_xml(path, bidirectional=True, simplify=False, retain_all=True)
    drop = [(u, v, k) for u, v, k, d in g.edges(keys=True, data=True)
            if not _car(d.get("highway"))]
    g.remove_edges_from(drop)
    g.remove_nodes_from([n for n in list(g.nodes) if g.degree(n) == 0])
    g = ox.truncate.largest_component(g, strongly=False)
    return g, ox.project_graph(g)


def projection_errors(g: nx.MultiDiGraph, projected: nx.MultiDiGraph,
                      rng: np.random.Generator) -> tuple[float, float]:
    """Largest relative error of pair distances against the WGS84 geodesic (pyproj ``Geod``):
    for the local equirectangular projection and for osmnx's UTM projection."""
    from pyproj import Geod

    nodes = list(g.nodes)
    lon = np.array([g.nodes[n]["x"] for n in nodes])
    lat = np.array([g.nodes[n]["y"] for n in nodes])
    utm = np.array([[projected.nodes[n]["x"], projected.nodes[n]["y"]] for n in nodes])
    local = LocalProjection.about(np.radians(lat), np.radians(lon)).forward(
        np.radians(lat), np.radians(lon))
    i, j = rng.integers(0, lon.size, size=(2, 1000))
    i, j = i[i != j], j[i != j]
    _, _, true = Geod(ellps="WGS84").inv(lon[i], lat[i], lon[j], lat[j])
    true = np.asarray(true)

    def worst(xy: np.ndarray) -> float:
        return float(np.max(np.abs(np.linalg.norm(xy[i] - xy[j], axis=1) - true) / true))

    return worst(local), worst(utm)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    header = ("map", "read_osm s", "osmnx s", "nodes ours (10 m)", "OSM nodes osmnx",
              "road km ours", "road km osmnx", "local proj. err", "UTM err")
    rows: list[tuple[str, ...]] = []
    for name in BUNDLED_MAPS:
        path = str(bundled_map(name))
        ours_s, theirs_s = [], []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            net = read_osm(path)
            ours_s.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            g, projected = osmnx_graph(path)
            theirs_s.append(time.perf_counter() - t0)
        # each road once: osmnx stores both directions of a two-way street
        seen = {(min(u, v), max(u, v)): d["length"] for u, v, d in g.edges(data=True)}
        rows.append((name, f"{statistics.median(ours_s):.2f}",
                     f"{statistics.median(theirs_s):.2f}", str(net.n_nodes),
                     str(g.number_of_nodes()), f"{net.lengths_m.sum() / 1e3:.2f}",
                     f"{sum(seen.values()) / 1e3:.2f}",
                     *(f"{e:.1e}" for e in projection_errors(g, projected, rng))))
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    print("  ".join(h.rjust(w) for h, w in zip(header, widths, strict=True)))
    print("  ".join("-" * w for w in widths))
    for r in rows:
        print("  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)))


if __name__ == "__main__":
    main()
