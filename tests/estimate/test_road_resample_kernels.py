"""The resampling kernels of the road filters against NumPy references: fixed counts, the
KLD-sampling count, and the joins with draws."""

from __future__ import annotations

import numpy as np

from searchtrack.estimate import road_resample_kernels as rkern
from searchtrack.estimate.road_entropy import RoadBins
from searchtrack.estimate.road_resampling import KLDSampling, systematic_indices
from searchtrack.models.road_particles import DirectedRoads

from .conftest import weighted_clouds

_NO_KLD = (np.zeros(0, dtype=np.int64), 1.0, 1.0, np.zeros(0, dtype=np.bool_),
           np.zeros(0, dtype=np.int64))


def _pick(w: np.ndarray, u: float, n: int) -> np.ndarray:
    """Reference: ``n`` systematic picks from the weights ``w`` with offset ``u``."""
    cum = np.cumsum(w) / w.sum()
    return np.minimum(np.searchsorted(cum, (u + np.arange(n)) / n, side="right"), w.size - 1)


def _kld(grid3: DirectedRoads, counts: KLDSampling, cap: int, n_speed: int = 1
         ) -> tuple[np.ndarray, float, float, np.ndarray, np.ndarray]:
    bins = RoadBins(grid3, counts.bin_m)
    return (bins.first_bin, counts.bin_m, counts.speed_bin_mps or 1.0,
            np.zeros(bins.n_bins * n_speed, dtype=np.bool_), counts.table(cap))


def test_resample_rows_matches_systematic_indices(grid3: DirectedRoads) -> None:
    """In-place resampling of some rows copies the particles (positions and speeds) the NumPy
    reference picks; the count stays the cap."""
    edge, s, w = weighted_clouds(grid3, 2)
    w = w ** 3
    v = np.random.default_rng(3).random(edge.shape) * 20.0
    rows, u = np.array([0, 3, 4]), np.array([0.2, 0.7, 0.0])
    e2, s2, v2, w2 = edge.copy(), s.copy(), v.copy(), w.copy()
    count = np.full(6, 400, dtype=np.int64)
    rkern.resample_rows(e2, s2, v2, w2, count, rows, u, *_NO_KLD)
    idx = systematic_indices(w[rows], u)
    for i, r in enumerate(rows):
        np.testing.assert_array_equal(e2[r], edge[r][idx[i]])
        np.testing.assert_array_equal(s2[r], s[r][idx[i]])
        np.testing.assert_array_equal(v2[r], v[r][idx[i]])
        np.testing.assert_allclose(w2[r], 1 / 400)
    for r in (1, 2, 5):
        np.testing.assert_array_equal(e2[r], edge[r])
        np.testing.assert_array_equal(w2[r], w[r])
    np.testing.assert_array_equal(count, 400)


def test_resample_rows_reads_only_each_rows_count(grid3: DirectedRoads) -> None:
    """A row of 150 particles (weight 0 beyond) resamples from those 150 alone, whatever the
    columns beyond hold; without KLD-sampling it is filled back to the cap."""
    edge, s, w = weighted_clouds(grid3, 5)
    count = np.full(6, 400, dtype=np.int64)
    count[2] = 150
    w[2, 150:] = 0.0
    w[2] /= w[2].sum()
    edge[2, 150:], s[2, 150:] = 0, 1.0   # the stale columns: all on one point
    v = np.zeros(edge.shape)
    e2, s2 = edge.copy(), s.copy()
    rkern.resample_rows(e2, s2, v, w.copy(), count, np.array([2]), np.array([0.4]), *_NO_KLD)
    idx = _pick(w[2, :150], 0.4, 400)
    np.testing.assert_array_equal(e2[2], edge[2, idx])
    np.testing.assert_array_equal(s2[2], s[2, idx])
    assert count[2] == 400


