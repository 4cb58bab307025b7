"""Argument types shared by the ``searchtrack`` subcommands (argparse reports their errors)."""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable

from searchtrack.core.registry import MAX_SEED

#: The ``searchtrack`` command's groups in the order its help lists them: name -> (the module of
#: :mod:`searchtrack.cli` that builds it, its line of help). A command line imports only the
#: group it names, and the solvers behind that group.
GROUPS: dict[str, tuple[str, str]] = {
    "optw": ("optw", "orienteering with time windows (team OPTW)"),
    "mission": ("mission", "closed-loop road search-and-track missions"),
    "track": ("track", "SMC-PHD filter on recorded 2-D detections"),
    "track-roads": ("track_roads", "Rao-Blackwellized road filter on recorded detections"),
    "campaign": ("campaign", "Monte Carlo campaigns on Dask into DuckDB"),
    "fleet-size": ("fleet", "fewest UAVs for a tracking-variance requirement"),
    "rl": ("rl", "train or evaluate the deep-RL road planner (paper 000)"),
    "radio": ("radio", "radio-tagged objects: simulate, track, fly missions (paper 002)"),
    "plan": ("plan", "solve one planning problem from a JSON file"),
    "warm-up": ("kernels", "compile the numba solver kernels now (once per install)"),
}


def add_group(sub: argparse._SubParsersAction[argparse.ArgumentParser], name: str,
              description: str | None = None) -> argparse.ArgumentParser:
    """The parser of the command group ``name`` (one of :data:`GROUPS`) with its line of help."""
    return sub.add_parser(name, help=GROUPS[name][1], description=description)


def positive_float(text: str) -> float:
    """``text`` as a number > 0, else an :class:`argparse.ArgumentTypeError`."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be positive: {text!r}")
    return value


def float_in(low: float, high: float, *, low_open: bool = False, high_open: bool = False,
             unit: str = "") -> Callable[[str], float]:
    """An argument type: the text as a number in the interval from ``low`` to ``high`` (open at
    an end when asked), else an :class:`argparse.ArgumentTypeError` naming the interval."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
        above = value > low if low_open else value >= low
        below = value < high if high_open else value <= high
        if not (above and below):
            interval = f"{'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
            raise argparse.ArgumentTypeError(f"must be in {interval}{unit}: {text!r}")
        return value

    return parse


def int_at_least(low: int) -> Callable[[str], int]:
    """An argument type: the text as an integer ≥ ``low``, else an
    :class:`argparse.ArgumentTypeError`."""
    return _integer(low, None)


def int_in(low: int, high: int) -> Callable[[str], int]:
    """An argument type: the text as an integer in ``[low, high]``, else an
    :class:`argparse.ArgumentTypeError` naming the range."""
    return _integer(low, high)


def _integer(low: int, high: int | None) -> Callable[[str], int]:
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
        if value < low or (high is not None and value > high):
            wanted = f"≥ {low}" if high is None else f"in [{low}, {high}]"
            raise argparse.ArgumentTypeError(f"must be {wanted}: {text!r}")
        return value

    return parse


seed_arg = int_in(0, MAX_SEED)
"""An argument type for seeds: every backend takes ``[0, MAX_SEED]``."""


def description(doc: str | None) -> str | None:
    """A command's help description: the first paragraph of its module docstring, its reST
    markup read as plain text (``x`` → x, :func:`~a.b` → b)."""
    if not doc:
        return None
    text = doc.split("\n\n")[0]
    text = re.sub(r":[a-z]+:`~?(?:[\w.]*\.)?([^`]+)`", r"\1", text)
    return text.replace("``", "")

