"""The hand-written OpenStreetMap file of the road tests and its geodesy by hand."""

from __future__ import annotations

from pathlib import Path

TINY = Path(__file__).parents[1] / "data" / "osm" / "tiny.osm"

# 0.001° of longitude and 0.0009° of latitude at 45°N on WGS84 (geodesy tables: 78 847 m and
# 111 133 m per degree).
EW_M = 78.847
NS_M = 100.02
