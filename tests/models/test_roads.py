"""Road networks: OSM import, resampling, graph matrices, distances, synthetic networks, errors."""

from __future__ import annotations

import bz2
import math
from collections.abc import Callable
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.models import (
    CAR_HIGHWAYS,
    LocalProjection,
    RoadNetwork,
    grid_network,
    network_from_polylines,
    random_network,
    read_osm,
)

TINY = Path(__file__).parents[1] / "data" / "osm" / "tiny.osm"
BUNDLED = Path(__file__).parents[2] / "searchtrack" / "data" / "osm"  # copies of ../shared

# 0.001° of longitude and 0.0009° of latitude at 45°N on WGS84 (geodesy tables: 78 847 m and
# 111 133 m per degree).
EW_M = 78.847
NS_M = 100.02

# (nodes, edges, total length m, intersections) at 10 m spacing, as first measured
REAL_MAPS = {
    "West-Oakland.osm.bz2": (677, 682, 6641.1, 14),
    "aguascalientes.osm.bz2": (8602, 8917, 83324.5, 602),
}


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _osm(body: str) -> str:
    return f'<?xml version="1.0"?>\n<osm version="0.6">\n{body}\n</osm>\n'


# ----- the hand-written file --------------------------------------------------------------------


def test_tiny_file_keeps_only_car_roads() -> None:
    """The tiny map keeps A-B-C, B-D, C-G and D-G; footway, service, private and far roads go."""
    net = read_osm(TINY)
    # 3 roads of 78.85 m in 8 pieces and 2 of 100.02 m in 11 pieces, 5 junctions
    assert net.n_nodes == 5 + 3 * 7 + 2 * 10
    assert net.n_edges == 3 * 8 + 2 * 11
    assert net.total_length_m == pytest.approx(3 * EW_M + 2 * NS_M, rel=2e-4)
    assert net.n_intersections == 1  # B, where A-B-C meets B-D
    assert net.is_connected
    assert net.source == "tiny.osm" and net.spacing_m == 10.0


def test_tiny_file_edge_lengths_match_geodesy() -> None:
    """Edge lengths are the roads' lengths on the ellipsoid split evenly: 78.847/8 and 100.02/11."""
    net = read_osm(TINY)
    lengths = np.unique(net.lengths_m.round(3))
    assert lengths == pytest.approx(sorted([NS_M / 11, EW_M / 8]), rel=2e-4)


def test_oneway_is_ignored_and_graph_is_undirected() -> None:
    """The oneway link C-G is an ordinary undirected edge: the adjacency is symmetric."""
    net = read_osm(TINY)
    a = net.adjacency
    assert abs(a - a.T).max() == 0
    # with the oneway link, B-C-G-D-B is a cycle: M = N - 1 + 1
    assert net.n_edges == net.n_nodes


def test_highway_types_parameter_adds_footways() -> None:
    """Adding footway to the kept types brings in D-E (100.02 m, 11 more edges)."""
    base = read_osm(TINY)
    more = read_osm(TINY, highway_types=CAR_HIGHWAYS | {"footway"})
    assert more.n_edges == base.n_edges + 11
    assert more.n_intersections == 2  # B and now D


def test_largest_component_can_be_switched_off() -> None:
    """Without the largest-component step the far road H-I stays as a second component."""
    net = read_osm(TINY, largest_component=False)
    assert net.n_components == 2
    assert net.n_nodes == 46 + 9
    assert net.largest_component().n_nodes == 46


def test_clip_to_bounds_drops_nodes_outside() -> None:
    """Clipping to <bounds> removes the far road H-I before any component is chosen."""
    net = read_osm(TINY, largest_component=False, clip_to_bounds=True)
    assert net.n_components == 1 and net.n_nodes == 46


def test_bz2_and_plain_files_agree(tmp_path: Path) -> None:
    """A bzip2-compressed copy gives the same network (compression is detected from content)."""
    packed = tmp_path / "tiny.osm.bz2"
    packed.write_bytes(bz2.compress(TINY.read_bytes()))
    a, b = read_osm(TINY), read_osm(packed)
    np.testing.assert_array_equal(a.coords, b.coords)
    np.testing.assert_array_equal(a.edges, b.edges)


