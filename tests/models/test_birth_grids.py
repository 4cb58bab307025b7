"""Birth and survival grids counted from tracks (paper 003, §1.3): counts, lookups, sampling."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import random_network
from searchtrack.models.birth_grids import BirthSurvivalGrid
from searchtrack.models.road_traces import taxi_traces

BOUNDS = [[0.0, 40.0], [0.0, 20.0]]  # 4 × 2 cells of 10 m


def _crossing(birth: float = 0.0, survival: float = 1e-9, death: float = 0.0,
              **kwargs: bool) -> BirthSurvivalGrid:
    """One track crossing the bottom row left to right at 5 m/s (samples every 2 s, 10 m)."""
    x = np.arange(-15.0, 60.0, 10.0)  # −15, −5 (outside), 5, 15, 25, 35 (inside), 45, 55
    xy = np.column_stack([x, np.full(x.size, 5.0)])
    return BirthSurvivalGrid.from_tracks(xy, np.zeros(x.size, dtype=int), 2.0 * np.arange(x.size),
                                         BOUNDS, 10.0, 2.0, birth_prior=birth,
                                         survival_prior=survival, death_prior=death, **kwargs)


def test_counts_of_one_crossing() -> None:
    """Entering gives a birth in the first cell, leaving a death in the last, survivals between."""
    g = _crossing()
    assert g.shape == (4, 2)
    np.testing.assert_allclose(g.birth_counts[:, 0], [1, 0, 0, 0])
    np.testing.assert_allclose(g.death_counts[:, 0], [0, 0, 0, 1])
    np.testing.assert_allclose(g.survival_counts[:, 0], [0, 1, 1, 1], atol=1e-8)
    assert g.birth_counts[:, 1].sum() == 0.0
    assert g.birth_rate_per_s == pytest.approx(1 / 16.0)  # 1 birth over 8 samples × 2 s


def test_priors_give_uniform_births_and_survival_point_nine() -> None:
    """With no data the priors 10/9/1 give a uniform birth pdf and p_s = 0.9 everywhere."""
    g = BirthSurvivalGrid.from_tracks(np.empty((0, 2)), np.empty(0, dtype=int), np.empty(0),
                                      BOUNDS, 10.0, 1.0)
    np.testing.assert_allclose(g.birth_pdf, np.full((4, 2), 1 / 8))
    np.testing.assert_allclose(g.survival_grid, 0.9)
    assert g.birth_rate_per_s == 0.0


def test_birth_pdf_is_normalised_and_intensity_integrates_to_the_mass() -> None:
    """The birth pdf sums to 1 and b(x) integrates over the area to rate · Δt."""
    g = _crossing(10.0, 9.0, 1.0)
    assert g.birth_pdf.sum() == pytest.approx(1.0)
    assert g.birth_pdf[0, 0] > g.birth_pdf[1, 0]
    cx, cy = np.meshgrid(np.arange(5.0, 40.0, 10.0), np.arange(5.0, 20.0, 10.0), indexing="ij")
    b = g.birth_intensity(np.column_stack([cx.ravel(), cy.ravel()]), 4.0)
    assert b.sum() * 100.0 == pytest.approx(g.birth_mass(4.0))
    assert g.birth_intensity(np.array([[-1.0, 5.0]]), 4.0)[0] == 0.0
    np.testing.assert_allclose(g.birth_intensity(np.array([[5.0, 5.0]])),
                               g.birth_intensity(np.array([[5.0, 5.0]]), g.data_dt_s))


def test_survival_lookup_rescales_with_the_step() -> None:
    """p_s per data step, p_s^(Δt/Δt_data) for another step, and 0 outside the area."""
    g = _crossing(10.0, 9.0, 1.0)
    pos = np.array([[35.0, 5.0], [5.0, 15.0], [100.0, 5.0]])
    ps = g.survival(pos)
    assert ps[0] == pytest.approx(10.0 / 12.0)  # last cell: 9 + 1 survivals, 1 + 1 deaths
    assert ps[1] == pytest.approx(0.9)
    assert ps[2] == 0.0
    np.testing.assert_allclose(g.survival(pos[:2], 6.0), ps[:2] ** 3)


def test_same_cell_and_trace_end_options() -> None:
    """count_same_cell=False counts only cell changes; trace ends can count as births/deaths."""
    xy = np.array([[5.0, 5.0], [6.0, 5.0], [7.0, 5.0], [15.0, 5.0]])

    def count(same: bool = True, ends: bool = False) -> BirthSurvivalGrid:
        return BirthSurvivalGrid.from_tracks(
            xy, np.zeros(4, dtype=int), np.arange(4.0), BOUNDS, 10.0, 1.0, birth_prior=0.0,
            survival_prior=1.0, death_prior=0.0, count_same_cell=same,
            trace_start_is_birth=ends, trace_end_is_death=ends)

    every, moves, ends = count(), count(same=False), count(ends=True)
    assert every.survival_counts[0, 0] - 1 == 2 and moves.survival_counts[0, 0] - 1 == 0
    assert every.birth_counts.sum() == 0.0
    assert ends.birth_counts[0, 0] == 1.0 and ends.death_counts[1, 0] == 1.0


def test_sampling_follows_the_birth_counts_and_is_seeded() -> None:
    """Birth samples fall inside the area, mostly in the heavy cell, and repeat for a seed."""
    counts = np.ones((4, 2))
    counts[2, 1] = 97.0
    g = BirthSurvivalGrid(np.array(BOUNDS), 10.0, counts, np.ones((4, 2)), np.ones((4, 2)),
                          0.5, 1.0)
    s = g.sample_births(4000, np.random.default_rng(1))
    assert np.all((s >= [0.0, 0.0]) & (s <= [40.0, 20.0]))
    heavy = np.mean((s[:, 0] >= 20.0) & (s[:, 0] < 30.0) & (s[:, 1] >= 10.0))
    assert heavy == pytest.approx(97.0 / 104.0, abs=0.02)
    np.testing.assert_array_equal(s, g.sample_births(4000, np.random.default_rng(1)))


def test_counts_from_taxi_traces_sit_on_the_area_edges() -> None:
    """On road traces crossing a sub-area, data births happen in the cells at its edge."""
    roads = random_network(20, 600.0, 10.0, seed=1)
    tr = taxi_traces(roads, 10, 1800.0, 2.0, np.random.default_rng(2))
    g = BirthSurvivalGrid.from_tracks(tr.xy_m, tr.vehicle, tr.time_s,
                                      [[150.0, 450.0], [150.0, 450.0]], 50.0, tr.dt_s,
                                      birth_prior=0.0)
    assert g.birth_rate_per_s > 0.0
    inner = g.birth_counts[1:-1, 1:-1].sum()
    edge = g.birth_counts.sum() - inner
    assert edge > 5 * inner


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"bounds": [[0.0, 0.0], [0.0, 1.0]]}, "bounds"), ({"cell_m": 0.0}, "cell_m"),
    ({"data_dt_s": 0.0}, "data_dt_s"), ({"birth_prior": -1.0}, "birth_prior"),
    ({"survival_prior": -1.0}, "survival_prior"), ({"death_prior": np.nan}, "death_prior"),
    ({"track": [0.5, 1.5]}, "track"), ({"xy_m": [[0.0, 0.0, 0.0]]}, "xy_m"),
    ({"time_s": [0.0]}, "time_s"), ({"count_same_cell": 1}, "count_same_cell"),
])
def test_bad_from_tracks(kwargs: dict[str, object], field: str) -> None:
    """Bad arguments of from_tracks raise InvalidInputError naming the argument."""
    args: dict[str, object] = {"xy_m": [[1.0, 1.0], [2.0, 1.0]], "track": [0, 0],
                               "time_s": [0.0, 1.0], "bounds": BOUNDS, "cell_m": 10.0,
                               "data_dt_s": 1.0}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        BirthSurvivalGrid.from_tracks(**args)  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"cell_m": 15.0}, "cell_m"), ({"birth_counts": np.full((4, 2), np.inf)}, "birth_counts"),
    ({"survival_counts": -np.ones((4, 2))}, "survival_counts"),
    ({"death_counts": np.ones((2, 4))}, "death_counts"),
    ({"birth_rate_per_s": -1.0}, "birth_rate_per_s"), ({"data_dt_s": 0.0}, "data_dt_s"),
])
def test_bad_grid(kwargs: dict[str, object], field: str) -> None:
    """A grid with a bad part is refused, naming it."""
    args: dict[str, object] = {"bounds": np.array(BOUNDS), "cell_m": 10.0,
                               "birth_counts": np.ones((4, 2)), "survival_counts": np.ones((4, 2)),
                               "death_counts": np.ones((4, 2)), "birth_rate_per_s": 1.0,
                               "data_dt_s": 1.0}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        BirthSurvivalGrid(**args)  # type: ignore[arg-type]
    assert err.value.field == field


def test_no_births_cannot_be_sampled() -> None:
    """A grid without birth counts has a zero pdf and refuses to sample births."""
    g = BirthSurvivalGrid(np.array(BOUNDS), 10.0, np.zeros((4, 2)), np.ones((4, 2)),
                          np.ones((4, 2)), 0.0, 1.0)
    assert g.birth_pdf.sum() == 0.0
    with pytest.raises(InvalidInputError, match="birth_counts"):
        g.sample_births(3, np.random.default_rng(0))


def test_zero_survival_and_death_cell_is_refused() -> None:
    """A cell with no survival and no death count has no p_s and is refused."""
    surv = np.ones((4, 2))
    surv[0, 0] = 0.0
    deaths = np.ones((4, 2))
    deaths[0, 0] = 0.0
    with pytest.raises(InvalidInputError, match="death_counts"):
        BirthSurvivalGrid(np.array(BOUNDS), 10.0, np.ones((4, 2)), surv, deaths, 1.0, 1.0)
