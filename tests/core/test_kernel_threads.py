"""Numba's threads per call: one for small work, numba's own setting for large, restored."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from searchtrack.core.kernel_threads import PARALLEL_WORK, threads_for
from searchtrack.estimate import signature_kernels


def test_small_work_runs_on_one_thread_and_the_setting_comes_back() -> None:
    before = numba.get_num_threads()
    with threads_for(PARALLEL_WORK - 1):
        assert numba.get_num_threads() == 1
    assert numba.get_num_threads() == before
    with threads_for(PARALLEL_WORK):
        assert numba.get_num_threads() == before
    with pytest.raises(RuntimeError), threads_for(0):
        raise RuntimeError("inside")
    assert numba.get_num_threads() == before


def test_a_parallel_kernel_gives_the_same_answer_on_one_thread() -> None:
    """The row totals of a parallel kernel are equal bit for bit on one thread and on all."""
    a = np.random.default_rng(3).random((7, 5000))
    program = signature_kernels.pairwise_program(a.shape[1])
    every = signature_kernels.row_sums(a, *program)
    with threads_for(0):
        one = signature_kernels.row_sums(a, *program)
    np.testing.assert_array_equal(one, every)
    np.testing.assert_array_equal(every, a.sum(axis=1))
