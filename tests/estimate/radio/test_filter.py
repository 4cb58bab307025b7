"""The shared labelled particle LMB filter: its recursion with a given likelihood, its read-outs,
belief seams, configuration and bad inputs (and that both radio filters are built on it)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import LabelledParticleBelief
from searchtrack.estimate.particle_belief import ParticleBelief
from searchtrack.estimate.radio.dtt import DttLmbFilter
from searchtrack.estimate.radio.filter import FilterConfig, LabelledFilter, roughen
from searchtrack.estimate.radio.particles import LabelledParticles
from searchtrack.estimate.radio.tbd import TbdLmbFilter
from searchtrack.models.radio.scenario import RadioScenario

SCENARIO = RadioScenario.paper()
SIGNAL = SCENARIO.signal
SMALL = FilterConfig(particles_per_label=200, birth_fraction=0.2)
Z = np.ones((SIGNAL.frames, SIGNAL.fft_size))
POSE = np.array([0.0, 0.0, 0.0])


def _constant(values: list[float]):  # type: ignore[no-untyped-def]
    """A likelihood giving every particle of label ``λ`` the log ratio ``values[λ]``."""
    def likelihood(z: np.ndarray, pose: np.ndarray, pred: LabelledParticles) -> np.ndarray:
        return np.broadcast_to(np.asarray(values)[:, None], pred.w.shape).copy()
    return likelihood


def _near(xy: tuple[float, float], spread_m: float = 30.0):  # type: ignore[no-untyped-def]
    """A likelihood favouring particles of every label near ``xy``."""
    def likelihood(z: np.ndarray, pose: np.ndarray, pred: LabelledParticles) -> np.ndarray:
        d2 = ((pred.x[:, :, ::2] - np.asarray(xy)) ** 2).sum(axis=2)
        return 5.0 - d2 / (2.0 * spread_m**2)
    return likelihood


def _filter(config: FilterConfig = SMALL, seed: int = 0,
            values: list[float] | None = None) -> LabelledFilter:
    return LabelledFilter(SCENARIO, config, likelihood=_constant(values or [0.0] * 4), seed=seed)


def test_existence_follows_the_lmb_update() -> None:
    """With constant log ratios c_λ one step gives r = r⁺e^c / (r⁺e^c + 1 − r⁺) (eqs. 27, 30),
    r⁺ = p_S r_B + r_B (1 − r_B)."""
    c = [20.0, 0.0, -3.0, 1.0]
    f = _filter(values=c)
    f.step(Z, POSE)
    r_b, p_s = SCENARIO.birth_probability, SCENARIO.survival_probability
    r_pred = p_s * r_b + r_b * (1.0 - r_b)
    want = [r_pred * math.exp(v) / (r_pred * math.exp(v) + 1.0 - r_pred) for v in c]
    np.testing.assert_allclose(f.state.r, want, rtol=1e-10)
    assert f.steps == 1
    np.testing.assert_allclose(f.state.w, 1.0 / SMALL.particles_per_label)
    assert [lab for lab, _ in f.estimates()] == [0]


def test_likelihood_sees_checked_inputs_and_the_prediction() -> None:
    """The likelihood gets z and the pose as float arrays and N + n_birth particles per label."""
    seen: list[tuple[np.ndarray, np.ndarray, LabelledParticles]] = []

    def record(z: np.ndarray, pose: np.ndarray, pred: LabelledParticles) -> np.ndarray:
        seen.append((z, pose, pred))
        return np.zeros(pred.w.shape)

    f = LabelledFilter(SCENARIO, SMALL, likelihood=record, seed=0)
    f.step(Z.astype(np.float32).tolist(), (1, 2, 3))  # type: ignore[arg-type]
    (z, pose, pred), = seen
    assert z.dtype == np.float64 and z.shape == Z.shape
    np.testing.assert_array_equal(pose, [1.0, 2.0, 3.0])
    assert pred.w.shape == (SIGNAL.n_labels, SMALL.particles_per_label + SMALL.n_birth)
    assert f.state.w.shape == (SIGNAL.n_labels, SMALL.particles_per_label)


def test_localises_where_the_likelihood_peaks() -> None:
    """A likelihood peaked at a birth site confirms every label there within a few steps."""
    site = SCENARIO.birth_means[1]
    f = LabelledFilter(SCENARIO, FilterConfig(particles_per_label=2000),
                       likelihood=_near((site[0], site[2])), seed=1)
    for _ in range(4):
        f.step(Z, POSE)
    est = f.estimates()
    assert [lab for lab, _ in est] == [0, 1, 2, 3]
    for _, xy in est:
        assert np.hypot(xy[0] - site[0], xy[1] - site[2]) < 15.0
    assert np.argmax(f.cardinality()) == 4
    assert f.cardinality_variance() == pytest.approx((f.state.r * (1 - f.state.r)).sum())


def test_same_seed_same_state() -> None:
    """Equal seeds and measurements give identical states; another seed does not."""
    runs = [LabelledFilter(SCENARIO, SMALL, likelihood=_near((800.0, 300.0)), seed=s)
            for s in (3, 3, 4)]
    for f in runs:
        for _ in range(3):
            f.step(Z, POSE)
    a, b, c = runs
    for name in ("x", "mode", "tau", "w", "r"):
        np.testing.assert_array_equal(getattr(a.state, name), getattr(b.state, name))
    assert not np.array_equal(a.state.x, c.state.x)


def test_initial_state_and_belief_seams() -> None:
    """Before any step r = r_B; the filter is a LabelledParticleBelief and a ParticleBelief
    (positions (Λ·N, 2), weights r_λ w_i summing to Σ r)."""
    f = _filter(FilterConfig(particles_per_label=50))
    n_labels = SIGNAL.n_labels
    np.testing.assert_allclose(f.state.r, SCENARIO.birth_probability)
    assert isinstance(f, LabelledParticleBelief)
    assert isinstance(f, ParticleBelief)
    assert f.positions.shape == (n_labels * 50, 2)
    assert f.weights.shape == (n_labels * 50,)
    assert f.weights.sum() == pytest.approx(f.expected_count())
    assert f.expected_count() == pytest.approx(f.cardinality_mean())
    np.testing.assert_array_equal(f.positions[50], f.state.x[1, 0, [0, 2]])
    assert f.weights[50] == pytest.approx(f.state.r[1] * f.state.w[1, 0])
    with pytest.raises(ValueError, match="read-only"):
        f.positions[0, 0] = 1.0
    before = f.positions
    f.step(Z, POSE)
    np.testing.assert_array_equal(f.positions[50], f.state.x[1, 0, [0, 2]])
    assert f.positions is not before


def test_labelled_particles_is_a_copy() -> None:
    """Changing the copy a planner gets leaves the filter's state alone; the state is read-only."""
    f = _filter(FilterConfig(particles_per_label=20))
    mine = f.labelled_particles()
    assert isinstance(mine, LabelledParticles)
    mine.x[:] = 0.0
    mine.r[:] = 0.5
    assert not np.all(f.state.x == 0.0)
    np.testing.assert_allclose(f.state.r, SCENARIO.birth_probability)
    with pytest.raises(ValueError, match="read-only"):
        f.state.w[0, 0] = 1.0


