"""An offline map page of a GeoJSON collection: one HTML file that any browser opens from the
file system, with no network (no tiles, no script from elsewhere): the features drawn as SVG in
an equirectangular view of their bounding box, coloured by ``kind`` (roads grey, UAV paths
and routes in colour, targets dashed, estimates dotted), with a legend and the scale."""

from __future__ import annotations

import html
import json
from collections.abc import Mapping
from typing import Any

#: Stroke of each feature kind: colour, width (px), dash pattern.
STYLES = {"road": ("#c8c8c8", 1.0, ""), "uav": ("#1f77b4", 2.0, ""),
          "route": ("#1f77b4", 2.0, ""), "target": ("#222222", 1.5, "5 3"),
          "estimate": ("#d62728", 1.5, "1 3"), "customer": ("#555555", 1.0, ""),
          "depot": ("#000000", 1.0, "")}

_SCRIPT = """
const fc = JSON.parse(document.getElementById('data').textContent);
const styles = JSON.parse(document.getElementById('styles').textContent);
const palette = ['#1f77b4', '#ff7f0e', '#2ca02c', '#9467bd', '#8c564b', '#e377c2'];
const rings = [];
const walk = (g, f) => g.type === 'Point' ? f([g.coordinates]) :
  g.type === 'LineString' ? f(g.coordinates) : g.coordinates.forEach(f);
fc.features.forEach(ft => walk(ft.geometry, c => rings.push(...c)));
const lons = rings.map(p => p[0]), lats = rings.map(p => p[1]);
const [x0, x1, y0, y1] = [Math.min(...lons), Math.max(...lons), Math.min(...lats),
                          Math.max(...lats)];
const k = Math.cos((y0 + y1) / 2 * Math.PI / 180);
const w = 1000, pad = 20;
const h = Math.round(pad * 2 + (w - 2 * pad) * (y1 - y0) / Math.max((x1 - x0) * k, 1e-9));
const s = (w - 2 * pad) / Math.max((x1 - x0) * k, 1e-9);
const px = p => [pad + (p[0] - x0) * k * s, pad + (y1 - p[1]) * s];
const svg = document.getElementById('map');
svg.setAttribute('viewBox', `0 0 ${w} ${Math.max(h, 200)}`);
const seen = {};
fc.features.forEach((ft, i) => {
  const kind = ft.properties.kind || 'feature';
  let [colour, width, dash] = styles[kind] || ['#444444', 1.5, ''];
  const who = ft.properties.uav ?? ft.properties.vehicle ?? ft.properties.route;
  if ((kind === 'uav' || kind === 'route') && who !== undefined) colour = palette[who % 6];
  seen[kind] = colour;
  const draw = c => {
    if (ft.geometry.type === 'Point') {
      const [x, y] = px(c[0]);
      const dot = document.createElementNS('http://www.w3.org/2000/svg', 'circle');
      Object.entries({cx: x, cy: y, r: 3, fill: colour}).forEach(([a, v]) =>
        dot.setAttribute(a, v));
      svg.appendChild(dot);
      return;
    }
    const path = document.createElementNS('http://www.w3.org/2000/svg', 'polyline');
    path.setAttribute('points', c.map(p => px(p).join(',')).join(' '));
    Object.entries({fill: 'none', stroke: colour, 'stroke-width': width,
                    'stroke-dasharray': dash}).forEach(([a, v]) => path.setAttribute(a, v));
    svg.appendChild(path);
  };
  walk(ft.geometry, draw);
});
const metres = (x1 - x0) * k * 111320;
document.getElementById('legend').textContent = Object.keys(seen).join(' · ') +
  ` — ${Math.round(metres)} m across`;
"""


def map_page(collection: Mapping[str, Any], title: str) -> str:
    """The HTML page drawing ``collection`` (module docstring)."""
    data = json.dumps(collection).replace("</", "<\\/")
    styles = json.dumps({k: list(v) for k, v in STYLES.items()})
    return (f"<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(title)}</title><style>body{{font:14px sans-serif;"
            "margin:12px}} svg{width:100%;max-height:85vh;background:#fff;"
            "border:1px solid #ddd}</style></head><body>"
            f"<h3>{html.escape(title)}</h3><svg id=\"map\"></svg><p id=\"legend\"></p>"
            f"<script id=\"data\" type=\"application/json\">{data}</script>"
            f"<script id=\"styles\" type=\"application/json\">{styles}</script>"
            f"<script>{_SCRIPT}</script></body></html>\n")
