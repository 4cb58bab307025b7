"""Boundary checks: read-only arrays, numbers in range, arrays of a shape, each naming the field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core import checks
from searchtrack.core.checks import readonly
from searchtrack.core.errors import InvalidInputError


def test_readonly_copies_unless_told_not_to() -> None:
    """readonly() freezes a copy, keeping the dtype; copy=False freezes the array itself."""
    a = np.arange(4)
    frozen = readonly(a)
    assert frozen.dtype == a.dtype and not frozen.flags.writeable and a.flags.writeable
    a[0] = 7
    assert frozen[0] == 0
    b = np.zeros(3)
    assert readonly(b, copy=False) is b and not b.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        frozen[1] = 5


@pytest.mark.parametrize(("check", "good", "bad"), [
    (checks.positive, [1e-12, 3, np.float32(2.5)], [0.0, -1.0, math.inf, math.nan, True, "1"]),
    (checks.non_negative, [0.0, 0, np.int64(4)], [-1e-12, math.inf, None, False]),
    (checks.probability, [1e-9, 0.5, 1 - 1e-9], [0.0, 1.0, -0.1, 1.5, math.nan]),
])
def test_number_checks_accept_their_range_only(check, good: list[object],  # type: ignore[no-untyped-def]
                                               bad: list[object]) -> None:
    """positive, non_negative and probability return floats in range; anything else (bools,
    strings, NaN, inf, the excluded end) raises naming the field."""
    for value in good:
        out = check("speed_mps", value)
        assert isinstance(out, float) and out == float(value)  # type: ignore[arg-type]
    for value in bad:
        with pytest.raises(InvalidInputError) as err:
            check("speed_mps", value)
        assert err.value.field == "speed_mps" and err.value.value is value


def test_real_reports_the_interval_it_wanted() -> None:
    """real() honours open and closed ends and spells the interval in its message."""
    assert checks.real("x", 2, low=2.0, high=3.0) == 2.0
    with pytest.raises(InvalidInputError, match=r"x=2: must be a finite number in \(2, 3\]"):
        checks.real("x", 2, low=2.0, high=3.0, low_open=True)
    with pytest.raises(InvalidInputError, match=r"in \[2, 3\)"):
        checks.real("x", 3.0, low=2.0, high=3.0, high_open=True)


def test_count_takes_integers_at_least_its_floor() -> None:
    """count() returns a Python int for ints and NumPy ints ≥ least; refuses floats and bools."""
    assert checks.count("n", 0) == 0
    out = checks.count("n", np.int32(5), least=5)
    assert out == 5 and type(out) is int
    for bad in (4, 2.0, True, "5"):
        with pytest.raises(InvalidInputError, match=r"n=.*≥ 5"):
            checks.count("n", bad, least=5)


@pytest.mark.parametrize("bad", [0, 1, np.bool_(True), "yes", None, 1.0])
def test_boolean_takes_true_or_false_only(bad: object) -> None:
    """A flag is ``True`` or ``False``; a number, string or NumPy bool is one clear error."""
    assert checks.boolean("flag", True) is True and checks.boolean("flag", False) is False
    with pytest.raises(InvalidInputError, match="flag"):
        checks.boolean("flag", bad)


def test_finite_array_checks_shape_and_values() -> None:
    """finite_array gives a read-only float copy of the shape (None: any length), else raises."""
    src = [[1, 2], [3, 4], [5, 6]]
    arr = checks.finite_array("xy", src, (None, 2))
    assert arr.dtype == np.float64 and arr.shape == (3, 2) and not arr.flags.writeable
    with pytest.raises(InvalidInputError, match=r"shape \(k, 3\), got \(3, 2\)"):
        checks.finite_array("xy", src, (None, 3))
    with pytest.raises(InvalidInputError, match="finite"):
        checks.finite_array("xy", [[0.0, math.nan]], (None, 2))
    with pytest.raises(InvalidInputError, match="array of numbers"):
        checks.finite_array("xy", [["a", "b"]], (None, 2))


@pytest.mark.parametrize(("value", "shape"), [
    ([], (0, 2)),
    ([3.0, 4.0], (1, 2)),
    ([[0.0, 1.0], [2.0, 3.0]], (2, 2)),
])
def test_points_accepts_one_point_many_or_none(value: object, shape: tuple[int, int]) -> None:
    """points() turns a single point, a list of points or an empty list into a (k, 2) array."""
    out = checks.points("targets", value)  # type: ignore[arg-type]
    assert out.shape == shape and not out.flags.writeable
    np.testing.assert_array_equal(out.ravel(), np.ravel(value))


def test_points_refuses_other_shapes() -> None:
    """Three coordinates or text are not planar points."""
    with pytest.raises(InvalidInputError, match="targets"):
        checks.points("targets", [1.0, 2.0, 3.0])
    with pytest.raises(InvalidInputError, match="array of numbers"):
        checks.points("targets", [["x", "y"]])


def test_index_and_node_arrays() -> None:
    """index_array and node_set accept integer indices in [0, size); node_set maps an empty input
    to an empty int array; floats and out-of-range indices name the field."""
    idx = checks.index_array("order", [2, 0, 1], 3)
    assert idx.dtype == np.int64 and idx.tolist() == [2, 0, 1] and not idx.flags.writeable
    assert checks.index_array("order", [], 3).size == 0
    with pytest.raises(InvalidInputError, match=r"order=.*\[0, 3\)"):
        checks.index_array("order", [3], 3)
    with pytest.raises(InvalidInputError, match="integer indices"):
        checks.index_array("order", [0.0, 1.0], 3)
    assert checks.node_set("nodes", [], 4).dtype == np.int64
    assert checks.node_set("nodes", np.array([3, 1], dtype=np.uint8), 4).tolist() == [3, 1]
    with pytest.raises(InvalidInputError, match=r"nodes=.*\[0, 4\)"):
        checks.node_set("nodes", [-1], 4)
    with pytest.raises(InvalidInputError, match="integer node indices"):
        checks.node_set("nodes", [[0, 1]], 4)


def test_node_vector_and_generator() -> None:
    """node_vector gives a finite read-only (n,) copy of the right length; generator() accepts
    only a numpy Generator."""
    src = np.array([1.0, 2.0])
    vec = checks.node_vector("prior", src, 2)
    src[0] = 9.0
    assert vec.tolist() == [1.0, 2.0] and not vec.flags.writeable
    for bad in ([], [1.0, 2.0, 3.0], [1.0, math.inf]):
        with pytest.raises(InvalidInputError, match="prior"):
            checks.node_vector("prior", bad, 2)
    rng = np.random.default_rng(0)
    assert checks.generator("rng", rng) is rng
    with pytest.raises(InvalidInputError, match=r"rng=0: .*default_rng"):
        checks.generator("rng", 0)


def test_finite_or_none() -> None:
    assert checks.finite_or_none(2.5) == 2.5 and checks.finite_or_none(0.0) == 0.0
    assert all(checks.finite_or_none(v) is None for v in (math.nan, math.inf, -math.inf))