def test_kld_count_follows_the_bins_the_cap_sample_fills(grid3: DirectedRoads) -> None:
    """With KLD-sampling a row keeps ``table[k]`` particles, ``k`` the 10 m bins its cap-sized
    systematic sample fills, drawn systematically from the same weights and offset (weights
    ``1/n``, 0 beyond); a tight cloud keeps few, a cloud over the whole map the cap."""
    counts = KLDSampling(bin_m=10.0, min_particles=20)
    rng = np.random.default_rng(6)
    edge, s = grid3.uniform((2, 400), rng)
    edge[0] = 3                            # row 0: 25 m of one edge
    s[0] = 40.0 + 25.0 * rng.random(400)
    w = rng.random((2, 400))
    w /= w.sum(axis=1, keepdims=True)
    kld = _kld(grid3, counts, 400)
    bins = RoadBins(grid3, 10.0)
    e2, s2, v2, w2 = edge.copy(), s.copy(), np.zeros((2, 400)), w.copy()
    count = np.full(2, 400, dtype=np.int64)
    u = np.array([0.3, 0.8])
    rkern.resample_rows(e2, s2, v2, w2, count, np.array([0, 1]), u, *kld)
    for r in range(2):
        k = np.unique(bins.index(edge[r], s[r])[_pick(w[r], u[r], 400)]).size
        n = int(counts.table(400)[k])
        assert count[r] == n
        idx = _pick(w[r], u[r], n)
        np.testing.assert_array_equal(e2[r, :n], edge[r, idx])
        np.testing.assert_array_equal(s2[r, :n], s[r, idx])
        np.testing.assert_allclose(w2[r, :n], 1.0 / n)
        np.testing.assert_array_equal(w2[r, n:], 0.0)
    assert count[0] < 150 and count[1] == 400
    assert not kld[3].any()   # the scratch marks are cleared


def test_kld_resampling_keeps_each_particle_in_proportion_to_its_weight(
        grid3: DirectedRoads) -> None:
    """Over many offsets, the share of the output copying each input particle is its weight
    (the count varies with the offset; the output stays a sample of the weights)."""
    rng = np.random.default_rng(7)
    cap = 200
    edge = np.where(rng.random((1, cap)) < 0.5, 3, 7).astype(np.int64)
    s = 60.0 * rng.random((1, cap))          # six 20 m bins: about 40 particles kept
    w = rng.random(cap) ** 2
    w /= w.sum()
    counts = KLDSampling(epsilon=0.2, bin_m=20.0, min_particles=10)
    kld = _kld(grid3, counts, cap)
    share = np.zeros(cap)
    kept = []
    repeats = 3000
    for u in rng.random(repeats):
        e2, s2, w2 = edge.copy(), s.copy(), w[None].copy()
        v2 = np.arange(float(cap))[None].copy()
        count = np.array([cap], dtype=np.int64)
        rkern.resample_rows(e2, s2, v2, w2, count, np.array([0]), np.array([u]), *kld)
        share += np.bincount(v2[0, :count[0]].astype(np.int64), minlength=cap) / count[0]
        kept.append(int(count[0]))
    assert 20 < np.mean(kept) < 60
    # one particle's share has a standard error of about 2e-4 here
    np.testing.assert_allclose(share / repeats, w, rtol=0.0, atol=1e-3)
    assert np.abs(share / repeats - w).sum() < 0.06


def test_join_rows_is_systematic_resampling_of_the_union() -> None:
    """Each listed row becomes the low-variance resample of its particles (weighed by the
    row's mass) joined with its draws: the same copies as systematic_indices on the union;
    an unlisted row and a row whose union weighs nothing stay as they were."""
    rng = np.random.default_rng(4)
    n, k = 9, 4
    edge = rng.integers(0, 5, (3, n)).astype(np.int64)
    s = rng.random((3, n))
    w = rng.random((3, n))
    w /= w.sum(axis=1, keepdims=True)
    add_e = rng.integers(5, 9, (2, k)).astype(np.int64)
    add_s = rng.random((2, k)) + 10.0
    add_w = rng.random((2, k)) * 0.2
    v, add_v = rng.random((3, n)), rng.random((2, k)) + 5.0
    rows, mass = np.array([0, 2]), np.array([0.7, 0.0])
    u = np.array([0.3, 0.6])
    union_e = np.concatenate([edge[rows], add_e], axis=1)
    union_s = np.concatenate([s[rows], add_s], axis=1)
    union_v = np.concatenate([v[rows], add_v], axis=1)
    union_w = np.concatenate([w[rows] * mass[:, None], add_w], axis=1)
    before = (edge.copy(), s.copy(), w.copy())
    count = np.full(3, n, dtype=np.int64)
    rkern.join_rows(edge, s, v, w, count, rows, mass, add_e, add_s, add_v, add_w, u, *_NO_KLD)
    for i, r in enumerate(rows):
        cum = np.cumsum(union_w[i]) / union_w[i].sum()
        idx = np.minimum(np.searchsorted(cum, (u[i] + np.arange(n)) / n, side="right"), n + k - 1)
        np.testing.assert_array_equal(edge[r], union_e[i, idx])
        np.testing.assert_array_equal(s[r], union_s[i, idx])
        np.testing.assert_array_equal(v[r], union_v[i, idx])
        np.testing.assert_allclose(w[r], 1.0 / n)
    assert np.all(s[2] >= 10.0)          # mass 0: only the draws survive
    np.testing.assert_array_equal(edge[1], before[0][1])
    np.testing.assert_array_equal(w[1], before[2][1])
    empty = np.zeros((1, k))
    rkern.join_rows(edge, s, v, w, count, np.array([1]), np.array([0.0]), add_e[:1], add_s[:1],
                    add_v[:1], empty, np.array([0.5]), *_NO_KLD)
    np.testing.assert_array_equal(s[1], before[1][1])


