"""searchtrack: teams of UAVs that search for and track an unknown number of moving targets.

Layers, each importing only those before it:

``core``
    The one :class:`Result` (with its :class:`Status`) every solver returns, backend registries,
    deadlines, boundary checks, errors, array types and angles.
``models``
    The world and the agents: road networks, targets, sensors, vehicle dynamics.
``estimate``
    Belief states built from sensor data: LRT fields, node trackers, EMD association, SMC-PHD.
``plan``
    Beliefs turned into routes, assignments and trajectories as solver problems (OPTW,
    assignment, search, guidance, trajectory tracking), each with exact and fallback backends.
``sim``
    Scenarios, closed-loop missions and flights, and the papers' experiments.
``cli``
    The ``searchtrack`` command.
"""

from __future__ import annotations

from searchtrack.core.result import Result, Status

__version__ = "0.1.0"

__all__ = ["Result", "Status", "__version__"]
