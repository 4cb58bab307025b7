"""OSPA, GOSPA and OSPA(2) on hand-computed cases, and their bad-input errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.metrics import gospa, ospa, ospa2, ospa_components, track_distance

NAN = math.nan


def test_ospa_both_empty_is_zero() -> None:
    """Two empty sets are at distance 0."""
    assert ospa([], [], c=100.0) == 0.0
    assert gospa([], [], c=100.0) == 0.0


def test_ospa_one_sided_is_cutoff() -> None:
    """Against an empty set every point costs the cut-off: OSPA = c, GOSPA = (n c^p / 2)^{1/p}."""
    x = [[0.0, 0.0], [5.0, 5.0], [9.0, 1.0]]
    assert ospa(x, [], c=100.0) == pytest.approx(100.0)
    assert ospa([], x, c=50.0, p=2.0) == pytest.approx(50.0)
    assert gospa(x, [], c=100.0) == pytest.approx(150.0)
    assert gospa(x, [], c=10.0, p=2.0) == pytest.approx(math.sqrt(3 * 100 / 2))


def test_ospa_hand_case() -> None:
    """{(0,0), (10,0)} vs {(3,4)}: the best pair costs 5, the unmatched point c; mean over n=2."""
    x = [[0.0, 0.0], [10.0, 0.0]]
    y = [[3.0, 4.0]]
    assert ospa(x, y, c=20.0) == pytest.approx((5.0 + 20.0) / 2)
    assert ospa(x, y, c=20.0, p=2.0) == pytest.approx(math.sqrt((25.0 + 400.0) / 2))
    assert gospa(x, y, c=20.0) == pytest.approx(5.0 + 10.0)
    assert gospa(x, y, c=20.0, alpha=1.0) == pytest.approx(5.0 + 20.0)


def test_cutoff_caps_far_pairs() -> None:
    """A pair farther apart than c costs exactly c."""
    assert ospa([[0.0, 0.0]], [[1000.0, 0.0]], c=100.0) == pytest.approx(100.0)
    assert gospa([[0.0, 0.0]], [[1000.0, 0.0]], c=100.0) == pytest.approx(100.0)


def test_assignment_is_optimal() -> None:
    """The matching is optimal, not greedy: the greedy pairing would cost more."""
    x = [[0.0, 0.0], [4.0, 0.0]]
    y = [[2.0, 0.0], [6.5, 0.0]]
    # Optimal: (0→2, 4→6.5) = 2 + 2.5; greedy nearest-first takes (4→2) then (0→6.5) = 2 + 6.5.
    assert ospa(x, y, c=100.0) == pytest.approx(4.5 / 2)


def test_ospa_is_symmetric() -> None:
    """OSPA and GOSPA do not depend on the order of the arguments."""
    rng = np.random.default_rng(3)
    x, y = rng.random((4, 2)) * 50, rng.random((7, 2)) * 50
    assert ospa(x, y, 20.0) == pytest.approx(ospa(y, x, 20.0))
    assert gospa(x, y, 20.0, 2.0) == pytest.approx(gospa(y, x, 20.0, 2.0))


def test_track_distance_hand_case() -> None:
    """Both exist at t0 (distance 5), only x at t1 (c), neither at t2: mean over 2 scans."""
    x = np.array([[0.0, 0.0], [1.0, 1.0], [NAN, NAN]])
    y = np.array([[3.0, 4.0], [NAN, NAN], [NAN, NAN]])
    assert track_distance(x, y, c=10.0) == pytest.approx(7.5)
    assert track_distance(np.full((2, 2), NAN), np.full((2, 2), NAN), c=10.0) == 0.0


def test_ospa2_hand_case() -> None:
    """Two truth tracks, one estimated track close to the first: (7.5 + c) / 2."""
    truth = [np.array([[0.0, 0.0], [0.0, 0.0], [NAN, NAN]]),
             np.array([[50.0, 50.0], [50.0, 50.0], [50.0, 50.0]])]
    est = [np.array([[3.0, 4.0], [NAN, NAN], [NAN, NAN]])]
    assert ospa2(truth, est, c=10.0) == pytest.approx((7.5 + 10.0) / 2)
    assert ospa2(truth, truth, c=10.0) == 0.0
    assert ospa2([], [], c=10.0) == 0.0
    assert ospa2(truth, [], c=10.0) == pytest.approx(10.0)


@pytest.mark.parametrize(("call", "field"), [
    (lambda: ospa([[0.0, 0.0]], [[1.0, 1.0]], c=0.0), "c"),
    (lambda: ospa([[0.0, 0.0]], [[1.0, 1.0]], c=10.0, p=-1.0), "p"),
    (lambda: ospa([[NAN, 0.0]], [[1.0, 1.0]], c=10.0), "x"),
    (lambda: ospa([[0.0, 0.0]], [[1.0, 1.0, 1.0]], c=10.0), "y"),
    (lambda: gospa([[0.0, 0.0]], [[1.0, 1.0]], c=10.0, alpha=3.0), "alpha"),
    (lambda: ospa2([np.zeros(3)], [], c=10.0), "x_tracks[0]"),
    (lambda: ospa2([np.zeros((3, 2))], [np.zeros((2, 2))], c=10.0), "y"),
])
def test_bad_input(call: object, field: str) -> None:
    """Bad sets or parameters raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        call()  # type: ignore[operator]
    assert err.value.field == field