def test_join_rows_with_kld_reads_the_rows_count_and_the_draws(grid3: DirectedRoads) -> None:
    """A row of 30 live particles joined with 10 draws: the union is those 40 (the stale
    columns beyond 30 never chosen), and the row keeps the KLD count of the union's bins."""
    rng = np.random.default_rng(8)
    cap, k = 100, 10
    edge, s = grid3.uniform((1, cap), rng)
    w = np.zeros((1, cap))
    w[0, :30] = rng.random(30)
    w /= w.sum()
    v = np.zeros((1, cap))
    v[0, :30] = 1.0
    add_e, add_s = grid3.uniform((1, k), rng)
    add_v, add_w = np.full((1, k), 2.0), rng.random((1, k)) * 0.1
    count = np.array([30], dtype=np.int64)
    counts = KLDSampling(bin_m=10.0, min_particles=5)
    union_e = np.concatenate([edge[0, :30], add_e[0]])
    union_s = np.concatenate([s[0, :30], add_s[0]])
    union_w = np.concatenate([w[0, :30] * 0.5, add_w[0]])
    rkern.join_rows(edge, s, v, w, count, np.array([0]), np.array([0.5]), add_e, add_s, add_v,
                    add_w, np.array([0.25]), *_kld(grid3, counts, cap))
    bins = RoadBins(grid3, 10.0)
    kk = np.unique(bins.index(union_e, union_s)[_pick(union_w, 0.25, cap)]).size
    n = int(counts.table(cap)[kk])
    assert count[0] == n
    idx = _pick(union_w, 0.25, n)
    np.testing.assert_array_equal(edge[0, :n], union_e[idx])
    np.testing.assert_array_equal(v[0, :n] == 2.0, idx >= 30)
    np.testing.assert_allclose(w[0, :n], 1.0 / n)
    np.testing.assert_array_equal(w[0, n:], 0.0)


def test_kld_speed_bins_count_a_cloud_spread_in_speed(grid3: DirectedRoads) -> None:
    """Particles in one road bin with speeds over 0–10 m/s fill one bin by position and six of
    2 m/s with speed bins, and keep the counts of those bins."""
    rng = np.random.default_rng(9)
    cap = 300
    edge = np.full((1, cap), 3, dtype=np.int64)
    s = 41.0 + 8.0 * rng.random((1, cap))
    v = np.round(10.0 * rng.random((1, cap)), 1)
    w = np.full((1, cap), 1.0 / cap)
    kept = []
    for speed_bin, n_speed in ((None, 1), (2.0, 6)):
        counts = KLDSampling(bin_m=10.0, min_particles=20, speed_bin_mps=speed_bin)
        assert counts.speed_bins(10.0) == n_speed
        count = np.array([cap], dtype=np.int64)
        rkern.resample_rows(edge.copy(), s.copy(), v.copy(), w.copy(), count, np.array([0]),
                            np.array([0.5]), *_kld(grid3, counts, cap, n_speed))
        kept.append(int(count[0]))
    table = KLDSampling(bin_m=10.0, min_particles=20).table(cap)
    assert kept == [table[1], table[6]]
