"""How many threads numba's parallel kernels use for one call, by the size of the call's work.

A kernel compiled with ``parallel=True`` starts a parallel region for every ``prange`` loop and
every array allocation it parallelises. On a large array the threads pay for themselves; on a
small one the start-up of each region costs more than the work, and on a busy machine (another
process on every core, as in a campaign or a test run) a region waits for a thread the operating
system has not scheduled yet, so a kernel that computes for microseconds takes milliseconds.
:func:`threads_for` runs the kernels of a ``with`` block on one thread when the work is small,
and as numba is set up otherwise. The results are the same: the library's parallel kernels give
equal answers on any number of threads.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import numba

PARALLEL_WORK = 1 << 17
"""Elements a call must touch before its kernels run on more than one thread."""


@contextmanager
def threads_for(work: int, least: int = PARALLEL_WORK) -> Iterator[None]:
    """Within the block, numba's parallel kernels run on one thread if ``work < least``
    (elements the block's kernels touch), else on the threads numba is set to use. The setting
    is the calling thread's own and is restored on leaving."""
    if work >= least:
        yield
        return
    before = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(before)
