"""Orienteering with time windows (OPTW) and team OPTW: instances, files, validator, solvers.

``solve(instance, backend="auto", time_limit_s=..., seed=...)`` picks a backend of
:data:`BACKENDS` by name (``auto``, ``ils``, ``labelling``, ``cpsat``, ``bp``, ``mip``); each
backend's module, and with it Numba, OR-Tools or SCIP, is imported only when it is first used.
"""

from __future__ import annotations

from searchtrack.plan.optw.instance import OPTWInstance, Route, Routes
from searchtrack.plan.optw.io import read_optw, write_optw
from searchtrack.plan.optw.solve import BACKENDS, solve
from searchtrack.plan.optw.validate import Validation, validate

__all__ = [
    "BACKENDS",
    "OPTWInstance",
    "Route",
    "Routes",
    "Validation",
    "read_optw",
    "solve",
    "validate",
    "write_optw",
]
