"""The replay page in a real browser (headless Chromium through Playwright): it loads from
``file://`` without errors, holds one plotly frame and slider step per heat frame, moves to a
later frame, and draws a picture that is not blank.

Skipped when Playwright is not installed or there is no Chromium at ``/usr/bin/chromium`` (or at
``$SEARCHTRACK_CHROMIUM``). ``$SEARCHTRACK_SCREENSHOT_DIR``, when set, keeps the screenshot there
(``replay.png``).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import matplotlib.image
import numpy as np
import pytest

from searchtrack.sim.roads.mission import Mission
from searchtrack.sim.roads.replay_page import write_replay
from searchtrack.sim.roads.scenario_file import load_scenario

CHROMIUM = Path(os.environ.get("SEARCHTRACK_CHROMIUM", "/usr/bin/chromium"))
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]
DEMO = Path(__file__).parents[3] / "searchtrack" / "data" / "scenarios" / "demo.toml"
PLOT = "document.querySelector('.js-plotly-plot')"

sync_api = pytest.importorskip("playwright.sync_api",
                               reason="playwright is not installed (pip install playwright)")
if not CHROMIUM.is_file():
    pytest.skip(f"no Chromium at {CHROMIUM} (set SEARCHTRACK_CHROMIUM to its path)",
                allow_module_level=True)


@pytest.fixture(scope="module")
def replay(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, int]:
    """The page of the demo mission cut to 15 s (50 steps, all of them heat frames)."""
    scenario = dataclasses.replace(load_scenario(DEMO), duration_s=15.0)
    record = Mission(scenario).run().to_json()
    path = write_replay(record, tmp_path_factory.mktemp("replay") / "replay.html")
    return path, len(record["heat"]["frames"])


@pytest.fixture(scope="module")
def page(replay: tuple[Path, int]) -> Iterator[tuple[Any, list[str]]]:
    """The page loaded in headless Chromium, and the errors it reported."""
    errors: list[str] = []
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), args=ARGS)
        tab = browser.new_page(viewport={"width": 1400, "height": 900})   # a laptop window
        tab.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        tab.on("pageerror", lambda e: errors.append(str(e)))
        tab.goto(replay[0].as_uri())
        tab.wait_for_selector(".js-plotly-plot", timeout=15_000)
        yield tab, errors
        browser.close()


def test_page_loads_with_its_frames_and_slider(page: tuple[Any, list[str]],
                                               replay: tuple[Path, int]) -> None:
    """No console error, one plotly frame and one slider step per heat frame, and the slider
    and play button drawn."""
    tab, errors = page
    frames = replay[1]
    assert frames == 50
    assert tab.evaluate(f"{PLOT}._transitionData._frames.length") == frames
    assert tab.evaluate(f"{PLOT}.layout.sliders[0].steps.length") == frames
    assert tab.locator(".slider-container").count() == 1
    assert tab.locator(".updatemenu-button").count() == 2
    for part in (".slider-container", ".updatemenu-button"):   # above the fold at 1400 × 900
        box = tab.locator(part).first.bounding_box()
        assert box is not None and box["y"] + box["height"] <= 900, (part, box)
    assert errors == []


def test_page_opens_on_the_last_frame_and_the_slider_moves(page: tuple[Any, list[str]],
                                                           replay: tuple[Path, int]) -> None:
    """The page opens on the last frame (the whole mission, slider at its end); animating to
    the first frame moves the time cursor and the slider to its time and step; the screenshot
    is a picture (many colours), not a blank page."""
    tab, errors = page
    cursor = f"{PLOT}.data[{PLOT}.data.length - 2].x[0]"
    opened = tab.evaluate(cursor)
    assert tab.evaluate(f"{PLOT}.layout.sliders[0].active") == 49
    tab.evaluate(f"""() => {{
        const gd = {PLOT};
        const first = gd._transitionData._frames[0].name;
        return Plotly.animate(gd, [first], {{mode: 'immediate', transition: {{duration: 0}},
                                             frame: {{duration: 0, redraw: false}}}});
    }}""")
    tab.wait_for_function(f"{PLOT}.layout.sliders[0].active === 0", timeout=5_000)
    assert opened == pytest.approx(15.0) and tab.evaluate(cursor) == pytest.approx(0.3)
    keep = os.environ.get("SEARCHTRACK_SCREENSHOT_DIR")  # where to keep the picture, if set
    shot = Path(keep) / "replay.png" if keep else replay[0].with_suffix(".png")
    shot.parent.mkdir(parents=True, exist_ok=True)
    tab.screenshot(path=str(shot), full_page=True)
    image = matplotlib.image.imread(shot)[..., :3]
    colours = np.unique((image.reshape(-1, 3) * 255).round().astype(np.uint8), axis=0)
    assert image.std() > 0.05 and len(colours) > 50
    assert errors == []
