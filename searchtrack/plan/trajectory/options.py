"""How the NMPC's nonlinear program is built and solved (CasADi ``nlpsol`` options)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError


@dataclass(frozen=True)
class NmpcOptions:
    """How the NLP is built and solved.

    Parameters
    ----------
    solver
        ``"ipopt"`` (interior point) or ``"sqpmethod"`` (SQP with ``qpsol``). Fatrop is not
        offered: its structure detection needs stage-local path constraints, and the input-rate
        constraint couples neighbouring stages.
    qpsol
        QP solver of ``sqpmethod``: ``"qrqp"`` or ``"osqp"``.
    hessian
        ``"exact"`` or ``"limited-memory"`` (Ipopt's quasi-Newton).
    linear_solver
        Ipopt's linear solver (``"mumps"``; ``"ma27"`` needs the HSL library).
    jit
        Compile the NLP functions with the system C compiler (build takes seconds).
    expand
        Expand the MX graph to SX (faster evaluation).
    max_iter
        Iteration cap.
    tol
        Convergence tolerance (Ipopt ``tol``; ``acceptable_tol`` is 100 times it).
    mu_init
        Ipopt's initial barrier parameter (small values suit warm starts).
    mu_strategy
        Ipopt's barrier update, ``"adaptive"`` or ``"monotone"``.
    """

    solver: Literal["ipopt", "sqpmethod"] = "ipopt"
    qpsol: Literal["qrqp", "osqp"] = "qrqp"
    hessian: Literal["exact", "limited-memory"] = "exact"
    linear_solver: str = "mumps"
    jit: bool = False
    expand: bool = True
    max_iter: int = 100
    tol: float = 1e-4
    mu_init: float = 1e-2
    mu_strategy: Literal["adaptive", "monotone"] = "adaptive"

    def __post_init__(self) -> None:
        if self.solver not in ("ipopt", "sqpmethod"):
            raise InvalidInputError("solver", self.solver, "must be 'ipopt' or 'sqpmethod'")
        if self.qpsol not in ("qrqp", "osqp"):  # the CasADi conic plugins nmpc.py configures
            raise InvalidInputError("qpsol", self.qpsol, "must be 'qrqp' or 'osqp'")
        if self.hessian not in ("exact", "limited-memory"):
            raise InvalidInputError("hessian", self.hessian, "must be exact or limited-memory")
        if self.mu_strategy not in ("adaptive", "monotone"):
            raise InvalidInputError("mu_strategy", self.mu_strategy,
                                    "must be 'adaptive' or 'monotone'")
        checks.count("max_iter", self.max_iter, least=1)
        checks.positive("tol", self.tol)
        checks.positive("mu_init", self.mu_init)
