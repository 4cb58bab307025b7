"""Every backend maps each native status to one of ours, anything unknown to ERROR."""

from __future__ import annotations

from typing import Any

import numpy as np

from searchtrack.core.result import Status
from searchtrack.estimate.transport.lp import map_status as lp_status
from searchtrack.estimate.transport.network import map_status as network_status
from searchtrack.estimate.transport.simplex import FlowSolution


def test_status_mapping_is_explicit() -> None:
    """Each native status maps to one of ours; anything unknown is ERROR."""
    assert lp_status("optimal") is Status.OPTIMAL
    assert lp_status("infeasible") is Status.INFEASIBLE
    assert lp_status("optimal_inaccurate") is Status.NO_SOLUTION
    assert lp_status("unbounded") is Status.ERROR
    assert lp_status("something new") is Status.ERROR
    empty = (np.zeros(0, dtype=np.int64), np.zeros(0))

    def raw(status: Any, unrouted: float) -> FlowSolution:
        return FlowSolution(status, *empty, unrouted, 0, routed=unrouted == 0.0)

    assert network_status(raw("optimal", 0.0)) is Status.OPTIMAL
    assert network_status(raw("infeasible", 1.0)) is Status.INFEASIBLE
    assert network_status(raw("time_limit", 0.0)) is Status.FEASIBLE
    assert network_status(raw("time_limit", 0.5)) is Status.NO_SOLUTION
    assert network_status(raw("unbounded", 0.0)) is Status.ERROR
    assert network_status(raw("weird", 0.0)) is Status.ERROR
