"""Orienteering with time windows (OPTW) and team OPTW: instances, files, validator, solvers."""

from __future__ import annotations

from searchtrack.plan.optw.instance import OPTWInstance, Route, Routes
from searchtrack.plan.optw.io import read_optw, write_optw
from searchtrack.plan.optw.validate import Validation, validate

__all__ = ["OPTWInstance", "Route", "Routes", "Validation", "read_optw", "validate", "write_optw"]
