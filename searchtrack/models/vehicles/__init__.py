"""Controlled vehicle models for trajectory tracking: unicycle/Dubins (001 §5.1), fixed-wing
kinematics (003 §2.3) and the 7-state UAV of 004 eq. (12), errata fixed.

Design: the dynamics are written once against an array namespace (:mod:`.namespace`) and this
package imports only NumPy; the CasADi namespace and symbolic functions live in the plan layer
(``searchtrack.plan.trajectory.symbolic``), keeping the models → plan layering intact.
"""

from __future__ import annotations

from searchtrack.models.vehicles.fixed_wing import FixedWingDynamics, fixed_wing
from searchtrack.models.vehicles.model import Dynamics, VehicleModel, rk4_step
from searchtrack.models.vehicles.namespace import NUMPY, ArrayNamespace, NumpyNamespace
from searchtrack.models.vehicles.uav7 import GRAVITY_MPS2, Uav7Dynamics, uav7
from searchtrack.models.vehicles.unicycle import UnicycleDynamics, unicycle

__all__ = [
    "GRAVITY_MPS2",
    "NUMPY",
    "ArrayNamespace",
    "Dynamics",
    "FixedWingDynamics",
    "NumpyNamespace",
    "Uav7Dynamics",
    "UnicycleDynamics",
    "VehicleModel",
    "fixed_wing",
    "rk4_step",
    "uav7",
    "unicycle",
]
