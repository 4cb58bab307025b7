"""searchtrack.sim.experiments: the papers' experiments as functions of a seed — the thesis's road
missions (experiments 1 and 2), 003's tracking loop, 004's search episodes and its E7 flights."""

from __future__ import annotations
