"""Validated EMD instances and the three ways of mixing unequal masses."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse as sp

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.transport import GraphProblem, TransportProblem, emd
from searchtrack.estimate.transport.problem import balance, is_balanced, signature


def test_masses_normalise_partial_and_equal() -> None:
    """Normalised EMD ignores scale; partial EMD moves min(Σp, Σq); 'equal' keeps units."""
    p, q = np.array([1.0, 1.0]), np.array([0.0, 1.0])
    cost = np.array([[0.0, 2.0], [2.0, 0.0]])
    assert emd(3 * p, q, cost).objective == pytest.approx(1.0)
    partial = emd(p, q, cost, mass="partial")
    assert partial.objective == pytest.approx(0.0)
    assert partial.plan is not None and partial.plan.total_flow == pytest.approx(1.0)
    equal = emd(p, 2 * q, cost, mass="equal")
    assert equal.objective == pytest.approx(1.0)
    assert equal.plan is not None and equal.plan.work == pytest.approx(2.0)


def test_signature_accepts_non_negative_weights() -> None:
    """A list of non-negative numbers with a positive total becomes a float array."""
    out = signature("p", [0, 1, 2])
    assert out.dtype == np.float64 and out.tolist() == [0.0, 1.0, 2.0]


@pytest.mark.parametrize(("values", "text"), [
    ([[1.0, 2.0]], "non-empty 1-D"),
    ([], "non-empty 1-D"),
    (["a", "b"], "array of numbers"),
    ([1.0, -2.0], r"weights must be >= 0 \(p\[1\]\)"),
    ([math.nan, 1.0], r"weights must be finite \(p\[0\]\)"),
    ([0.0, 0.0], "total mass must be positive"),
    ([1e308, 1e308], "total mass must be positive and finite, got inf"),
])
def test_signature_refuses_bad_weights(values: object, text: str) -> None:
    """Wrong shapes, text, negative or NaN entries (located by index) and a zero or overflowing
    total raise naming the signature."""
    with pytest.raises(InvalidInputError, match=text) as err:
        signature("p", values)  # type: ignore[arg-type]
    assert err.value.field == "p"


@pytest.mark.filterwarnings("error")
def test_overflowing_total_is_refused_without_a_warning() -> None:
    """Weights whose total overflows raise naming the signature and emit no RuntimeWarning,
    through signature and through emd."""
    with pytest.raises(InvalidInputError, match="got inf") as err:
        signature("p", [1e308, 1e308])
    assert err.value.field == "p"
    with pytest.raises(InvalidInputError) as err:
        emd([1.0], [1e308, 1e308], [[1.0, 1.0]])
    assert err.value.field == "q"


def test_balance_by_hand() -> None:
    """normalize divides by each total (flow 1); partial keeps the units (flow min); equal
    rescales q onto p's total exactly."""
    p, q = np.array([1.0, 3.0]), np.array([2.0, 2.0, 4.0])
    p_n, q_n, flow = balance(p, q, "normalize")
    assert (p_n.tolist(), q_n.tolist(), flow) == ([0.25, 0.75], [0.25, 0.25, 0.5], 1.0)
    p_p, q_p, flow = balance(p, q, "partial")
    assert p_p is p and q_p is q and flow == 4.0
    near = np.array([2.0, 2.0 + 2e-9])
    p_e, q_e, flow = balance(p, near, "equal")
    assert flow == 4.0 and q_e.sum() == pytest.approx(4.0, rel=1e-15) and p_e is p


def test_balance_refuses_unequal_masses_and_unknown_modes() -> None:
    """mass='equal' with totals 1e-6 apart names q; an unknown mode names mass."""
    with pytest.raises(InvalidInputError, match="mass='equal' needs") as err:
        balance(np.array([1.0]), np.array([1.0 + 1e-6]), "equal")
    assert err.value.field == "q"
    with pytest.raises(InvalidInputError, match="normalize") as err:
        balance(np.array([1.0]), np.array([1.0]), "scaled")
    assert err.value.field == "mass"


def test_is_balanced_is_round_off_only() -> None:
    """Totals 1e-13 apart (relative) are balanced; 1e-9 apart are not."""
    assert is_balanced(1.0, 1.0 + 1e-13)
    assert not is_balanced(1.0, 1.0 + 1e-9)


def test_transport_problem_build() -> None:
    """build() stores a contiguous float cost and the balanced masses; a cost that is not
    numbers or has the wrong shape names ``cost``."""
    problem = TransportProblem.build([1, 1], [2], np.asfortranarray([[1, 2]]).T, "normalize")
    assert problem.cost.flags.c_contiguous and problem.cost.dtype == np.float64
    assert problem.p.tolist() == [0.5, 0.5] and problem.q.tolist() == [1.0]
    assert problem.total_flow == 1.0 and problem.mass == "normalize"
    with pytest.raises(InvalidInputError, match=r"\(len\(p\), len\(q\)\) = \(2, 1\)"):
        TransportProblem.build([1, 1], [2], np.ones((1, 2)), "normalize")
    with pytest.raises(InvalidInputError, match="2-D array of numbers") as err:
        TransportProblem.build([1, 1], [2], [["a"], ["b"]], "normalize")
    assert err.value.field == "cost"


def test_graph_problem_arcs_from_stored_entries() -> None:
    """Every stored entry is an arc, explicit zeros included; self-loops are dropped."""
    adj = sp.csr_array((np.array([0.0, 5.0, 7.0, 2.0]),
                        (np.array([0, 1, 2, 1]), np.array([1, 0, 2, 2]))), shape=(3, 3))
    problem = GraphProblem.build(adj, [1, 0, 0], [0, 0, 2], "partial")
    arcs = sorted(zip(problem.tails.tolist(), problem.heads.tolist(),
                      problem.lengths.tolist(), strict=True))
    assert arcs == [(0, 1, 0.0), (1, 0, 5.0), (1, 2, 2.0)]
    assert problem.n_nodes == 3 and problem.total_flow == 1.0
    assert problem.q.tolist() == [0.0, 0.0, 2.0]  # partial keeps the caller's units


def test_graph_problem_without_edges() -> None:
    """A graph with no stored entry has no arcs (and needs no length check)."""
    problem = GraphProblem.build(sp.csr_array((2, 2)), [1, 0], [0, 1], "normalize")
    assert problem.tails.size == 0 and problem.lengths.size == 0
