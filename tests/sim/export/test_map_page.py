"""The offline map page of an export: the collection embedded (safely), and in a real browser
(headless Chromium, skipped without it) the roads and paths drawn over each other, no error.
``$SEARCHTRACK_SCREENSHOT_DIR``, when set, keeps the screenshot there (``map_page.png``)."""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest

from searchtrack.sim.export import geojson as gj
from searchtrack.sim.export.geo import GeoFrame
from searchtrack.sim.export.map_page import map_page
from searchtrack.sim.export.plans import road_mission_files
from searchtrack.sim.roads.mission import Mission
from searchtrack.sim.roads.scenario_file import load_scenario

CHROMIUM = Path(os.environ.get("SEARCHTRACK_CHROMIUM", "/usr/bin/chromium"))
DEMO = Path(__file__).parents[3] / "searchtrack" / "data" / "scenarios" / "demo.toml"


def test_page_embeds_the_collection_and_escapes_markup() -> None:
    fc = gj.collection([gj.line([[1.0, 2.0], [1.1, 2.1]], {"kind": "road",
                                                            "note": "</script><b>"})])
    page = map_page(fc, "a <plan>")
    assert "<title>a &lt;plan&gt;</title>" in page and "</script><b>" not in page
    data = page.split('<script id="data" type="application/json">')[1].split("</script>")[0]
    assert json.loads(data.replace("<\\/", "</")) == fc
    assert "http" not in page.replace("http://www.w3.org/2000/svg", "")   # no network


def test_page_draws_a_mission_in_the_browser(tmp_path: Path) -> None:
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    if not CHROMIUM.is_file():
        pytest.skip(f"no Chromium at {CHROMIUM} (set SEARCHTRACK_CHROMIUM to its path)")
    scenario = dataclasses.replace(load_scenario(DEMO), duration_s=10.0)
    log = Mission(scenario).run()
    assert log.network.projection is not None
    frame = GeoFrame(log.network.projection, 100.0)
    page = tmp_path / "plan.html"
    page.write_text(road_mission_files(log, frame, 30.0)["plan.html"], encoding="utf-8")
    errors: list[str] = []
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM),
                                    args=["--no-sandbox", "--disable-gpu"])
        tab = browser.new_page(viewport={"width": 1200, "height": 800})
        tab.on("pageerror", lambda e: errors.append(str(e)))
        tab.goto(page.as_uri())
        lines = tab.locator("#map polyline").count()
        legend = tab.locator("#legend").inner_text()
        keep = os.environ.get("SEARCHTRACK_SCREENSHOT_DIR")
        shot = Path(keep) / "map_page.png" if keep else tmp_path / "map_page.png"
        shot.parent.mkdir(parents=True, exist_ok=True)
        tab.screenshot(path=str(shot), full_page=True)
        browser.close()
    roads = len(log.network.edges)
    assert errors == [] and lines >= roads + 3 + 4     # every road, UAV and target path
    assert "road" in legend and "uav" in legend and "m across" in legend
    image = matplotlib.image.imread(shot)[..., :3]
    colours = np.unique((image.reshape(-1, 3) * 255).round().astype(np.uint8), axis=0)
    assert image.std() > 0.02 and len(colours) > 30
