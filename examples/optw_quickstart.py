"""Solve Solomon c101 with each backend and check every plan with the independent validator."""

from __future__ import annotations

from pathlib import Path

from searchtrack.plan.optw import read_optw, solve, validate

DATA = Path(__file__).resolve().parents[1] / "searchtrack" / "data" / "optw"


def main() -> None:
    """Print one line per backend: status, profit, bound, time."""
    inst = read_optw(DATA / "c101.txt")
    for backend in ("ils", "labelling", "cpsat", "auto"):
        res = solve(inst, backend=backend, time_limit_s=10.0)
        ok = res.plan is not None and validate(inst, res.plan).feasible
        print(f"{backend:10s} {res.status.name:9s} profit {res.objective} bound {res.bound} "
              f"{res.runtime_s:.2f} s valid={ok}")


if __name__ == "__main__":
    main()
