"""The paper pages' figures, drawn at build time by the commands the pages quote.

An mkdocs hook (``hooks:`` in ``mkdocs.yml``) and a script. Before the site is built, every
figure in :data:`FIGURES` is drawn by the ``searchtrack`` commands beside it into
``out/gallery`` (two commands at a time, about a minute on two cores) and added to the site as
``papers/figures/NAME``. The drawings are kept while the package's sources are unchanged (a hash
of ``searchtrack/`` and the example problems is stored beside them), so a second build draws
nothing. The browser screenshots (the replay page, the export's map page) are committed under
``docs/papers/figures``.

With ``SEARCHTRACK_DOCS_FIGURES=off`` nothing is drawn and the pages are built without the drawn
figures (the test suite builds the site this way).

    python docs/_ext/gallery.py [OUT_DIR] [NAME ...]   # draw (again) into OUT_DIR
"""

from __future__ import annotations

import hashlib
import logging
import os
import re
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
GALLERY = ROOT / "out" / "gallery"
SITE_FOLDER = "papers/figures"
SWITCH = "SEARCHTRACK_DOCS_FIGURES"
log = logging.getLogger("mkdocs.gallery")


@dataclass(frozen=True)
class Job:
    """``searchtrack`` commands run in one scratch folder ``{tmp}``; ``outputs`` maps each
    figure's name to the file the commands draw it into."""

    commands: tuple[tuple[str, ...], ...]
    outputs: tuple[tuple[str, str], ...]
    seconds: int   # about how long it runs on one core (the longest jobs start first)


#: Paper 000's Fig. 11 at 40 seeds per planner (the shipped campaign runs 1000).
P000_SEEDS = 40

JOBS: tuple[Job, ...] = (
    Job(commands=(("campaign", "run", "{tmp}/p000.toml", "--db", "{tmp}/p000.duckdb",
                   "--workers", "0"),
                  ("campaign", "report", "{tmp}/p000.duckdb", "--out", "{tmp}/report")),
        outputs=(("000-planners-entropy.png", "report/p000-planners-entropy_series.png"),),
        seconds=45),
    Job(commands=(("radio", "mission", "searchtrack/data/scenarios/radio_paper.toml",
                   "--seed", "1", "--out", "{tmp}/radio"),),
        outputs=(("002-exp1-seed1-map.png", "radio/map.png"),
                 ("002-exp1-seed1-ospa.png", "radio/ospa.png")),
        seconds=30),
    Job(commands=(("mission", "run", "searchtrack/data/scenarios/demo.toml",
                   "--out", "{tmp}/demo"),),
        outputs=(("001-demo-map.png", "demo/map.png"), ("001-demo-moc.png", "demo/moc.png")),
        seconds=8),
    Job(commands=(("plan", "assign", "examples/problems/assign.json", "--out", "{tmp}/a.json",
                   "--figure", "{tmp}/assign.png"),),
        outputs=(("003-assign.png", "assign.png"),), seconds=2),
    Job(commands=(("plan", "search", "examples/problems/search.json", "--out", "{tmp}/s.json",
                   "--figure", "{tmp}/search.png", "--backend", "receding"),),
        outputs=(("004-search.png", "search.png"),), seconds=2),
)

FIGURES: dict[str, Job] = {name: job for job in JOBS for name, _ in job.outputs}
"""Every drawn figure by name, with the job that draws it."""


def sources_hash() -> str:
    """A hash of what the figures are drawn from: the package's files and the examples."""
    digest = hashlib.sha256()
    for folder in ("searchtrack", "examples/problems"):
        for path in sorted((ROOT / folder).rglob("*")):
            if path.is_file() and "__pycache__" not in path.parts:
                digest.update(str(path.relative_to(ROOT)).encode())
                digest.update(path.read_bytes())
    return digest.hexdigest()


def _p000_campaign(tmp: Path) -> None:
    shipped = (ROOT / "searchtrack/data/campaigns/p000_planners.toml").read_text()
    text, found = re.subn(r"^seeds = \{count = \d+", f"seeds = {{count = {P000_SEEDS}", shipped,
                          flags=re.MULTILINE)
    if found != 1:
        raise RuntimeError("p000_planners.toml: no 'seeds = {count = N' line to shorten")
    (tmp / "p000.toml").write_text(text)


def _run(job: Job, out: Path) -> None:
    with tempfile.TemporaryDirectory(prefix="gallery-") as scratch:
        tmp = Path(scratch)
        if any("{tmp}/p000.toml" in command for command in job.commands):
            _p000_campaign(tmp)
        for command in job.commands:
            argv = [a.replace("{tmp}", scratch) for a in command]
            done = subprocess.run([sys.executable, "-m", "searchtrack.cli", *argv], cwd=ROOT,
                                  capture_output=True, text=True, check=False)
            if done.returncode != 0:
                raise RuntimeError(f"searchtrack {' '.join(argv)} failed "
                                   f"({done.returncode}):\n{done.stderr[-2000:]}")
        for name, drawn in job.outputs:
            shutil.copyfile(tmp / drawn, out / name)


def draw(out: Path = GALLERY, names: list[str] | None = None, workers: int = 2) -> list[str]:
    """Draw the figures ``names`` (default: those missing or drawn from other sources) into
    ``out``; returns the names drawn."""
    out.mkdir(parents=True, exist_ok=True)
    stamp = out / "SOURCES"
    current = sources_hash()
    if names is None:
        fresh = stamp.is_file() and stamp.read_text() == current
        names = [n for n in FIGURES if not (fresh and (out / n).is_file())]
    unknown = sorted(set(names) - set(FIGURES))
    if unknown:
        raise ValueError(f"no such figure: {', '.join(unknown)} (figures: {', '.join(FIGURES)})")
    jobs = sorted({FIGURES[n] for n in names}, key=lambda job: -job.seconds)
    if not jobs:
        return []
    stamp.unlink(missing_ok=True)
    with ThreadPoolExecutor(max_workers=workers) as pool:
        list(pool.map(lambda job: _run(job, out), jobs))   # raises the first job's failure
    if all((out / n).is_file() for n in FIGURES):
        stamp.write_text(current)
    return sorted(names)


def _enabled() -> bool:
    return os.environ.get(SWITCH, "on").lower() not in {"off", "0", "no"}


# --- mkdocs hooks --------------------------------------------------------------------------

def on_pre_build(config: Any) -> None:
    """Draw what is missing or stale before the pages are read."""
    if _enabled():
        drawn = draw()
        if drawn:
            log.info("gallery: drew %s into %s", ", ".join(drawn), GALLERY)


def on_files(files: Any, config: Any) -> Any:
    """Add the drawn figures to the site beside the committed screenshots."""
    if not _enabled():
        return files
    from mkdocs.structure.files import File

    for name in FIGURES:
        files.append(File.generated(config, f"{SITE_FOLDER}/{name}",
                                    abs_src_path=str(GALLERY / name)))
    return files


_IMAGE = re.compile(r"^!\[[^\]]*\]\(figures/([^)\s]+)\)\s*$", re.MULTILINE)


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    """With the figures switched off, the drawn figures' image lines are left out."""
    if _enabled():
        return markdown
    return _IMAGE.sub(lambda m: "" if m.group(1) in FIGURES else m.group(0), markdown)


if __name__ == "__main__":
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    args = sys.argv[1:]
    target = Path(args.pop(0)) if args and not args[0].endswith(".png") else GALLERY
    for drawn_name in draw(target, args or list(FIGURES)):
        print(f"wrote {target / drawn_name}")