# ----- the real extracts ------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(REAL_MAPS))
def test_real_maps_load(name: str, record_property: Callable[[str, object], None]) -> None:
    """Both shared OSM extracts load into one connected network of the expected size."""
    net = read_osm(BUNDLED / name)
    nodes, edges, length, intersections = REAL_MAPS[name]
    record_property("summary", repr(net))
    assert net.is_connected
    assert net.n_nodes == pytest.approx(nodes, rel=0.02)
    assert net.n_edges == pytest.approx(edges, rel=0.02)
    assert net.total_length_m == pytest.approx(length, rel=0.005)
    assert net.n_intersections == pytest.approx(intersections, rel=0.05)
    assert net.projection is not None
    assert net.projection.max_scale_error(net.coords) < 2e-4


@pytest.mark.parametrize("spacing", [5.0, 10.0, 25.0])
@pytest.mark.parametrize("name", sorted(REAL_MAPS))
def test_spacing_is_honoured(name: str, spacing: float) -> None:
    """No edge is longer than the spacing, and nearly all are between half of it and all of it."""
    net = read_osm(BUNDLED / name, spacing)
    lengths = net.lengths_m
    assert lengths.max() <= spacing * (1 + 1e-9)
    # a road of length ℓ ≥ h is cut in ⌈ℓ/h⌉ equal pieces of more than h/2; shorter ones stay whole
    assert np.median(lengths) >= 0.85 * spacing
    assert np.mean(lengths > 0.5 * spacing) > 0.97


def test_coarser_spacing_gives_fewer_nodes_same_length() -> None:
    """Resampling changes the node count roughly as 1/spacing but keeps the total road length."""
    fine = read_osm(BUNDLED / "aguascalientes.osm.bz2", 5.0)
    coarse = read_osm(BUNDLED / "aguascalientes.osm.bz2", 20.0)
    assert fine.total_length_m == pytest.approx(coarse.total_length_m, rel=1e-9)
    assert 2.5 < fine.n_nodes / coarse.n_nodes < 4.0


# ----- graph matrices ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "make", [lambda: read_osm(TINY), lambda: grid_network(3, 4), lambda: random_network(30)]
)
def test_laplacian_rows_sum_to_zero_and_equal_b_bt(make: object) -> None:
    """L = D − A has zero row sums and equals B Bᵀ (unweighted); B diag(w) Bᵀ is weighted."""
    net: RoadNetwork = make()  # type: ignore[operator]
    lap, b = net.laplacian, net.incidence
    assert np.abs(lap.sum(axis=1)).max() == 0
    assert abs(lap - b @ b.T).max() == 0
    np.testing.assert_array_equal(lap.diagonal(), net.degree)
    unit = (net.adjacency > 0).astype(float)
    assert abs(lap - (np.diag(net.degree) - unit.toarray())).max() == 0
    w = 1.0 / net.lengths_m**2
    lw = net.weighted_laplacian(w)
    assert np.abs(lw.sum(axis=1)).max() < 1e-12
    u, v = net.edges[:, 0], net.edges[:, 1]
    np.testing.assert_allclose(lw[u, v], -w)
    np.testing.assert_array_equal(np.abs(b).sum(axis=0), 2)  # one +1 and one −1 per column


def test_networkx_view_matches() -> None:
    """to_networkx has the same nodes, edges and lengths, so its Dijkstra agrees with ours."""
    net = read_osm(TINY)
    g = net.to_networkx()
    assert g.number_of_nodes() == net.n_nodes and g.number_of_edges() == net.n_edges
    theirs = nx.single_source_dijkstra_path_length(g, 0, weight="length")
    ours = net.shortest_paths(0)[0]
    np.testing.assert_allclose([theirs[i] for i in range(net.n_nodes)], ours)
    assert g.nodes[0]["pos"] == tuple(net.coords[0])


# ----- synthetic networks -----------------------------------------------------------------------


