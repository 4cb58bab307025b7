"""The compiled prediction and resampling passes give the NumPy equations' particles."""

from __future__ import annotations

import numpy as np

from searchtrack.estimate.phd import kernels, systematic_indices
from searchtrack.models.motion import ConstantVelocity


def test_systematic_gather_picks_the_systematic_ancestors() -> None:
    """Across chunk boundaries and with zero weights the merge finds searchsorted's indices."""
    rng = np.random.default_rng(1)
    w = rng.random(3 * kernels.CHUNK + 17)
    w[rng.random(w.shape[0]) < 0.3] = 0.0
    x = rng.standard_normal((w.shape[0], 4))
    labels = np.arange(w.shape[0], dtype=np.int64)
    n = 2 * kernels.CHUNK + 5
    u = float(np.random.default_rng(2).random())
    idx = systematic_indices(w, n, np.random.default_rng(2))
    cum = kernels.cumulative(w)
    np.testing.assert_array_equal(cum, np.cumsum(w))
    out_x, out_l, out_t = kernels.systematic_gather(cum, u, n, x, labels, -labels)
    np.testing.assert_array_equal(out_l, idx)
    np.testing.assert_array_equal(out_t, -idx)
    np.testing.assert_array_equal(out_x, x[idx])


def test_move_compact_is_propagate_then_region() -> None:
    """The move, the survival weight and the region cut equal ConstantVelocity.propagate and
    a mask, in order."""
    rng = np.random.default_rng(3)
    n = kernels.CHUNK + 100
    x = np.column_stack([1000.0 * rng.random((n, 2)), 20.0 * rng.standard_normal((n, 2))])
    w = rng.random(n)
    tags = rng.integers(-1, 5, n)
    motion = ConstantVelocity(0.5)
    ref = motion.propagate(x, 1.0, np.random.default_rng(4))
    e = np.random.default_rng(4).standard_normal((n, 4))
    lo, hi = np.array([0.0, 0.0]), np.array([1000.0, 1000.0])
    inside = np.all((ref[:, :2] >= lo) & (ref[:, :2] <= hi), axis=1)
    out_x, out_w = np.empty((n, 4)), np.empty(n)
    out_l, out_t = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    a, b, c = np.sqrt(0.5 / 3.0), np.sqrt(1.5) / 2.0, np.sqrt(0.125)
    kept = kernels.move_compact(x, e, 0, True, True, 1.0, a, b, c, 2, w, np.array([0.9]), tags,
                                1, lo, hi, out_x, out_w, out_l, out_t, 0)
    assert kept == inside.sum() < n
    np.testing.assert_array_equal(out_x[:kept], ref[inside])
    np.testing.assert_array_equal(out_w[:kept], w[inside] * 0.9)
    np.testing.assert_array_equal(out_t[:kept], tags[inside])
    assert np.all(out_l[:kept] == 1)
    assert kernels.n_chunks(0) == 1 and kernels.n_chunks(kernels.CHUNK + 1) == 2
