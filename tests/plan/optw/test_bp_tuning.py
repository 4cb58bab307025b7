"""Validation of the branch-and-price knobs: one error naming the field, never a silent no-op."""

from __future__ import annotations

from typing import Any

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.optw.bp import Tuning as FromSolver
from searchtrack.plan.optw.bp_tuning import Tuning


def test_the_solver_uses_this_tuning() -> None:
    assert FromSolver is Tuning


def test_defaults_and_documented_variants_are_accepted() -> None:
    Tuning()
    Tuning(heuristic_cap=1 << 14, bidirectional=False)
    Tuning(smoothing=0.0, table_ng=None, cuts_per_round=0, ils_again_max_s=0.0)


@pytest.mark.parametrize(("field", "value"), [
    ("smoothing", 1.0), ("smoothing", -0.1), ("smoothing", float("nan")),
    ("heuristic_cap", -1), ("heuristic_cap", 2.5), ("table_ng", 0), ("bidirectional", 1),
    ("collect", 0), ("ils_share", 1.5), ("ils_again_share", -0.1), ("ils_max_s", -1.0),
    ("primal_s", float("inf")), ("ils_iterations", -5), ("cuts_max", True),
    ("cut_depth", -1), ("primal_every", 0), ("strong", 0), ("strong", 1.5), ("half_tables", 1),
    ("enum_labels", -1), ("enum_routes", 2.5), ("enum_mip_s", -1.0), ("fix_arcs", 0),
])
def test_a_bad_value_names_its_field(field: str, value: Any) -> None:
    with pytest.raises(InvalidInputError, match=field):
        Tuning(**{field: value})


def test_a_guided_pass_without_whole_passes_is_refused() -> None:
    """The guided heuristic reads the forward table of whole passes; with bidirectional pricing
    it would never run, so the combination is an error rather than a silent no-op."""
    with pytest.raises(InvalidInputError, match="heuristic_cap"):
        Tuning(heuristic_cap=1000)