def test_grid_counts_by_hand() -> None:
    """A 3×4 grid of 100 m blocks at 10 m: 17 blocks, 165 nodes, 170 edges, 8 intersections."""
    net = grid_network(3, 4, block_m=100.0, spacing_m=10.0)
    blocks = 3 * 3 + 4 * 2
    assert net.n_nodes == 12 + 9 * blocks == 165
    assert net.n_edges == 10 * blocks == 170
    assert net.total_length_m == pytest.approx(1700.0)
    np.testing.assert_allclose(net.lengths_m, 10.0)
    assert net.n_intersections == 12 - 4  # corners have degree 2
    assert np.bincount(net.degree).tolist() == [0, 0, 4 + 9 * blocks, 6, 2]
    assert net.hull_area_m2 == pytest.approx(300.0 * 200.0)
    assert net.bbox_area_m2 == pytest.approx(300.0 * 200.0)
    assert net.intersection_density_per_km2 == pytest.approx(8 / 0.06)


def test_grid_spacing_not_dividing_block() -> None:
    """Blocks of 100 m at 30 m spacing are cut into 4 edges of 25 m."""
    net = grid_network(2, 2, block_m=100.0, spacing_m=30.0)
    assert net.n_nodes == 4 + 4 * 3 and net.n_edges == 16
    np.testing.assert_allclose(net.lengths_m, 25.0)


def test_grid_shortest_paths_are_manhattan() -> None:
    """From any intersection, the road distance to every node is the Manhattan distance."""
    net = grid_network(4, 5, block_m=50.0, spacing_m=10.0)
    xy = net.coords
    corners = np.flatnonzero(np.all(np.isclose(xy % 50.0, 0.0), axis=1))
    assert corners.size == 20
    dist = net.shortest_paths(corners)
    manhattan = np.abs(xy[corners][:, None, :] - xy[None, :, :]).sum(axis=2)
    np.testing.assert_allclose(dist, manhattan, atol=1e-9)


def test_shortest_path_nodes_are_adjacent() -> None:
    """The path between opposite grid corners is Manhattan long and walks along edges."""
    net = grid_network(3, 3, block_m=100.0, spacing_m=20.0)
    start, end = net.nearest_nodes([[0.0, 0.0], [200.0, 200.0]])
    path, length = net.shortest_path(int(start), int(end))
    assert length == pytest.approx(400.0)
    assert path[0] == start and path[-1] == end
    steps = net.adjacency[path[:-1], path[1:]]
    assert np.all(steps > 0) and steps.sum() == pytest.approx(400.0)


def test_shortest_paths_limit() -> None:
    """Nodes beyond limit_m are reported unreachable (inf)."""
    net = grid_network(2, 5, block_m=100.0, spacing_m=10.0)
    dist = net.shortest_paths([0], limit_m=55.0)[0]
    assert np.isinf(dist).sum() > 0 and dist[np.isfinite(dist)].max() <= 55.0


def test_random_network_is_seeded_connected_and_resampled() -> None:
    """The same seed gives the same network; it is connected and honours the spacing."""
    a = random_network(40, 800.0, 15.0, seed=7)
    b = random_network(40, 800.0, 15.0, seed=np.random.default_rng(7))
    c = random_network(40, 800.0, 15.0, seed=8)
    np.testing.assert_array_equal(a.coords, b.coords)
    np.testing.assert_array_equal(a.edges, b.edges)
    assert a.n_nodes != c.n_nodes or not np.array_equal(a.coords, c.coords)
    assert a.is_connected and a.lengths_m.max() <= 15.0 * (1 + 1e-9)
    tree = random_network(40, 800.0, 15.0, extra_road_fraction=0.0, seed=7)
    assert tree.n_edges == tree.n_nodes - 1  # the spanning tree alone


