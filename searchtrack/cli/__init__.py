"""The ``searchtrack`` command: ``optw`` (:mod:`.optw`), ``mission`` (:mod:`.mission`) and
``track`` (:mod:`.track`), each a thin shell over the library that prints with rich.

Every subcommand checks its output paths before it works (:mod:`.output`), answers bad input with
one line and status 2, and stops cleanly on Ctrl-C: the first press asks the running solve or
loop to stop and keeps what is done (written if outputs were asked for), the second aborts at
once; either way the status is 130.
"""

from __future__ import annotations

import argparse
import difflib
import importlib
import logging
import os
import re
import sys
from collections.abc import Sequence
from typing import NoReturn, cast

from rich.console import Console
from rich.markup import escape

from searchtrack import __version__
from searchtrack.cli.common import GROUPS
from searchtrack.core.errors import SearchtrackError
from searchtrack.core.interrupt import Aborted, sigint_stops, stop_requested

DESCRIPTION = "The searchtrack command: solve and benchmark planning problems from the shell."
"""What ``searchtrack --help`` says first."""

#: Exit statuses of every subcommand.
EXIT_OK, EXIT_NO_PLAN, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130

EPILOG = ("exit status: 0 solved; 1 no plan (or some bench instance or campaign run failed); "
          "2 bad input; 130 interrupted (Ctrl-C stops cleanly and keeps what was done; a second "
          "Ctrl-C aborts at once)")


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line (and exit status 2)."""

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_BAD_INPUT,
                  f"{self.prog}: error: {_suggest(message)} (see {self.prog} --help)\n")


def _suggest(message: str) -> str:
    """argparse's "invalid choice" message with the nearest choice offered first."""
    found = re.match(r"argument (\S+): invalid choice: '([^']*)' \(choose from (.*)\)$", message)
    if found is None:
        return message
    name, given, listed = found.groups()
    choices = re.findall(r"'([^']*)'", listed)
    near = difflib.get_close_matches(given, choices, n=1, cutoff=0.6)
    hint = f"did you mean '{near[0]}'? " if near else ""
    return f"argument {name}: invalid choice '{given}': {hint}choose from {', '.join(choices)}"


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The argument parser of the ``searchtrack`` command; given the command line ``argv``, only
    the group it names is built (each group imports its solvers), the others are listed by name
    and help line. Without ``argv``, every group is built."""
    parser = _Parser(prog="searchtrack", description=DESCRIPTION, epilog=EPILOG)
    parser.add_argument("-v", "--verbose", action="store_true", help="log solver progress")
    parser.add_argument("--version", action="version", version=f"searchtrack {__version__}")
    sub = cast("argparse._SubParsersAction[argparse.ArgumentParser]",
               parser.add_subparsers(dest="group", required=True))
    words = [a for a in argv if not a.startswith("-")] if argv is not None else None
    for name, (module, help_line) in GROUPS.items():
        if words is None or words[:1] == [name]:
            importlib.import_module(f"searchtrack.cli.{module}").add_parser(sub)
        else:
            sub.add_parser(name, help=help_line)
    for name, group in sub.choices.items():
        leaf = not any(isinstance(a, argparse._SubParsersAction) for a in group._actions)
        if leaf and "-v" not in group._option_string_actions and name not in SOLVE_NOTHING:
            group.add_argument("-v", "--verbose", action="store_true",
                               default=argparse.SUPPRESS, help="log solver progress")
        _add_epilog(group, name)
    return parser


#: Commands that solve nothing (they read or draw what was written): no ``-v`` of their own.
SOLVE_NOTHING = frozenset({"mission view", "campaign status", "campaign export",
                           "campaign report"})


def _add_epilog(parser: argparse.ArgumentParser, path: str) -> None:
    """Every (sub)command's help ends with the exit statuses, and every command that solves
    something takes ``-v`` after its name too (``searchtrack optw solve FILE -v``)."""
    parser.epilog = EPILOG
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                here = f"{path} {name}"
                if "-v" not in child._option_string_actions and here not in SOLVE_NOTHING:
                    child.add_argument("-v", "--verbose", action="store_true",
                                       default=argparse.SUPPRESS, help="log solver progress")
                _add_epilog(child, here)


def _abort() -> None:
    """The second Ctrl-C: leave at once, even from inside a native solver (files are written
    atomically, so none is left half-written)."""
    sys.stderr.write("aborted on a second Ctrl-C\n")
    sys.stderr.flush()
    os._exit(EXIT_INTERRUPTED)


def run() -> NoReturn:
    """The ``searchtrack`` console script: :func:`main`, then the process ends with its status
    once the output is flushed, without the interpreter's teardown of every imported module
    (numba, SciPy, ...), which a command would otherwise spend after its last line and after
    Ctrl-C. Every file is written and closed by then (atomically); the campaign's cluster is
    closed by its own block."""
    try:
        code = main()
    except SystemExit as done:   # argparse's --help, --version and usage errors
        code = done.code if isinstance(done.code, int) else (0 if done.code is None else 1)
        if isinstance(done.code, str):
            sys.stderr.write(done.code + "\n")
    sys.stdout.flush()
    sys.stderr.flush()
    logging.shutdown()
    os._exit(code)


def main(argv: Sequence[str] | None = None) -> int:
    """The ``searchtrack`` command on ``argv`` (default: the process's arguments); returns the
    exit status (:func:`run` is the console script)."""
    given = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(given)
    if not given:
        parser.print_help()
        return EXIT_OK
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    console = Console()
    err = Console(stderr=True)
    try:
        with sigint_stops(abort=_abort):
            code: int = args.run(args, console)
            if stop_requested():
                err.print("[bold yellow]interrupted:[/] stopped on Ctrl-C; kept what was done")
                code = EXIT_INTERRUPTED
    except (Aborted, KeyboardInterrupt):
        err.print("[bold red]aborted[/] on a second Ctrl-C")
        return EXIT_INTERRUPTED
    except (SearchtrackError, ValueError) as exc:
        err.print("[bold red]error:[/]", escape(str(exc)), soft_wrap=True)
        return EXIT_BAD_INPUT
    return code
