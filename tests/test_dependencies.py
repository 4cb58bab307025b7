"""The dependency set: OR-Tools and cvxpy import together in either order (no HiGHS clash);
Dask distributed and DuckDB import beside OR-Tools, CasADi and numba."""

from __future__ import annotations

import subprocess
import sys
from importlib import metadata

import pytest

ORDERS = {
    "cvxpy first": "import cvxpy\nfrom ortools.sat.python import cp_model\n"
    "from ortools.linear_solver import pywraplp\nassert pywraplp.Solver.CreateSolver('SCIP')\n"
    "import numpy as np\nx = cvxpy.Variable(2)\n"
    "p = cvxpy.Problem(cvxpy.Minimize(cvxpy.sum(x)), [x >= 1]); p.solve()\n"
    "assert abs(p.value - 2) < 1e-6",
    "ortools first": "from ortools.linear_solver import pywraplp\nimport cvxpy\n"
    "from ortools.sat.python import cp_model\nassert pywraplp.Solver.CreateSolver('SCIP')",
    "searchtrack first": "import searchtrack.plan.optw.solve\nimport cvxpy\n"
    "from ortools.sat.python import cp_model",
}


@pytest.mark.parametrize("order", sorted(ORDERS))
def test_solvers_import_in_any_order(order: str) -> None:
    """OR-Tools and cvxpy both work whichever is imported first, in a fresh interpreter."""
    proc = subprocess.run([sys.executable, "-c", ORDERS[order]], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]

_CAMPAIGN = ("import dask.distributed\nimport duckdb\n"
             "assert duckdb.connect().execute('SELECT 1 + 1').fetchone() == (2,)\n")
_SOLVERS = ("from ortools.sat.python import cp_model\nfrom ortools.linear_solver import pywraplp\n"
            "assert pywraplp.Solver.CreateSolver('SCIP')\nimport casadi\nimport numba\n"
            "x = casadi.SX.sym('x'); assert casadi.Function('f', [x], [x * 2])(3) == 6\n"
            "assert numba.njit(lambda a: a + 1)(1) == 2\n")
CAMPAIGN_ORDERS = {
    "dask and duckdb first": _CAMPAIGN + _SOLVERS,
    "solvers first": _SOLVERS + _CAMPAIGN,
    "searchtrack campaigns first": "import searchtrack.sim.campaigns.runner\n" + _SOLVERS
    + _CAMPAIGN,
}


@pytest.mark.parametrize("order", sorted(CAMPAIGN_ORDERS))
def test_campaign_engines_import_beside_the_solvers(order: str) -> None:
    """dask.distributed and duckdb work beside OR-Tools, CasADi and numba in a fresh
    interpreter, whichever is imported first."""
    proc = subprocess.run([sys.executable, "-c", CAMPAIGN_ORDERS[order]], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]


def test_no_dependency_pulls_in_cvxpy() -> None:
    """searchtrack depends on cvxpy-base (the modelling layer, not cvxpy's bundle of solvers)
    and on highspy for the team-OPTW master; the campaign engines are there too."""
    requires = metadata.requires("searchtrack") or []
    names = {r.split(";")[0].split("[")[0].split(">")[0].split("=")[0].split("<")[0].strip()
             for r in requires}
    assert "cvxpy-base" in names and "highspy" in names
    assert "cvxpy" not in names
    assert {"dask", "duckdb"} <= names


_HIGHS = ("from highspy._core import _Highs\nh = _Highs()\nh.setOptionValue('output_flag', False)\n"
          "assert str(h.run()).endswith('kOk')\n")
_ORTOOLS = ("from ortools.linear_solver import pywraplp\n"
            "s = pywraplp.Solver.CreateSolver('GLOP'); x = s.NumVar(0, 1, 'x'); s.Maximize(x)\n"
            "assert s.Solve() == 0\nassert pywraplp.Solver.CreateSolver('SCIP')\n"
            "from ortools.sat.python import cp_model\n")


@pytest.mark.parametrize("first", ["highspy", "ortools"])
def test_highspy_and_ortools_work_in_either_order(first: str) -> None:
    """HiGHS (the bp master) and OR-Tools (GLOP, SCIP, CP-SAT) both solve in one fresh
    interpreter, whichever is imported first (older wheels bundled clashing HiGHS builds)."""
    code = _HIGHS + _ORTOOLS if first == "highspy" else _ORTOOLS + _HIGHS
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