def test_config_defaults_and_birth_count() -> None:
    """The paper's 50 000 particles per label; n_birth = round(fraction · N), at least 1."""
    assert FilterConfig().particles_per_label == 50_000
    assert FilterConfig().n_birth == 5_000
    assert FilterConfig(particles_per_label=3, birth_fraction=0.01).n_birth == 1


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"particles_per_label": 0}, "particles_per_label"),
    ({"particles_per_label": 2.5}, "particles_per_label"),
    ({"birth_fraction": 0.0}, "birth_fraction"),
    ({"birth_fraction": 1.5}, "birth_fraction"),
    ({"existence_threshold": 1.0}, "existence_threshold"),
    ({"existence_threshold": math.nan}, "existence_threshold"),
])
def test_bad_config(kwargs: dict[str, object], field: str) -> None:
    """Out-of-range configuration values raise InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        FilterConfig(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"scenario": "paper"}, "scenario"),
    ({"config": 300}, "config"),
    ({"seed": -1}, "seed"),
    ({"likelihood": "eq. 22"}, "likelihood"),
])
def test_bad_constructor_arguments(kwargs: dict[str, object], field: str) -> None:
    """A scenario, config, seed or likelihood of the wrong kind is refused by name."""
    args: dict[str, object] = {"scenario": SCENARIO, "config": SMALL, "seed": 0,
                               "likelihood": _constant([0.0] * 4)}
    args.update(kwargs)
    with pytest.raises(InvalidInputError) as err:
        LabelledFilter(args["scenario"], args["config"],  # type: ignore[arg-type]
                       likelihood=args["likelihood"], seed=args["seed"])  # type: ignore[arg-type]
    assert err.value.field == field


NAN_Z = Z.copy()
NAN_Z[10, 20] = np.nan


@pytest.mark.parametrize(("z", "pose", "field"), [
    (Z[:, :-1], [0.0, 0.0, 0.0], "z"),
    (Z.T, [0.0, 0.0, 0.0], "z"),
    (Z[0], [0.0, 0.0, 0.0], "z"),
    (NAN_Z, [0.0, 0.0, 0.0], "z"),
    (-Z, [0.0, 0.0, 0.0], "z"),
    (Z, [0.0, 0.0], "uav_pose"),
    (Z, [0.0, math.nan, 0.0], "uav_pose"),
    (Z, [0.0, math.inf, 0.0], "uav_pose"),
    (Z, "north", "uav_pose"),
])
def test_bad_step_input(z: np.ndarray, pose: object, field: str) -> None:
    """Bad magnitudes or poses raise InvalidInputError naming the field; the state and the
    random generator are kept (the next step equals a fresh filter's first)."""
    f, fresh = _filter(), _filter()
    before = f.labelled_particles()
    with pytest.raises(InvalidInputError) as err:
        f.step(z, pose)  # type: ignore[arg-type]
    assert err.value.field == field
    assert f.steps == 0
    np.testing.assert_array_equal(f.state.x, before.x)
    f.step(Z, POSE)
    fresh.step(Z, POSE)
    np.testing.assert_array_equal(f.state.x, fresh.state.x)


@pytest.mark.parametrize("bad", [np.zeros((4, 3)), np.full((4, 240), np.nan)])
def test_bad_likelihood_output(bad: np.ndarray) -> None:
    """A likelihood of the wrong shape or not finite is refused; the state is kept."""
    f = LabelledFilter(SCENARIO, SMALL, likelihood=lambda z, pose, pred: bad, seed=0)
    with pytest.raises(InvalidInputError, match="log_lik"):
        f.step(Z, POSE)
    assert f.steps == 0
    np.testing.assert_allclose(f.state.r, SCENARIO.birth_probability)


@pytest.mark.parametrize("cls", [TbdLmbFilter, DttLmbFilter])
def test_radio_filters_are_labelled_filters(cls: type[LabelledFilter]) -> None:
    """Both radio filters are this filter (seams, read-outs, input checks) with the constructor
    checks of its arguments."""
    f = cls(SCENARIO, FilterConfig(particles_per_label=20), seed=0)
    assert isinstance(f, LabelledFilter)
    assert isinstance(f, LabelledParticleBelief) and isinstance(f, ParticleBelief)
    with pytest.raises(InvalidInputError, match="z"):
        f.step(-Z, POSE)
    assert f.steps == 0
    f.step(Z, POSE)
    assert f.steps == 1 and f.state.w.shape == (SIGNAL.n_labels, 20)
    for kwargs, field in (({"scenario": "paper"}, "scenario"), ({"config": 300}, "config"),
                          ({"seed": -1}, "seed")):
        args: dict[str, object] = {"scenario": SCENARIO, "config": SMALL, "seed": 0}
        args.update(kwargs)
        with pytest.raises(InvalidInputError) as err:
            cls(args["scenario"], args["config"], seed=args["seed"])  # type: ignore[arg-type]
        assert err.value.field == field


def test_roughening_keeps_a_collapsed_cloud_alive() -> None:
    """A likelihood that picks one particle collapses the resampled cloud (spread 0) without
    roughening; with σ_r every axis keeps a spread close to σ_r. roughen() itself jitters by
    σ_r on both axes whatever the cloud's extent (a wide cloud is not jittered more)."""
    def one(z: np.ndarray, pose: np.ndarray, pred: LabelledParticles) -> np.ndarray:
        out = np.full(pred.w.shape, -1e3)
        out[:, 0] = 0.0
        return out

    spreads = {}
    for floor in (0.0, 3.0):
        config = FilterConfig(particles_per_label=400, birth_fraction=0.01, roughening_m=floor)
        f = LabelledFilter(SCENARIO, config, likelihood=one, seed=2)
        f.step(Z, POSE)
        spreads[floor] = f.state.x[:, :, ::2].std(axis=1)
    assert np.all(spreads[0.0] < 1e-9)
    np.testing.assert_allclose(spreads[3.0], 3.0, rtol=0.15)
    rng = np.random.default_rng(0)
    x = np.zeros((1, 10_000, 4))
    x[0, :, 0] = np.linspace(0.0, 1000.0, 10_000)          # extent 1000 m in x, 0 in y
    state = LabelledParticles(x.copy(), np.zeros((1, 10_000), dtype=np.int8),
                              np.full((1, 10_000), 0.1), np.full((1, 10_000), 1e-4),
                              np.array([0.9]))
    roughen(state, 1.0, rng)
    jitter = state.x[0] - x[0]
    assert jitter[:, 0].std() == pytest.approx(1.0, rel=0.05)
    assert jitter[:, 2].std() == pytest.approx(1.0, rel=0.05)
    assert np.all(jitter[:, [1, 3]] == 0.0)
    for bad in (-1.0, math.nan):
        with pytest.raises(InvalidInputError, match="roughening_m"):
            FilterConfig(roughening_m=bad)