def test_builder_merges_shared_ends_and_keeps_shortest_parallel_road() -> None:
    """Roads ending at equal coordinates share a junction; of parallel roads the shortest stays."""
    net = network_from_polylines(
        [
            [[0, 0], [5, 0]],  # 5 m, one piece
            [[0.0, 0.0], [2.5, 1.0], [5.0, 0.0]],  # 5.39 m, one piece parallel to it: dropped
            [[5, 0], [0, 0]],  # the first road again, reversed: dropped
            [[0, 0], [0, 4], [5, 0]],  # 10.40 m: two pieces, through a new interior node
            [[5, 0], [9, 0]],  # 4 m
        ],
        spacing_m=10.0,
        largest_component=False,
    )
    assert net.n_nodes == 3 + 1 and net.n_edges == 4
    half = (4 + math.hypot(5, 4)) / 2
    assert sorted(net.lengths_m) == pytest.approx(sorted([5.0, 4.0, half, half]))


def test_builder_closed_loop_gets_three_pieces() -> None:
    """A loop road shorter than the spacing still becomes a triangle, not a self-loop."""
    net = network_from_polylines([[[0, 0], [3, 0], [3, 3], [0, 0]]], spacing_m=100.0)
    assert net.n_nodes == 3 and net.n_edges == 3


# ----- projection -------------------------------------------------------------------------------


def test_projection_round_trip_and_scale() -> None:
    """Forward then inverse is the identity, and degree lengths at 45°N match geodesy tables."""
    proj = LocalProjection(math.radians(45.0), math.radians(7.0))
    lat = np.radians([45.0, 45.0, 45.0009])
    lon = np.radians([7.0, 7.001, 7.0])
    xy = proj.forward(lat, lon)
    assert xy[1, 0] == pytest.approx(EW_M, rel=1e-4) and xy[2, 1] == pytest.approx(NS_M, rel=1e-4)
    back_lat, back_lon = proj.inverse(xy)
    np.testing.assert_allclose(back_lat, lat, rtol=0, atol=1e-15)
    np.testing.assert_allclose(back_lon, lon, rtol=0, atol=1e-15)
    # 1 km north of the centre the east-west scale is off by about tan(45°)·(1 km / 6371 km)
    assert proj.max_scale_error([[0.0, 1000.0]]) == pytest.approx(1000.0 / 6.37e6, rel=0.01)


# ----- errors -----------------------------------------------------------------------------------


def test_missing_file(tmp_path: Path) -> None:
    """A missing file is a ParseError naming it."""
    with pytest.raises(ParseError, match=r"nowhere\.osm.*no such file"):
        read_osm(tmp_path / "nowhere.osm")


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("empty.osm", "", "empty file"),
        ("text.osm", "just some text, not XML\n", "not well-formed XML"),
        ("broken.osm", '<osm version="0.6"><node id="1" lat="1" lon="1">', "not well-formed XML"),
        ("route.gpx", '<?xml version="1.0"?><gpx version="1.1"></gpx>', "not an OpenStreetMap"),
        (
            "buildings.osm",
            _osm(
                '<node id="1" lat="0" lon="0"/><node id="2" lat="0" lon="0.001"/>'
                '<way id="3"><nd ref="1"/><nd ref="2"/><tag k="building" v="yes"/></way>'
            ),
            "no roads",
        ),
        (
            "paths.osm",
            _osm(
                '<node id="1" lat="0" lon="0"/><node id="2" lat="0" lon="0.001"/>'
                + "".join(
                    f'<way id="{10 + k}"><nd ref="1"/><nd ref="2"/><tag k="highway" v="{t}"/></way>'
                    for k, t in enumerate(["footway", "path", "cycleway", "service"])
                )
            ),
            "no car-accessible roads",
        ),
        (
            "private.osm",
            _osm(
                '<node id="1" lat="0" lon="0"/><node id="2" lat="0" lon="0.001"/>'
                '<way id="3"><nd ref="1"/><nd ref="2"/><tag k="highway" v="residential"/>'
                '<tag k="access" v="private"/></way>'
            ),
            "no car-accessible roads",
        ),
        (
            "dangling.osm",
            _osm(
                '<node id="1" lat="0" lon="0"/>'
                '<way id="3"><nd ref="1"/><nd ref="2"/><tag k="highway" v="residential"/></way>'
            ),
            "reference no two nodes",
        ),
        (
            "badlat.osm",
            _osm('<node id="7" lat="north" lon="0"/>'),
            "node 7 lat",
        ),
    ],
)
def test_broken_files_raise_parse_error(
    tmp_path: Path, name: str, content: str, message: str
) -> None:
    """Each kind of broken file raises a ParseError naming the file and the problem."""
    path = _write(tmp_path, name, content)
    with pytest.raises(ParseError, match=message) as info:
        read_osm(path)
    assert info.value.path == str(path)


