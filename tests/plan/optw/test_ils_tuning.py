"""Validation of the ILS search parameters: one error naming the field, never a traceback from
inside the search or a knob that silently does nothing."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.optw import ils_search as KS
from searchtrack.plan.optw.ils import Tuning as FromSolver
from searchtrack.plan.optw.ils_tuning import Tuning


def test_the_solver_uses_this_tuning() -> None:
    assert FromSolver is Tuning


def test_defaults_and_documented_variants_are_accepted() -> None:
    Tuning()
    Tuning(w_route=1.0, relocate=True, k_max=6, split=False, elite=3, cycle0=10, grow=1.2)
    Tuning(pool=0.0, local_search=False, replace=False, t_end=0.0, temperature=0.0)


def test_the_parameter_array_follows_the_kernel_indices() -> None:
    """``array`` lays the knobs out as the search kernel reads them; one route has no pool."""
    t = Tuning(k_frac=0.25, grow=1.75, k_max=9, pool=0.05)
    par = t.array(3)
    assert par.shape == (KS.P_POOL + 1,)
    assert (par[KS.P_KFRAC], par[KS.P_GROW], par[KS.P_KMAX], par[KS.P_POOL]) == \
        (0.25, 1.75, 9.0, 0.05)
    assert t.array(1)[KS.P_POOL] == 0.0
    assert np.array_equal(np.delete(t.array(1), KS.P_POOL), np.delete(par, KS.P_POOL))


@pytest.mark.parametrize(("field", "value"), [
    ("k_frac", 1.5), ("k_frac", float("nan")), ("temperature", -1.0), ("t_end", 2.0),
    ("cycle0", 0), ("cycle0", 2.5), ("grow", 0.5), ("p_equal", 1.1), ("alpha_lo", -1.0),
    ("alpha_hi", 0.5), ("noise", float("inf")), ("w_target", -1.0), ("local_search", 1),
    ("relocate", "yes"), ("k_max", 3), ("elite", -1), ("pool", -0.1), ("pool", 1.0),
    ("pool", float("nan")), ("pool_size", 0), ("pack_every", 0), ("pack_nodes", -1),
    ("pack_s", -0.01),
])
def test_a_bad_value_names_its_field(field: str, value: Any) -> None:
    """Out-of-domain knobs fail at once (an empty route pool, for one, would crash the search,
    and a negative ``pack_s`` would keep it past its deadline)."""
    with pytest.raises(InvalidInputError, match=field):
        Tuning(**{field: value})


def test_all_ruin_weights_zero_is_refused() -> None:
    zero = {name: 0.0 for name in ("w_segment", "w_random", "w_related", "w_target", "w_fit",
                                   "w_route")}
    with pytest.raises(InvalidInputError, match="ruin"):
        Tuning(**zero)
