"""searchtrack.plan: planners posed as solver problems, each family a registry of backends that
return :class:`searchtrack.core.Result` — ``optw`` (routes), ``assign`` (one action per UAV),
``search`` (004's receding-horizon step and lawnmowers), ``guidance`` (the thesis's potential
fields and reacquisition) and ``trajectory`` (controllers). Planners read beliefs through the
protocols of :mod:`searchtrack.estimate.belief`."""

from __future__ import annotations
