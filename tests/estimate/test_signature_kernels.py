"""The signature kernels: NumPy's pairwise row sums bit for bit, faults found in either memory
order, and truncation supports that do not depend on the order or on the candidate buffer."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate import signature_kernels as kernels


@pytest.mark.parametrize("n", [1, 7, 8, 9, 127, 128, 129, 256, 1000, 4099])
def test_row_sums_are_numpys_pairwise_sums(n: int) -> None:
    """Both orders give each row's ``row.sum()`` exactly, at lengths around the block sizes."""
    rng = np.random.default_rng(n)
    a = rng.random((5, n)) * 10.0 ** rng.integers(-8, 8, size=(5, n))
    program = kernels.pairwise_program(n)
    want = np.array([row.sum() for row in a])
    np.testing.assert_array_equal(kernels.row_sums(a, *program), want)
    np.testing.assert_array_equal(
        kernels.row_sums_by_column(np.asfortranarray(a), *program), want)


@pytest.mark.parametrize("by_column", [False, True])
def test_faults_find_every_bad_entry_and_the_first_empty_row(by_column: bool) -> None:
    """A NaN, an infinity or a negative entry anywhere is found; the first row with no mass is
    named."""
    rng = np.random.default_rng(1)
    base = rng.random((6, 300))

    def run(a: np.ndarray) -> tuple[bool, int]:
        arr = np.asfortranarray(a) if by_column else np.ascontiguousarray(a)
        return kernels.faults(arr, by_column)

    assert run(base) == (False, -1)
    for bad in (np.nan, np.inf, -1e-300):
        for r, c in ((0, 0), (5, 299), (3, 150)):
            a = base.copy()
            a[r, c] = bad
            assert run(a)[0], (bad, r, c)
    a = base.copy()
    a[[2, 4]] = 0.0
    assert run(a) == (False, 2)


@pytest.mark.parametrize("width", [50, kernels.ROW_CAP + 500])
def test_truncation_supports_do_not_depend_on_order_or_buffer(width: int) -> None:
    """Rows with fewer and with more candidates than the buffer give the same supports in both
    orders, and each is the smallest heaviest set holding the mass."""
    rng = np.random.default_rng(width)
    a = rng.random((4, width + 100))
    a[:, :width] += 1.0  # the first ``width`` columns are all candidates
    a[1] = 0.0
    a[1, 7] = 1.0
    mass = 0.999
    program = kernels.pairwise_program(a.shape[1])
    total = kernels.row_sums(a, *program)
    nodes_c, off_c = kernels.heaviest(a, total, mass, False)
    nodes_f, off_f = kernels.heaviest(np.asfortranarray(a), total, mass, True)
    np.testing.assert_array_equal(nodes_c, nodes_f)
    np.testing.assert_array_equal(off_c, off_f)
    for r in range(a.shape[0]):
        kept = nodes_c[off_c[r]:off_c[r + 1]]
        order = np.argsort(-a[r], kind="stable")
        need = int(np.searchsorted(np.cumsum(a[r, order]), mass * total[r])) + 1
        np.testing.assert_array_equal(kept, np.sort(order[:need]))
