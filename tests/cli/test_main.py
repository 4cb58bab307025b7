"""The top-level command: help without arguments, ``--version``, ``-v`` after a subcommand,
help text on every argument."""

from __future__ import annotations

import argparse
import logging
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

import searchtrack
from searchtrack.cli import build_parser, main
from searchtrack.cli.plan import BACKEND_NAMES, available_families, family_module


def test_no_arguments_prints_the_help(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([]) == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: searchtrack") and "radio" in out and "exit status" in out


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == f"searchtrack {searchtrack.__version__}"


@pytest.mark.parametrize("where", ["before", "after"])
def test_verbose_before_or_after_the_subcommand(where: str, monkeypatch: pytest.MonkeyPatch,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    levels: list[int] = []
    monkeypatch.setattr(logging, "basicConfig", lambda **kw: levels.append(kw["level"]))
    argv = ["radio", "simulate", "missing.toml", "--out", "x.npz"]
    argv = ["-v", *argv] if where == "before" else [*argv, "-v"]
    assert main(argv) == 2                      # the scenario is missing: bad input
    assert levels == [logging.INFO]
    assert "missing.toml" in capsys.readouterr().err


def _parsers(parser: argparse.ArgumentParser,
             path: tuple[str, ...] = ("searchtrack",)
             ) -> Iterator[tuple[tuple[str, ...], argparse.ArgumentParser]]:
    """Every parser of the command tree with its command path."""
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _parsers(sub, (*path, name))


def test_every_argument_has_help_and_no_bracketed_options() -> None:
    """Every positional and option of every subcommand says what it is, and no help sentence
    shows a literal ``[--flag]`` (the usage line already does)."""
    missing, bracketed = [], []
    for path, parser in _parsers(build_parser()):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction | argparse._HelpAction):
                continue
            if not action.help:
                missing.append(f"{' '.join(path)} {action.dest}")
            if re.search(r"\[--?\w", str(action.help or "")):
                bracketed.append(f"{' '.join(path)} {action.dest}")
        if re.search(r"\[--?\w", (parser.description or "") + (parser.epilog or "")):
            bracketed.append(" ".join(path))
    assert not missing, missing
    assert not bracketed, bracketed


def test_help_pages_show_no_rest_markup() -> None:
    """No help page shows the docstrings' reST (````x````, ``:func:`x```)."""
    marked = [" ".join(path) for path, parser in _parsers(build_parser(["plan"]))
              if re.search(r"``|:[a-z]+:`", parser.format_help())]
    assert not marked, marked


def test_plan_help_lists_each_familys_backends() -> None:
    """``plan FAMILY --help`` names the family's backends, as its module registers them."""
    for name in available_families():
        assert BACKEND_NAMES[name] == tuple(family_module(name).backends()), name
        parser = dict(_parsers(build_parser()))[("searchtrack", "plan", name)]
        text = " ".join(parser.format_help().split())
        assert ", ".join(BACKEND_NAMES[name]) in text


def test_every_help_page_renders() -> None:
    """``--help`` of every (sub)command formats (a stray ``%`` in a help text breaks it)."""
    for path, parser in _parsers(build_parser()):
        assert parser.format_help(), path
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for choice in action._choices_actions:
                    assert "%" not in (choice.help or "").replace("%%", ""), (path, choice.dest)


def test_only_the_plan_command_imports_the_plan_families() -> None:
    """Other commands start without the five plan families and the solvers behind them; the
    ``plan`` command builds them all."""
    code = ("import sys; from searchtrack.cli import build_parser; "
            "build_parser(['-v', 'mission', 'run', 'x.toml']); "
            "print(any(m.startswith('searchtrack.sim.jobs.') for m in sys.modules)); "
            "build_parser(['plan', 'assign', 'p.json']); "
            "print(all(f'searchtrack.sim.jobs.{f}' in sys.modules for f in "
            "('assign', 'associate', 'route', 'search', 'trajectory')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "True"]


@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["-v"], []])
def test_the_command_alone_imports_no_group_and_no_solver(argv: list[str]) -> None:
    """``searchtrack --version`` and the group list start at once: no group's module is
    imported, nor numba, SciPy or networkx; every group is still listed."""
    code = ("import sys; from searchtrack.cli import build_parser; "
            f"p = build_parser({argv!r}); "
            "heavy = [m for m in ('numba', 'scipy', 'networkx') if m in sys.modules]; "
            "from searchtrack.cli.common import GROUPS; "
            "groups = [m for m, _ in GROUPS.values() if f'searchtrack.cli.{m}' in sys.modules]; "
            "print(heavy, groups, 'fleet-size' in p.format_help())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[] [] True"


def test_a_command_line_builds_only_the_group_it_names() -> None:
    """Each group's command line builds that group's parser whole (its arguments and
    subcommands, as the full parser has them); the other groups are only listed."""
    from searchtrack.cli.common import GROUPS

    def actions(parser: argparse.ArgumentParser) -> set[str]:
        return {a.dest for a in parser._actions}

    whole = {name: actions(p) for name, p in _subcommands(build_parser()).items()}
    assert list(whole) == list(GROUPS)
    for name in GROUPS:
        built = _subcommands(build_parser(["-v", name, "x"]))
        assert list(built) == list(GROUPS)
        for other, parser in built.items():
            if other == name:
                assert actions(parser) == whole[name], name
            else:
                assert actions(parser) <= {"help", "verbose"}, (name, other)
                assert parser.epilog == searchtrack.cli.EPILOG


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


@pytest.mark.parametrize(("argv", "offered"), [
    (["misson", "run"], "did you mean 'mission'?"),
    (["mission", "rnu", "x.toml"], "did you mean 'run'?"),
    (["optw", "solve", "x.txt", "--backend", "cpsta"], "did you mean 'cpsat'?"),
    (["zzzz"], "choose from optw, mission"),
])
def test_a_mistyped_choice_offers_the_nearest(argv: list[str], offered: str,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as done:
        main(argv)
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert offered in err and len(err.strip().splitlines()) == 1, err
    assert "did you mean" not in err or argv[0] != "zzzz"


def test_only_commands_that_solve_offer_verbose() -> None:
    """``-v`` (log solver progress) on every command that solves or simulates, not on those
    that only read or draw what was written."""
    from searchtrack.cli import SOLVE_NOTHING

    parsers = dict(_parsers(build_parser(["plan"])))
    for path, parser in parsers.items():
        leaf = not any(isinstance(a, argparse._SubParsersAction) for a in parser._actions)
        if not leaf or len(path) < 2:
            continue
        offered = "-v" in parser._option_string_actions
        assert offered == (" ".join(path[1:]) not in SOLVE_NOTHING), path
    assert {"mission view", "campaign status"} <= SOLVE_NOTHING


@pytest.mark.parametrize(("argv", "code", "said"), [
    (["--version"], 0, "searchtrack "),
    (["optw", "solve", "searchtrack/data/optw/c101.txt", "--time-limit", "0.5"], 0, "objective"),
    (["misson"], 2, "did you mean 'mission'?"),
    (["optw", "solve", "missing.txt"], 2, "no such file"),
])
def test_the_console_entry_flushes_and_keeps_the_status(argv: list[str], code: int,
                                                        said: str) -> None:
    """``run`` (the console script) ends the process without the interpreter's teardown: the
    piped output still arrives whole and the exit status is main's (or argparse's)."""
    root = Path(__file__).parents[2]
    done = subprocess.run([sys.executable, "-m", "searchtrack.cli", *argv], cwd=root,
                          capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == code, done.stderr
    assert said in done.stdout + done.stderr
