"""NmpcOptions: the defaults and the named errors for values outside each option's domain."""

from __future__ import annotations

import dataclasses
import math

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.trajectory import NmpcOptions


def test_options_reject_out_of_domain_values() -> None:
    """NmpcOptions rejects out-of-domain values by name."""
    with pytest.raises(InvalidInputError, match="solver"):
        NmpcOptions(solver="fatrop")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="max_iter"):
        NmpcOptions(max_iter=0)
    with pytest.raises(InvalidInputError, match="tol"):
        NmpcOptions(tol=-1.0)


def test_defaults_are_exact_hessian_ipopt_with_mumps() -> None:
    """The default is Ipopt with the exact Hessian, MUMPS, no JIT, SX expansion, 100 iterations."""
    opts = NmpcOptions()
    assert (opts.solver, opts.hessian, opts.linear_solver) == ("ipopt", "exact", "mumps")
    assert (opts.jit, opts.expand, opts.max_iter) == (False, True, 100)
    assert (opts.tol, opts.mu_init, opts.mu_strategy) == (1e-4, 1e-2, "adaptive")


@pytest.mark.parametrize(("changes", "field"), [
    ({"hessian": "bfgs"}, "hessian"), ({"mu_strategy": "probing"}, "mu_strategy"),
    ({"max_iter": 2.5}, "max_iter"), ({"max_iter": True}, "max_iter"),
    ({"tol": 0.0}, "tol"), ({"tol": math.nan}, "tol"), ({"mu_init": -1e-3}, "mu_init"),
    ({"mu_init": math.inf}, "mu_init")])
def test_each_bad_option_names_its_field(changes: dict[str, object], field: str) -> None:
    """Unknown Hessian or barrier names, non-integer or boolean iteration caps and non-positive
    or non-finite tolerances each name their field."""
    with pytest.raises(InvalidInputError) as info:
        NmpcOptions(**changes)  # type: ignore[arg-type]
    assert info.value.field == field


def test_valid_alternatives_are_accepted_and_options_are_frozen() -> None:
    """SQP with OSQP, limited memory and the monotone barrier are accepted; options are hashable
    (they key the solver cache) and cannot be changed."""
    opts = NmpcOptions(solver="sqpmethod", qpsol="osqp", hessian="limited-memory",
                       mu_strategy="monotone", max_iter=1)
    assert hash(opts) == hash(NmpcOptions(solver="sqpmethod", qpsol="osqp",
                                          hessian="limited-memory", mu_strategy="monotone",
                                          max_iter=1))
    with pytest.raises(dataclasses.FrozenInstanceError):
        opts.max_iter = 5  # type: ignore[misc]


@pytest.mark.parametrize("qpsol", ["bogus", "qpoases"])
def test_unsupported_qp_solver_is_named(qpsol: str) -> None:
    """A QP solver other than qrqp or osqp (even one CasADi has) is refused naming qpsol."""
    with pytest.raises(InvalidInputError, match="must be 'qrqp' or 'osqp'") as info:
        NmpcOptions(solver="sqpmethod", qpsol=qpsol)  # type: ignore[arg-type]
    assert info.value.field == "qpsol"
