"""Bad input and Ctrl-C, command by command: the probe table and the time from SIGINT to exit.

    python benchmarks/cli_probes.py probes     # every malformed input: exit status, message
    python benchmarks/cli_probes.py sigint     # SIGINT to running commands: status, seconds

The probes are the bad-input test suite's (``tests/cli/probes.py``); ``sigint`` runs each
command in a subprocess, sends SIGINT a few seconds in and times the exit.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).parent))

from tables import table  # noqa: E402

from searchtrack.cli import main  # noqa: E402
from tests.cli.test_bad_input import ALL_PROBES  # noqa: E402
from tests.cli.test_interrupt import DATA, OPTW, _interrupt, _wide_instance  # noqa: E402


def probes() -> None:
    """One row per probe: the input, the exit status (and whether it is the expected one), the
    first line of the message."""
    rows = []
    for name, build, status, _ in ALL_PROBES:
        with tempfile.TemporaryDirectory() as folder:
            argv = build(Path(folder))
            err, out = io.StringIO(), io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
                try:
                    code = main(argv)
                except SystemExit as exc:
                    code = exc.code if isinstance(exc.code, int) else 2
            text = " ".join(err.getvalue().split()).replace(folder, "…")
            rows.append([name, f"{code}" + ("" if code == status else f" (want {status})"),
                         text[:110] or "(table printed)"])
    table(["input", "exit", "message"], rows)


def sigint() -> None:
    """SIGINT 4 s into each command: exit status and seconds from the signal to exit."""
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        wide = _wide_instance(tmp / "wide.txt")
        scenario = tmp / "long.toml"
        scenario.write_text('name = "long"\nduration_s = 3000.0\nseed = 1\n[map]\ngrid = '
                            '{ rows = 6, cols = 6, block_m = 100.0 }\n[uavs]\ncount = 2\n'
                            '[targets]\ncount = 2\n', encoding="utf-8")
        cases = [
            ("optw solve ils (r101)", ["optw", "solve", str(OPTW / "r101.txt"), "--backend",
                                       "ils", "--time-limit", "120"]),
            ("optw solve labelling (wide 200)", ["optw", "solve", str(wide), "--backend",
                                                 "labelling", "--time-limit", "120"]),
            ("optw solve cpsat (c101, m=3)", ["optw", "solve", str(OPTW / "c101.txt"),
                                              "--backend", "cpsat", "--vehicles", "3",
                                              "--time-limit", "120"]),
            ("optw solve mip (rc101)", ["optw", "solve", str(OPTW / "rc101.txt"), "--backend",
                                        "mip", "--time-limit", "120"]),
            ("optw solve auto (pr10, m=4)", ["optw", "solve", str(OPTW / "cordeau" / "pr10.txt"),
                                             "--vehicles", "4", "--time-limit", "120"]),
            ("optw bench ils", ["optw", "bench", str(OPTW), "--backend", "ils",
                                "--time-limit", "30"]),
            ("mission run", ["mission", "run", str(scenario), "--out", str(tmp / "out")]),
            ("radio mission", ["radio", "mission", str(DATA / "scenarios" / "radio_paper.toml"),
                               "--out", str(tmp / "radio")]),
            ("campaign run (quick start, 2 workers)",
             ["campaign", "run", str(DATA / "campaigns" / "quick_start.toml"), "--db",
              str(tmp / "quick.duckdb")]),
        ]
        rows = []
        for name, argv in cases:
            code, waited, _ = _interrupt(argv, after_s=4.0)
            rows.append([name, str(code), f"{waited:.2f}"])
        table(["command", "exit", "SIGINT → exit s"], rows)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=["probes", "sigint"])
    {"probes": probes, "sigint": sigint}[parser.parse_args().what]()