def test_ospa_components_hand_case() -> None:
    """{(0,0), (10,0)} vs {(3,4)}, c = 20: localisation 5/2, cardinality 20/2, total their sum."""
    x = [[0.0, 0.0], [10.0, 0.0]]
    y = [[3.0, 4.0]]
    total, loc, card = ospa_components(x, y, c=20.0)
    assert (total, loc, card) == pytest.approx((12.5, 2.5, 10.0))
    total, loc, card = ospa_components(x, y, c=20.0, p=2.0)
    assert loc == pytest.approx(math.sqrt(25.0 / 2))
    assert card == pytest.approx(math.sqrt(400.0 / 2))
    assert total == pytest.approx(math.sqrt(loc**2 + card**2))


def test_ospa_components_edge_cases() -> None:
    """Both empty: all zero; one empty: all cardinality; equal sizes: all localisation."""
    assert ospa_components([], [], c=10.0) == (0.0, 0.0, 0.0)
    assert ospa_components([[1.0, 2.0]], [], c=10.0) == pytest.approx((10.0, 0.0, 10.0))
    total, loc, card = ospa_components([[0.0, 0.0]], [[3.0, 4.0]], c=10.0)
    assert (total, loc, card) == pytest.approx((5.0, 5.0, 0.0))


@pytest.mark.parametrize("p", [1.0, 2.0, 3.0])
def test_ospa_components_decompose_ospa(p: float) -> None:
    """On random sets total = OSPA and total^p = loc^p + card^p, in either argument order."""
    rng = np.random.default_rng(7)
    x, y = rng.random((3, 2)) * 60, rng.random((6, 2)) * 60
    for a, b in ((x, y), (y, x)):
        total, loc, card = ospa_components(a, b, 25.0, p)
        assert total == pytest.approx(ospa(a, b, 25.0, p))
        assert total**p == pytest.approx(loc**p + card**p)
        assert card == pytest.approx((25.0**p * 3 / 6) ** (1 / p))


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"x": [[0.0, 0.0]], "y": [[1.0, 1.0]], "c": -1.0}, "c"),
    ({"x": [[0.0, 0.0]], "y": [[1.0, 1.0]], "c": 10.0, "p": 0.0}, "p"),
    ({"x": [[0.0, NAN]], "y": [[1.0, 1.0]], "c": 10.0}, "x"),
    ({"x": [[0.0, 0.0]], "y": [[1.0]], "c": 10.0}, "y"),
])
def test_ospa_components_bad_input(kwargs: dict[str, object], field: str) -> None:
    """Bad sets or parameters raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        ospa_components(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field
