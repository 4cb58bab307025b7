"""The documentation site: it builds with warnings as errors, and the API pages miss no module."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "searchtrack"
API_PAGES = sorted((ROOT / "docs" / "api").glob("*.md"))
LAYERS = ("core", "models", "estimate", "plan", "sim", "cli")

#: Each paper page and text it must show: the paper's experiment and a class the page links to.
PAPERS = {
    "000-moore-rbpf": ("Fig. 11", "RoadRBPF"),
    "001-barkley-road-tracking": ("Experiment 1", "EMDAssociator"),
    "002-nguyen-radio-tbd": ("Fig. 8", "TbdLmbFilter"),
    "003-dames-phd-assignment": ("expected number of detections", "ExpectedDetections"),
    "004-yousuf-3d-search": ("E2", "ExplorationBonus"),
}

#: Each API page and an object it must document.
API_OBJECTS = {
    "core": "searchtrack.core.registry.Registry",
    "models": "searchtrack.models.road_particles.DirectedRoads",
    "estimate": "searchtrack.estimate.road_rbpf.RoadRBPF",
    "plan": "searchtrack.plan.road_search.problem.RoadSearchProblem",
    "sim": "searchtrack.sim.flight.loop.fly",
    "cli": "searchtrack.cli.main",
}

_BUILD_TOOLS = ("mkdocs", "material", "pymdownx", "mkdocstrings", "mkdocstrings_handlers.python")


def _missing_tools() -> list[str]:
    missing = []
    for name in _BUILD_TOOLS:
        try:
            found = importlib.util.find_spec(name) is not None
        except ModuleNotFoundError:
            found = False
        if not found:
            missing.append(name)
    return missing


def _modules() -> list[str]:
    """Dotted names of the public modules and packages under ``searchtrack/``."""
    names = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        if any(part.startswith("_") for part in parts):  # private modules and __main__
            continue
        names.append(".".join(parts))
    return names


def _documented() -> dict[str, str]:
    """Every ``::: identifier`` of the API pages, with the page it is on."""
    found: dict[str, str] = {}
    for page in API_PAGES:
        for name in re.findall(r"^::: *(\S+) *$", page.read_text(encoding="utf-8"), re.MULTILINE):
            found[name] = page.name
    return found


def test_every_module_is_on_an_api_page() -> None:
    """A new module under ``searchtrack/`` needs its ``::: searchtrack.x.y`` block in docs/api/."""
    documented = _documented()
    missing = [name for name in _modules() if name not in documented]
    assert not missing, ("modules on no docs/api/*.md page (add a '::: NAME' block to the "
                         "layer's page):\n" + "\n".join(missing))


def test_api_pages_name_only_existing_modules() -> None:
    """No stale ``:::`` block: each names a module or package that exists, on its layer's page."""
    modules = set(_modules())
    stale = [f"{page}: {name}" for name, page in _documented().items() if name not in modules]
    assert not stale, stale
    misplaced = [f"{page}: {name}" for name, page in _documented().items()
                 if name != "searchtrack" and page != f"{name.split('.')[1]}.md"]
    assert not misplaced, misplaced
    assert sorted(page.stem for page in API_PAGES) == sorted(LAYERS)


