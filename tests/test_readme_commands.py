"""The README's command lines are commands a user can paste: each parses, and each input file it
names exists in a fresh clone (or is written by an earlier command of the README)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from searchtrack.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
OUTPUT_OPTIONS = ("--out", "--json", "--truth", "--figure", "--db", "--export")
INPUT_SUFFIXES = (".txt", ".toml", ".json", ".npz", ".csv", ".duckdb")


def readme_commands() -> list[str]:
    """Every ``searchtrack ...`` line of the README's shell blocks, comments cut."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    lines = []
    for block in re.findall(r"```sh\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            line = line.split("  #")[0].strip()
            if line.startswith("searchtrack "):
                lines.append(line)
    return lines


COMMANDS = readme_commands()


def test_the_readme_has_commands() -> None:
    assert len(COMMANDS) >= 15


def test_every_command_parses_and_names_files_that_exist() -> None:
    """Each line parses as it stands (no ``[--option]`` brackets, no placeholders), and every
    input path exists or was written (or written into) by an earlier line."""
    parser = build_parser()
    written: set[str] = set()
    for line in COMMANDS:
        argv = shlex.split(line)[1:]
        assert not any(a.startswith("[") or a.endswith("]") for a in argv), line
        assert not any(a.isupper() for a in argv), f"{line!r}: a placeholder"
        try:
            parser.parse_args(argv)
        except SystemExit as exc:  # argparse's way of refusing
            pytest.fail(f"{line!r} does not parse ({exc})")
        for i, arg in enumerate(argv):
            if i and argv[i - 1] in OUTPUT_OPTIONS:
                written.add(arg)
                continue
            if arg.startswith("-") or not arg.endswith(INPUT_SUFFIXES):
                continue
            made = arg in written or any(arg.startswith(f"{w}/") for w in written)
            assert (ROOT / arg).exists() or made, f"{line!r}: no file {arg}"


def test_every_output_goes_under_out() -> None:
    """The README's commands write under ``out/`` (ignored by git), never into the clone."""
    stray = []
    for line in COMMANDS:
        argv = shlex.split(line)[1:]
        outputs = [argv[i] for i in range(1, len(argv)) if argv[i - 1] in OUTPUT_OPTIONS]
        if argv[:2] == ["campaign", "export"]:
            outputs.append(argv[3])
        stray += [f"{line!r}: {o}" for o in outputs if not o.startswith("out/")]
    assert not stray, stray
