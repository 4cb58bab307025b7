"""Planners: solver problems with exact backends and fast fallbacks, sharing one result type."""

from __future__ import annotations

from searchtrack.plan.registry import Backend, Registry
from searchtrack.plan.result import Result, Sense, Status
from searchtrack.plan.stop import Deadline

__all__ = ["Backend", "Deadline", "Registry", "Result", "Sense", "Status"]
