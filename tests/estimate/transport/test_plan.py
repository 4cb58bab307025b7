"""What an EMD solve returns: a sparse transport plan, or a flow on a graph's arcs."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate.transport import GraphFlow, TransportPlan


def _plan() -> TransportPlan:
    """0.25 from p[0] to q[2] at cost 4 and 0.5 from p[1] to q[0] at cost 2: work 2, flow 0.75."""
    return TransportPlan(np.array([0, 1]), np.array([2, 0]), np.array([0.25, 0.5]), (2, 3),
                         work=2.0, total_flow=0.75)


def test_transport_plan_emd_is_work_over_flow() -> None:
    """EMD = work / total flow (Rubner et al.): 2 / 0.75."""
    assert _plan().emd == pytest.approx(8.0 / 3.0)


def test_transport_plan_dense_matrix() -> None:
    """dense() puts each amount at its (row, column) of an (m, n) zero matrix."""
    np.testing.assert_array_equal(_plan().dense(), [[0.0, 0.0, 0.25], [0.5, 0.0, 0.0]])
    empty = TransportPlan(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0),
                          (2, 2), 0.0, 1.0)
    assert empty.dense().shape == (2, 2) and empty.emd == 0.0


def test_plans_are_read_only() -> None:
    """A plan's arrays cannot be written through."""
    plan = _plan()
    flow = GraphFlow(np.array([0]), np.array([1]), np.array([1.0]), 2, 1.0, 1.0)
    for arr in (plan.rows, plan.cols, plan.amounts, flow.tails, flow.heads, flow.amounts):
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 0


def test_graph_flow_net_outflow_and_emd_by_hand() -> None:
    """Flows 0.5 on 0→1 (10 m) and 0.25 on 1→2 (20 m): net outflow (0.5, −0.25, −0.25, 0) on four
    nodes, work 10, EMD 10 / 0.5."""
    flow = GraphFlow(np.array([0, 1]), np.array([1, 2]), np.array([0.5, 0.25]), 4,
                     work=0.5 * 10 + 0.25 * 20, total_flow=0.5)
    np.testing.assert_allclose(flow.net_outflow(), [0.5, -0.25, -0.25, 0.0])
    assert flow.emd == pytest.approx(20.0)
