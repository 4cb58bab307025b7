"""The campaign package's own experiments: ``toy``, the run its tests and benchmarks time, and
``optw_instance``, a bundled OPTW instance solved by one backend (the planning layer has no
closed loop of a domain to live in)."""

from __future__ import annotations

import time
from importlib import resources

from searchtrack.plan.optw import BACKENDS as OPTW_BACKENDS
from searchtrack.plan.optw import read_optw, solve
from searchtrack.sim.campaigns.experiments import Experiment, Metric, Metrics, Param, Params

OPTW_INSTANCES = ("c101", "r101", "rc101", "pr01")
"""The OPTW instances bundled in ``searchtrack/data/optw``."""


def toy_run(params: Params, seed: int) -> Metrics:
    """Sleep ``sleep_s``, then return ``value`` (or raise when ``fail``)."""
    time.sleep(float(params["sleep_s"]))
    if params["fail"]:
        raise RuntimeError(f"toy run failed on purpose (seed {seed})")
    return {"result": float(params["value"]), "seed_echo": seed}


def optw_run(params: Params, seed: int) -> Metrics:
    """One bundled OPTW instance solved by one backend."""
    path = resources.files("searchtrack") / "data" / "optw" / f"{params['instance']}.txt"
    inst = read_optw(str(path), vehicles=int(params["vehicles"]))
    result = solve(inst, backend=str(params["backend"]),
                   time_limit_s=float(params["time_limit_s"]), seed=seed)
    return {"objective": result.objective, "bound": result.bound,
            "solve_status": result.status.name, "solve_s": result.runtime_s}


EXPERIMENTS = (
    Experiment("toy", (Param("sleep_s", float, 0.0), Param("fail", bool, False),
                       Param("value", float, 1.0)),
               {"result": Metric(float), "seed_echo": Metric(int)}, toy_run,
               "sleeps, returns its value as result (or raises): for tests and benchmarks"),
    Experiment("optw_instance", (
        Param("instance", str, "c101", OPTW_INSTANCES),
        # ``solve`` defaults to ``auto`` for 10 s; a campaign times one backend for 1 s.
        Param("backend", str, "ils", tuple(OPTW_BACKENDS.names())),
        Param("time_limit_s", float, 1.0), Param.of(read_optw, "vehicles")),
        {"objective": Metric(float), "bound": Metric(float), "solve_status": Metric(str),
         "solve_s": Metric(float, non_negative=True)}, optw_run,
        "a bundled OPTW instance solved by one backend"),
)
"""``toy`` and ``optw_instance``."""
