"""Systematic resampling of batches of filters, N_eff and the resampling policy (Eq. 5–6)."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.road_resampling import (
    KLDSampling,
    ResamplePolicy,
    SpeedRoughening,
    effective_sample_size,
    reflect,
    systematic_indices,
)


def _reference(w: np.ndarray, u: float) -> list[int]:
    """The low-variance sampler of Probabilistic Robotics, one row, written as a loop."""
    n = w.size
    w = w / w.sum()
    out, i, c = [], 0, w[0]
    for j in range(n):
        target = (u + j) / n
        while c <= target and i < n - 1:
            i += 1
            c += w[i]
        out.append(i)
    return out


def test_by_hand() -> None:
    """Weights (0.5, 0.5, 0, 0) with offset 0.1: two copies of each of the first two."""
    idx = systematic_indices(np.array([[0.5, 0.5, 0.0, 0.0]]), np.array([0.1]))
    np.testing.assert_array_equal(idx, [[0, 0, 1, 1]])
    idx = systematic_indices(np.array([[0.0, 0.0, 1.0, 0.0]]), np.array([0.0]))
    np.testing.assert_array_equal(idx, [[2, 2, 2, 2]])


def test_equal_weights_are_the_identity() -> None:
    """With equal weights every particle is kept exactly once, whatever the offset."""
    idx = systematic_indices(np.ones((3, 7)), np.array([0.0, 0.5, 0.999]))
    np.testing.assert_array_equal(idx, np.tile(np.arange(7), (3, 1)))


def test_batch_matches_the_loop_and_keeps_counts_within_one() -> None:
    """Each row equals the one-row loop, and particle n is copied ⌊N w_n⌋ or ⌈N w_n⌉ times."""
    rng = np.random.default_rng(0)
    w = rng.random((20, 50)) ** 4
    u = rng.random(20)
    idx = systematic_indices(w, u)
    for b in range(20):
        assert idx[b].tolist() == _reference(w[b], u[b])
        counts = np.bincount(idx[b], minlength=50)
        expected = 50 * w[b] / w[b].sum()
        assert np.all(counts >= np.floor(expected) - 1e-9)
        assert np.all(counts <= np.ceil(expected) + 1e-9)
        assert np.all(np.diff(idx[b]) >= 0)


def test_effective_sample_size() -> None:
    """Eq. 5: N for equal weights, 1 for a single particle, per row."""
    w = np.array([[0.25] * 4, [1.0, 0.0, 0.0, 0.0], [0.5, 0.5, 0.0, 0.0]])
    np.testing.assert_allclose(effective_sample_size(w), [4.0, 1.0, 2.0])


def test_policy() -> None:
    """Default: always due; with a threshold q, due only when N_eff < q·N."""
    w = np.array([[0.25] * 4, [0.7, 0.1, 0.1, 0.1]])
    np.testing.assert_array_equal(ResamplePolicy().due(w), [True, True])
    np.testing.assert_array_equal(ResamplePolicy(2 / 3).due(w), [False, True])
    with pytest.raises(InvalidInputError, match="threshold"):
        ResamplePolicy(0.0)
    with pytest.raises(InvalidInputError, match="threshold"):
        ResamplePolicy(1.5)


def test_bad_input_names_the_field() -> None:
    """Weights must be non-negative with positive row sums; offsets in [0, 1), one per row."""
    with pytest.raises(InvalidInputError, match=r"^w="):
        systematic_indices(np.zeros((1, 3)), np.array([0.5]))
    with pytest.raises(InvalidInputError, match=r"^w="):
        systematic_indices(np.array([[1.0, -1.0, 1.0]]), np.array([0.5]))
    with pytest.raises(InvalidInputError, match=r"^w="):
        systematic_indices(np.array([[np.nan, 1.0]]), np.array([0.5]))
    with pytest.raises(InvalidInputError, match=r"^u="):
        systematic_indices(np.ones((1, 3)), np.array([1.0]))
    with pytest.raises(InvalidInputError, match=r"^u="):
        systematic_indices(np.ones((2, 3)), np.array([0.5]))


def test_reflection_folds_into_the_range() -> None:
    """Inside the range nothing moves; beyond an end a point comes back as far inside; many
    widths out it still lands inside; a range of one point maps everything there."""
    x = np.array([5.0, 6.5, 10.0, 4.0, 11.5, 5.0 - 12.0, 10.0 + 7.25])
    np.testing.assert_allclose(reflect(x, 5.0, 10.0), [5.0, 6.5, 10.0, 6.0, 8.5, 7.0, 7.25])
    rng = np.random.default_rng(0)
    far = reflect(rng.normal(0.0, 100.0, 1000), -1.0, 2.0)
    assert far.min() >= -1.0 and far.max() <= 2.0
    np.testing.assert_array_equal(reflect(x, 3.0, 3.0), np.full(x.size, 3.0))


def test_bandwidths_are_silvermans_rule_on_the_driving_speeds() -> None:
    """Per row: c · 1.06 · (sample standard deviation of the driving speeds) · n^(-1/5);
    stopped particles (speed 0) do not count; fewer than two driving particles give 0."""
    rng = np.random.default_rng(1)
    v = rng.uniform(5.0, 20.0, (4, 40))
    v[0, :25] = 0.0
    v[2, 1:] = 0.0
    v[3] = 0.0
    h = SpeedRoughening(scale=0.5).bandwidths(v)
    for r in range(2):
        d = v[r][v[r] > 0.0]
        assert h[r] == pytest.approx(0.5 * 1.06 * d.std(ddof=1) * d.size ** -0.2, rel=1e-12)
    assert h[2] == 0.0 and h[3] == 0.0


def test_bandwidths_read_each_rows_count() -> None:
    """With counts, only each row's first ``count`` speeds enter its bandwidth."""
    rng = np.random.default_rng(4)
    v = rng.uniform(5.0, 20.0, (2, 40))
    h = SpeedRoughening().bandwidths(v, np.array([40, 12]))
    assert h[0] == SpeedRoughening().bandwidths(v[[0]])[0]
    assert h[1] == pytest.approx(SpeedRoughening().bandwidths(v[[1], :12])[0], rel=1e-12)


