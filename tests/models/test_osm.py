"""OpenStreetMap import: car roads kept, ways split at junctions and map edges, real extracts,
and broken files named with the problem."""

from __future__ import annotations

import bz2
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import ParseError
from searchtrack.models import CAR_HIGHWAYS, read_osm
from tests.models.osm_data import EW_M, NS_M, TINY

BUNDLED = Path(__file__).parents[2] / "searchtrack" / "data" / "osm"  # copies of ../shared

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


# ----- splitting ways ---------------------------------------------------------------------------


def test_projection_is_centred_on_the_kept_roads() -> None:
    """The projection centre is the middle of the kept roads' nodes, the far road H-I included."""
    net = read_osm(TINY)
    assert net.projection is not None
    assert net.projection.lat0_rad == pytest.approx(math.radians(45.005), abs=1e-12)
    assert net.projection.lon0_rad == pytest.approx(math.radians(7.0055), abs=1e-12)


def test_ways_are_split_at_shared_nodes(tmp_path: Path) -> None:
    """Two ways crossing at a shared interior node meet there: one junction of degree 4."""
    path = _write(tmp_path, "cross.osm", _osm(
        '<node id="1" lat="0" lon="0"/><node id="2" lat="0" lon="0.001"/>'
        '<node id="3" lat="0" lon="0.002"/><node id="4" lat="-0.001" lon="0.001"/>'
        '<node id="5" lat="0.001" lon="0.001"/>'
        '<way id="10"><nd ref="1"/><nd ref="2"/><nd ref="3"/><tag k="highway" v="primary"/></way>'
        '<way id="11"><nd ref="4"/><nd ref="2"/><nd ref="5"/><tag k="highway" v="primary"/></way>'
    ))
    net = read_osm(path, 1000.0)
    assert (net.n_nodes, net.n_edges, net.n_intersections) == (5, 4, 1)
    assert sorted(net.degree.tolist()) == [1, 1, 1, 1, 4]


def test_ways_are_cut_where_nodes_are_missing(tmp_path: Path) -> None:
    """A way through a node missing from the extract becomes two roads of 0.001° each."""
    path = _write(tmp_path, "gap.osm", _osm(
        '<node id="1" lat="0" lon="0"/><node id="2" lat="0" lon="0.001"/>'
        '<node id="3" lat="0" lon="0.003"/><node id="4" lat="0" lon="0.004"/>'
        '<way id="10"><nd ref="1"/><nd ref="2"/><nd ref="99"/><nd ref="3"/><nd ref="4"/>'
        '<tag k="highway" v="residential"/></way>'
    ))
    net = read_osm(path, 1000.0, largest_component=False)
    assert net.n_components == 2 and net.n_edges == 2
    # 0.001° of longitude on the equator is a·π/180·0.001 = 111.3195 m
    np.testing.assert_allclose(net.lengths_m, 111.3195, rtol=1e-6)


@pytest.mark.parametrize(("key", "value"), [("area", "yes"), ("access", "no"),
                                            ("motor_vehicle", "no"), ("motorcar", "no")])
def test_tags_that_bar_cars_drop_the_way(tmp_path: Path, key: str, value: str) -> None:
    """A residential way tagged area=yes, access=no, motor_vehicle=no or motorcar=no is left out."""
    path = _write(tmp_path, "barred.osm", _osm(
        '<node id="1" lat="0" lon="0"/><node id="2" lat="0" lon="0.001"/>'
        f'<way id="3"><nd ref="1"/><nd ref="2"/><tag k="highway" v="residential"/>'
        f'<tag k="{key}" v="{value}"/></way>'
    ))
    with pytest.raises(ParseError, match="no car-accessible roads"):
        read_osm(path)


@pytest.mark.parametrize(("node", "field", "message"), [
    ('<node id="x1" lat="0" lon="0"/>', "node", "not an integer id"),
    ('<node id="7" lat="91" lon="0"/>', "node 7 lat", "not a valid lat"),
    ('<node id="7" lat="0" lon="-180.5"/>', "node 7 lon", "not a valid lon"),
    ('<node id="7" lat="0"/>', "node 7 lon", "not a valid lon"),
])
def test_bad_nodes_name_the_node_and_field(tmp_path: Path, node: str, field: str,
                                           message: str) -> None:
    """A non-integer id, a latitude beyond ±90°, a longitude beyond ±180° or none are named."""
    path = _write(tmp_path, "node.osm", _osm(node))
    with pytest.raises(ParseError, match=message) as info:
        read_osm(path)
    assert info.value.field == field
