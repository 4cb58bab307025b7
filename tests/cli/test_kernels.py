"""``searchtrack warm-up`` and the notice commands print before compiling kernels."""

from __future__ import annotations

import pytest
from rich.console import Console

from searchtrack.cli import kernels as cli_kernels
from searchtrack.cli import main
from searchtrack.sim.kernels import KERNEL_SETS, warm


def test_notice_only_when_a_set_is_cold(monkeypatch: pytest.MonkeyPatch) -> None:
    """A cold set is announced once, then compiled; a cached one is compiled silently."""
    warmed: list[str] = []
    monkeypatch.setattr(cli_kernels, "warm",
                        lambda sets: {ks.name: warmed.append(ks.name) or 0.0 for ks in sets})
    monkeypatch.setattr(cli_kernels, "cold_sets",
                        lambda names: [KERNEL_SETS[n] for n in names if n == "simplex"])
    console = Console(record=True, width=200)
    cli_kernels.ready_kernels(console, ["simplex", "road-filter"])
    text = console.export_text()
    assert text.count(cli_kernels.NOTICE) == 1 and "network simplex" in text
    assert warmed == ["simplex"]
    console = Console(record=True, width=200)
    assert cli_kernels.ready_kernels(console, ["road-filter"]) == {}
    assert cli_kernels.NOTICE not in console.export_text()


def test_warm_up_command(capsys: pytest.CaptureFixture[str]) -> None:
    """``warm-up --only`` readies the named sets and prints a row for each."""
    assert main(["warm-up", "--only", "simplex", "road-filter"]) == 0
    out = capsys.readouterr().out
    assert "simplex" in out and "road-filter" in out and "kernels ready" in out


def test_warm_up_unknown_set_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["warm-up", "--only", "nope"]) == 2
    assert "unknown kernel set" in capsys.readouterr().err


def test_warm_up_compiles_on_several_processes(capsys: pytest.CaptureFixture[str]) -> None:
    """``--jobs 2`` readies each named set (in two fresh processes when a set is cold, here
    loading what the cache holds) and reports every one of them."""
    assert main(["warm-up", "--only", "radio", "road-filter", "--jobs", "2"]) == 0
    out = capsys.readouterr().out
    assert "radio" in out and "road-filter" in out and "kernels ready" in out


def test_warm_on_a_pool_times_every_set() -> None:
    """The pool path of :func:`warm` compiles in spawned processes and times each set."""
    took = warm([KERNEL_SETS["radio"], KERNEL_SETS["road-filter"]], jobs=2)
    assert set(took) == {"radio", "road-filter"} and all(t > 0 for t in took.values())


def test_warm_up_bad_jobs_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["warm-up", "--jobs", "0"]) == 2
    assert "--jobs 0" in capsys.readouterr().err