def test_policy_compares_n_eff_with_each_rows_count() -> None:
    """A selective policy compares N_eff with q times the particles a row holds."""
    w = np.zeros((2, 10))
    w[:, :4] = 0.25                      # N_eff = 4 in both rows
    due = ResamplePolicy(0.5).due(w, np.array([10, 4]))
    np.testing.assert_array_equal(due, [True, False])


def test_kld_bound_is_the_chi_square_quantile() -> None:
    """n(k) is χ²_{k−1, 1−δ} / (2ε) (Fox 2003) to within the Wilson-Hilferty error."""
    from scipy.stats import chi2

    for eps, q in ((0.05, 0.99), (0.02, 0.95), (0.1, 0.9)):
        counts = KLDSampling(epsilon=eps, quantile=q)
        for k in (3, 10, 50, 400):
            exact = chi2.ppf(q, k - 1) / (2.0 * eps)
            assert counts.bound(k) == pytest.approx(exact, rel=0.02)
    assert KLDSampling().bound(1) == 0.0


def test_kld_table_is_clipped_and_grows_with_the_bins() -> None:
    counts = KLDSampling(epsilon=0.05, min_particles=30)
    table = counts.table(500)
    assert table.shape == (501,)
    assert table[0] == table[1] == 30    # one bin: the floor
    assert np.all(np.diff(table) >= 0) and table[-1] == 500
    for k in (2, 20):
        assert table[k] == int(np.ceil(counts.bound(k)))
    np.testing.assert_array_equal(KLDSampling(min_particles=80).table(40), 40)


def test_kld_speed_bins() -> None:
    """Speeds 0…v_max in bins of the given width (0 is the stopped bin); none without one."""
    assert KLDSampling().speed_bins(15.0) == 1
    assert KLDSampling(speed_bin_mps=2.0).speed_bins(None) == 1
    assert KLDSampling(speed_bin_mps=2.0).speed_bins(15.0) == 8
    assert KLDSampling(speed_bin_mps=2.0).speed_bins(16.0) == 9


@pytest.mark.parametrize(("field", "value"), [
    ("epsilon", 0.0), ("epsilon", 1.0), ("quantile", 0.5), ("quantile", 1.0),
    ("bin_m", 0.0), ("min_particles", 1), ("min_particles", 2.5), ("speed_bin_mps", 0.0)])
def test_bad_kld_sampling_is_named(field: str, value: float) -> None:
    with pytest.raises(InvalidInputError, match=field):
        KLDSampling(**{field: value})  # type: ignore[arg-type]


def test_roughening_moves_driving_speeds_by_the_bandwidth() -> None:
    """Listed rows only; stopped particles keep 0; driving ones stay in the range and, away
    from its ends, move by a normal of standard deviation h (mean 0)."""
    rng = np.random.default_rng(2)
    n = 20000
    v = np.vstack([rng.uniform(10.0, 11.0, n), rng.uniform(5.0, 20.0, n)])
    v[0, ::4] = 0.0
    before = v.copy()
    rough = SpeedRoughening()
    h = rough.bandwidths(v[[0]])[0]
    rough.roughen(v, np.array([0]), 5.0, 20.0, rng)
    np.testing.assert_array_equal(v[1], before[1])
    np.testing.assert_array_equal(v[0, ::4], 0.0)
    step = (v[0] - before[0])[before[0] > 0.0]
    assert v[0].max() <= 20.0 and v[0][before[0] > 0.0].min() >= 5.0
    assert abs(step.mean()) < 4.0 * h / np.sqrt(step.size)
    assert step.std() == pytest.approx(h, rel=0.03)


def test_roughening_keeps_the_uniform_speed_law() -> None:
    """Speeds uniform on the drive range stay uniform after roughening (the reflection keeps
    the law; clipping would pile mass on the ends)."""
    rng = np.random.default_rng(3)
    v = rng.uniform(5.0, 20.0, (1, 50000))
    rough = SpeedRoughening(scale=40.0)   # a bandwidth wider than the range
    for _ in range(3):
        rough.roughen(v, np.array([0]), 5.0, 20.0, rng)
    counts = np.histogram(v[0], bins=15, range=(5.0, 20.0))[0]
    expected = v.size / 15
    assert np.all(np.abs(counts - expected) < 5.0 * np.sqrt(expected))


def test_bad_roughening_is_named() -> None:
    for bad in (0.0, -1.0, float("nan"), "1"):
        with pytest.raises(InvalidInputError, match="scale"):
            SpeedRoughening(scale=bad)  # type: ignore[arg-type]