def test_xml_error_reports_line(tmp_path: Path) -> None:
    """Malformed XML reports the line where the parser stopped."""
    path = _write(tmp_path, "bad.osm", '<osm version="0.6">\n<node id="1"\n lat="1" lon=>\n</osm>')
    with pytest.raises(ParseError) as info:
        read_osm(path)
    assert info.value.line == 3


def test_corrupt_bz2(tmp_path: Path) -> None:
    """A file that starts like bzip2 but is not is reported as unreadable."""
    path = tmp_path / "bad.osm.bz2"
    path.write_bytes(b"BZh9" + b"\x00" * 64)
    with pytest.raises(ParseError, match="cannot read"):
        read_osm(path)


def test_clip_without_bounds(tmp_path: Path) -> None:
    """clip_to_bounds on a file without <bounds> names the missing element."""
    path = _write(
        tmp_path,
        "nobounds.osm",
        _osm(
            '<node id="1" lat="0" lon="0"/><node id="2" lat="0" lon="0.001"/>'
            '<way id="3"><nd ref="1"/><nd ref="2"/><tag k="highway" v="residential"/></way>'
        ),
    )
    assert read_osm(path).n_edges == 12  # 111.3 m in 12 pieces
    with pytest.raises(ParseError, match="bounds"):
        read_osm(path, clip_to_bounds=True)


@pytest.mark.parametrize("spacing", [0.0, -1.0, math.nan, math.inf, True, "10"])
def test_bad_spacing(spacing: object) -> None:
    """Spacing must be a finite positive number, for the reader and the generators alike."""
    with pytest.raises(InvalidInputError, match="spacing_m"):
        read_osm(TINY, spacing)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="spacing_m"):
        grid_network(2, 2, spacing_m=spacing)  # type: ignore[arg-type]


def test_network_without_edges() -> None:
    """A RoadNetwork needs at least one edge."""
    with pytest.raises(InvalidInputError, match="edges"):
        RoadNetwork(
            coords=np.zeros((2, 2)), edges=np.empty((0, 2), dtype=np.int64), lengths_m=np.empty(0)
        )


@pytest.mark.parametrize(
    ("edges", "lengths", "field"),
    [
        ([[0, 0]], [1.0], "edges"),
        ([[0, 1], [1, 0]], [1.0, 1.0], "edges"),
        ([[0, 3]], [1.0], "edges"),
        ([[0, 1]], [0.0], "lengths_m"),
        ([[0, 1]], [math.nan], "lengths_m"),
    ],
)
def test_network_refuses_bad_edges(
    edges: list[list[int]], lengths: list[float], field: str
) -> None:
    """Self-loops, duplicates, unknown nodes and non-positive lengths are refused by name."""
    coords = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    with pytest.raises(InvalidInputError, match=field):
        RoadNetwork(coords=coords, edges=np.array(edges), lengths_m=np.array(lengths))


def test_polylines_of_zero_length() -> None:
    """Polylines that do not move give no network."""
    with pytest.raises(InvalidInputError, match="positive length"):
        network_from_polylines([[[1.0, 1.0], [1.0, 1.0]]])


def test_bad_sources() -> None:
    """Shortest paths refuse node indices outside the network."""
    net = grid_network(2, 2)
    with pytest.raises(InvalidInputError, match="sources"):
        net.shortest_paths([net.n_nodes])
    with pytest.raises(InvalidInputError, match="limit_m"):
        net.shortest_paths([0], limit_m=math.nan)
