"""The top-level command: help without arguments, ``--version``, ``-v`` after a subcommand."""

from __future__ import annotations

import logging

import pytest

import searchtrack
from searchtrack.cli import main


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
