"""searchtrack.plan: planners posed as solver problems, each family a registry of backends that
return :class:`searchtrack.core.Result` — ``optw`` (routes), ``assign`` (one action per UAV),
``search`` (004's receding-horizon step and lawnmowers), ``guidance`` (the thesis's potential
fields and reacquisition), ``trajectory`` (controllers) and ``road_search`` (paper 000's
receding-horizon road planners); beside them ``road_rl`` (000's trained policy flown by NumPy)
and ``fleet`` (000's entropy lower bound and fleet sizing). Planners read beliefs through the
protocols of :mod:`searchtrack.estimate.belief`."""

from __future__ import annotations
