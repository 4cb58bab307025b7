"""The mission's filter spec: defaults and the RBPF options checked by name."""

from __future__ import annotations

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.roads.filter_spec import SEARCH_FIELDS, FilterSpec


def test_defaults_are_the_thesis_and_the_paper() -> None:
    """The LRT by default; the RBPF at the paper's sizes with fixed counts, searching on the
    LRT's field."""
    f = FilterSpec()
    assert f.belief == "lrt" and (f.histories, f.particles) == (10, 500)
    assert f.kld_epsilon is None and f.search_field == "lrt"
    assert SEARCH_FIELDS == ("particles", "lrt")
    assert FilterSpec(belief="rbpf", search_field="particles").search_field == "particles"


@pytest.mark.parametrize(("changes", "field"), [
    ({"search_field": "gradient"}, "search_field"),
    ({"kld_epsilon": 0.0}, "kld_epsilon"),
    ({"kld_epsilon": 1.0}, "kld_epsilon"),
    ({"kld_epsilon": "0.1"}, "kld_epsilon"),
    ({"particles": 0}, "particles"),
    ({"belief": "kalman"}, "belief"),
])
def test_bad_settings_are_named(changes: dict[str, object], field: str) -> None:
    with pytest.raises(InvalidInputError) as info:
        FilterSpec(**changes)  # type: ignore[arg-type]
    assert info.value.field == field
