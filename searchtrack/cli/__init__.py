"""The ``searchtrack`` command: ``optw`` (:mod:`.optw`), ``mission`` (:mod:`.mission`) and
``track`` (:mod:`.track`), each a thin shell over the library that prints with rich and exits
with status 2 and a one-line message on bad input."""

from __future__ import annotations

import argparse
import logging
from collections.abc import Sequence

from rich.console import Console
from rich.markup import escape

from searchtrack.cli import mission, optw, track
from searchtrack.core.errors import SearchtrackError

DESCRIPTION = "The ``searchtrack`` command: solve and benchmark planning problems from the shell."
"""What ``searchtrack --help`` says first."""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``searchtrack`` command."""
    parser = argparse.ArgumentParser(prog="searchtrack", description=DESCRIPTION)
    parser.add_argument("-v", "--verbose", action="store_true", help="log solver progress")
    sub = parser.add_subparsers(dest="group", required=True)
    optw.add_parser(sub)
    mission.add_parser(sub)
    track.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``searchtrack`` console script."""
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    console = Console()
    err = Console(stderr=True)
    try:
        code: int = args.run(args, console)
    except (SearchtrackError, ValueError) as exc:
        err.print("[bold red]error:[/]", escape(str(exc)), soft_wrap=True)
        return 2
    return code

