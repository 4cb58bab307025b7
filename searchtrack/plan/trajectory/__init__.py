"""Trajectory tracking as nonlinear programs: CasADi NMPC, OSQP LTV-MPC and the closed-form
backstepping (paper 004 eq. 13) / pursuit fallback behind one registry, with obstacles and
references."""

from __future__ import annotations

from searchtrack.plan.trajectory.closed_form import ClosedFormGains, control_law, solve_closed_form
from searchtrack.plan.trajectory.ltv_mpc import solve_ltv_mpc
from searchtrack.plan.trajectory.nmpc import solve_nmpc
from searchtrack.plan.trajectory.obstacles import Obstacles
from searchtrack.plan.trajectory.options import NmpcOptions
from searchtrack.plan.trajectory.problem import ControlPlan, TrackingProblem, TrackingWeights
from searchtrack.plan.trajectory.reference import Reference, SampledPath, waypoint_path
from searchtrack.plan.trajectory.solve import BACKENDS, solve

__all__ = [
    "BACKENDS",
    "ClosedFormGains",
    "ControlPlan",
    "NmpcOptions",
    "Obstacles",
    "Reference",
    "SampledPath",
    "TrackingProblem",
    "TrackingWeights",
    "control_law",
    "solve",
    "solve_closed_form",
    "solve_ltv_mpc",
    "solve_nmpc",
    "waypoint_path",
]