def _load_gallery() -> Any:
    spec = importlib.util.spec_from_file_location("gallery", ROOT / "docs" / "_ext" / "gallery.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["gallery"] = module
    spec.loader.exec_module(module)
    return module


GALLERY = _load_gallery()


def test_every_figure_on_a_page_is_drawn_or_committed() -> None:
    """Each image a paper page shows is drawn by the gallery or committed (the browser
    screenshots); nothing committed is also drawn, and nothing drawn goes unused."""
    shown = {m for page in (ROOT / "docs" / "papers").glob("*.md")
             for m in re.findall(r"\]\(figures/([^)\s]+)\)", page.read_text(encoding="utf-8"))}
    committed = {p.name for p in (ROOT / "docs" / "papers" / "figures").glob("*")}
    assert shown == set(GALLERY.FIGURES) | committed
    assert not set(GALLERY.FIGURES) & committed


def test_the_gallery_draws_what_is_missing_and_keeps_the_rest(tmp_path: Path) -> None:
    """With the sources unchanged, only a missing figure is drawn (by the command its page
    quotes); an unknown name is refused."""
    for name in GALLERY.FIGURES:
        (tmp_path / name).write_bytes(b"kept")
    (tmp_path / "SOURCES").write_text(GALLERY.sources_hash())
    assert GALLERY.draw(tmp_path) == []
    (tmp_path / "003-assign.png").unlink()
    assert GALLERY.draw(tmp_path) == ["003-assign.png"]
    assert (tmp_path / "003-assign.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "004-search.png").read_bytes() == b"kept"
    assert (tmp_path / "SOURCES").read_text() == GALLERY.sources_hash()
    with pytest.raises(ValueError, match=r"no such figure: nope\.png"):
        GALLERY.draw(tmp_path, ["nope.png"])


def test_without_figures_the_drawn_ones_are_left_out(monkeypatch: pytest.MonkeyPatch) -> None:
    """With the switch off, the drawn figures' image lines go and the screenshots stay."""
    page = "a\n![x](figures/003-assign.png)\n![y](figures/001-demo-replay.png)\nb\n"
    monkeypatch.setenv(GALLERY.SWITCH, "off")
    assert GALLERY.on_page_markdown(page, None, None, None) == (
        "a\n\n![y](figures/001-demo-replay.png)\nb\n")
    monkeypatch.setenv(GALLERY.SWITCH, "on")
    assert GALLERY.on_page_markdown(page, None, None, None) == page


@pytest.fixture(scope="session")  # one build per worker, whatever runs between its tests
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The site built by ``mkdocs build --strict`` (every warning is an error) into a tmp dir."""
    missing = _missing_tools()
    if missing:
        pytest.skip(f"documentation tools not installed ({', '.join(missing)}): "
                    "pip install -e '.[docs]'")
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1", GALLERY.SWITCH: "off"}
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT, capture_output=True, text=True, timeout=900, env=env, check=False)
    log = done.stdout + done.stderr
    assert done.returncode == 0, f"mkdocs build --strict failed:\n{log}"
    assert "WARNING" not in log, log
    return out


def _html(site: Path, page: str) -> str:
    path = site / f"{page}.html" if page else site / "index.html"   # use_directory_urls: false
    assert path.is_file(), f"{path} was not built"
    return path.read_text(encoding="utf-8")


@pytest.mark.slow
@pytest.mark.xdist_group("site")  # one worker builds the site once
def test_home_and_guides_include_the_readme(site: Path) -> None:
    """The README sections arrive through the snippet markers, and no marker leaks."""
    home = _html(site, "")
    assert "A Python library for teams of UAVs" in home
    assert "make demo" in home and "runs ruff, mypy and the suite" in home
    for page, text in (("quickstart-python", "read_optw"), ("quickstart-cli", "track-roads"),
                       ("campaigns", "searchtrack campaign run"), ("benchmarks", "benchmarks/")):
        html = _html(site, page)
        assert text in html, page
        assert "--8&lt;--" not in html and "--8<--" not in html, page


@pytest.mark.slow
@pytest.mark.xdist_group("site")  # one worker builds the site once
@pytest.mark.parametrize("page", sorted(PAPERS))
def test_paper_pages(site: Path, page: str) -> None:
    """Each paper page is built, names its experiment and links its classes into the API pages."""
    html = _html(site, f"papers/{page}")
    for text in PAPERS[page]:
        assert text in html, f"{page}: {text!r} missing"
    assert re.search(rf'href="[^"]*api/[a-z]+\.html#searchtrack\.[\w.]*{PAPERS[page][1]}"', html), (
        f"{page}: no link to {PAPERS[page][1]} in the API reference")


@pytest.mark.slow
@pytest.mark.xdist_group("site")  # one worker builds the site once
@pytest.mark.parametrize("layer", LAYERS)
def test_api_pages(site: Path, layer: str) -> None:
    """Each API page documents every module of its layer, rendered from its docstrings."""
    html = _html(site, f"api/{layer}")
    assert f'id="{API_OBJECTS[layer]}"' in html, f"{API_OBJECTS[layer]} not documented"
    for name, page in _documented().items():
        if page == f"{layer}.md" and name != f"searchtrack.{layer}":
            assert f'id="{name}"' in html, f"{name} not rendered on api/{layer}"
    folders = re.findall(r'href="((?:\.\./|\./)?[\w./-]*/)(?:#[^"]*)?"', html)
    assert not folders, f"links to folders (a directory listing under file://): {folders[:5]}"
    # reST roles are rendered as code (linked where the target is documented), never literally
    assert ":class:`" not in html and ":func:`" not in html and ":meth:`" not in html
