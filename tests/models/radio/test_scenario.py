"""RadioScenario: the §IV-A set-up, its TOML form, and the simulated ground truth."""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.models.radio.motion import CV, WD, TagMotion
from searchtrack.models.radio.scenario import RadioScenario, TagSpec, simulate_truth
from searchtrack.models.radio.signal import RadioSignal
from searchtrack.models.radio.uav import UavModel

PAPER = RadioScenario.paper()


def _paper_file() -> Path:
    return Path(str(resources.files("searchtrack") / "data" / "scenarios" / "radio_paper.toml"))


def test_paper_scenario_matches_tables_ii_to_iv() -> None:
    """Four tags with the paper's lifetimes, states, offsets and mode schedules."""
    assert [(t.birth_s, t.death_s) for t in PAPER.tags] == [(1, 250), (50, 300), (100, 350),
                                                           (150, 400)]
    assert [t.label for t in PAPER.tags] == [0, 1, 2, 3]
    assert [t.tau_s for t in PAPER.tags] == [0.1, 0.2, 0.3, 0.4]
    assert PAPER.tags[0].initial_state == (800.0, 0.13, 300.0, -1.44)
    assert PAPER.tags[3].initial_state == (900.0, 1.91, 1300.0, -2.04)
    assert [t.scheduled_mode(1.0) for t in PAPER.tags] == [CV, WD, CV, WD]
    assert [t.scheduled_mode(65.0) for t in PAPER.tags] == [None, WD, None, WD]
    assert PAPER.tags[1].scheduled_mode(66.0) is None
    assert PAPER.n_steps == 400 and PAPER.area_m == (1500.0, 1500.0)
    assert PAPER.birth_means[2] == (1200.0, 0.0, 1000.0, 0.0)
    assert PAPER.birth_probability == 1e-6 and PAPER.survival_probability == 0.99
    assert PAPER.signal == RadioSignal() and PAPER.motion == TagMotion()
    assert PAPER.uav == UavModel()
    loud = RadioScenario.paper(0.05**2)
    assert loud.signal.noise_var_v2 == 0.05**2 and loud.tags == PAPER.tags


def test_bundled_file_loads_equal_to_the_paper_scenario() -> None:
    """data/scenarios/radio_paper.toml is RadioScenario.paper() written out."""
    assert RadioScenario.from_toml(_paper_file()) == PAPER


def test_to_dict_round_trips() -> None:
    """from_dict(to_dict(s)) == s, also for a modified scenario; the dict is plain data."""
    custom = RadioScenario(signal=RadioSignal(frequencies_hz=(131e3, 401e3)),
                           tags=(TagSpec(1, 0.0, 10.0, (1.0, 2.0, 3.0, 4.0), 0.5,
                                         ((0.0, 1), (2.0, 0))),),
                           duration_s=20.0, area_m=(100.0, 200.0))
    for scenario in (PAPER, custom):
        data = scenario.to_dict()
        assert isinstance(data["signal"]["frequencies_hz"], list)
        assert isinstance(data["tags"][0]["mode_schedule"][0], list)
        assert RadioScenario.from_dict(data) == scenario
    assert RadioScenario.from_dict({}) == PAPER


def _nested(path: str, value: Any) -> dict[str, Any]:
    """``{"a": {"b": value}}`` for ``"a.b"``; ``tags[i].key`` edits a copy of the paper tags."""
    head, _, rest = path.partition(".")
    if head.startswith("tags["):
        tags = PAPER.to_dict()["tags"]
        tags[int(head[5:-1])][rest] = value
        return {"tags": tags}
    return {head: {rest: value}} if rest else {head: value}


@pytest.mark.parametrize(("path", "value"), [
    ("foo", 1),
    ("signal.foo", 1),
    ("motion.bar", 1),
    ("uav.baz", 1),
    ("tags[2].colour", "red"),
    ("signal.noise_var_v2", math.nan),
    ("signal.noise_var_v2", -0.1),
    ("signal.frames", "many"),
    ("motion.tau_std", -1.0),
    ("uav.speed_mps", math.inf),
    ("duration_s", -1.0),
    ("duration_s", math.nan),
    ("area_m", [1500.0]),
    ("birth_probability", 1.5),
    ("birth_cov_diag", [100.0, -4.0, 100.0, 4.0]),
    ("tags[1].tau_s", -0.2),
    ("tags[1].tau_s", 1.0),
    ("tags[0].death_s", 0.5),
    ("tags[3].initial_state", [1.0, 2.0]),
    ("tags[3].mode_schedule", [[1.0, 0]]),
    ("tags[3].mode_schedule", [[0.0, 2]]),
    ("tags[1].label", 0),
    ("tags[1].label", 4),
    ("motion.period_s", 2.0),
    ("uav.step_s", 0.5),
])
def test_bad_entries_name_their_key_path(path: str, value: Any) -> None:
    """Unknown keys and bad values raise InvalidInputError naming the dotted key path."""
    with pytest.raises(InvalidInputError) as err:
        RadioScenario.from_dict(_nested(path, value))
    assert err.value.field == path


def test_structural_errors() -> None:
    """A non-table section, a non-list of tags or a tag without a required key is named."""
    cases = [({"signal": 3}, "signal"), ({"tags": {"label": 0}}, "tags"),
             ({"tags": [{"label": 0}]}, "tags[0].birth_s"), ({"tags": [5]}, "tags[0]"),
             ({"uav": {"start_xy": [-5.0, 0.0]}}, "uav.start_xy")]
    for data, field in cases:
        with pytest.raises(InvalidInputError) as err:
            RadioScenario.from_dict(data)  # type: ignore[arg-type]
        assert err.value.field == field


def test_toml_file_errors(tmp_path: Path) -> None:
    """Missing or malformed files raise ParseError; bad content names the key and the file."""
    with pytest.raises(ParseError):
        RadioScenario.from_toml(tmp_path / "missing.toml")
    broken = tmp_path / "broken.toml"
    broken.write_text("[signal\nfoo = 1\n", encoding="utf-8")
    with pytest.raises(ParseError, match=r"broken\.toml"):
        RadioScenario.from_toml(broken)
    unknown = tmp_path / "unknown.toml"
    unknown.write_text("duration_s = 50.0\n[signal]\nfoo = 1\n", encoding="utf-8")
    with pytest.raises(InvalidInputError, match=r"unknown\.toml") as err:
        RadioScenario.from_toml(unknown)
    assert err.value.field == "signal.foo"
    short = tmp_path / "short.toml"
    short.write_text("duration_s = 50.0\ntags = []\n[signal]\nnoise_var_v2 = 1e-4\n",
                     encoding="utf-8")
    loaded = RadioScenario.from_toml(short)
    assert loaded.n_steps == 50 and loaded.tags == () and loaded.signal.noise_var_v2 == 1e-4


def test_truth_alive_windows_and_absent_conventions() -> None:
    """Tags live on birth ≤ t_k < death; absent rows hold NaN states/τ and mode −1."""
    truth = simulate_truth(PAPER, np.random.default_rng(0))
    assert truth.states.shape == (400, 4, 4) and truth.modes.dtype == np.int8
    np.testing.assert_array_equal(truth.times_s, np.arange(1, 401))
    np.testing.assert_array_equal(truth.alive.sum(axis=0), [249, 250, 250, 250])
    assert truth.alive[0].tolist() == [True, False, False, False]
    assert truth.alive[49, 1] and not truth.alive[48, 1] and not truth.alive[399, 3]
    absent = ~truth.alive
    assert np.isnan(truth.states[absent]).all() and np.isnan(truth.taus_s[absent]).all()
    assert (truth.modes[absent] == -1).all()
    assert np.isfinite(truth.states[truth.alive]).all()
    taus = truth.taus_s[truth.alive]
    assert taus.min() >= 0.0 and taus.max() < 1.0
    np.testing.assert_array_equal(truth.states[0, 0], PAPER.tags[0].initial_state)
    np.testing.assert_array_equal(truth.states[149, 3], PAPER.tags[3].initial_state)
    assert truth.taus_s[99, 2] == 0.3
    labels, xy = truth.positions(160)
    assert labels.tolist() == [0, 1, 2, 3]
    np.testing.assert_array_equal(xy, truth.states[160][:, [0, 2]])
    assert truth.positions(0)[1].shape == (1, 2)
    with pytest.raises(InvalidInputError, match="k"):
        truth.positions(400)


def test_truth_follows_the_mode_schedule_and_cv_moves_with_velocity() -> None:
    """Tags 0 and 2 are CV one second after birth, tags 1 and 3 WD for 65 s; CV steps add v T0."""
    truth = simulate_truth(PAPER, np.random.default_rng(1))
    for tag in PAPER.tags:
        row = int(tag.birth_s) - 1
        assert truth.modes[row, tag.label] == WD
        expected = CV if tag.label in (0, 2) else WD
        span = 1 if expected == CV else 66
        assert (truth.modes[row + 1:row + span + 1, tag.label] == expected).all()
    prev_cv = (truth.modes[:-1] == CV) & truth.alive[1:] & truth.alive[:-1]
    assert prev_cv.sum() > 100
    step = truth.states[1:] - truth.states[:-1]
    vel = truth.states[:-1][..., [1, 3]]
    np.testing.assert_allclose(step[..., [0, 2]][prev_cv], vel[prev_cv], atol=0.2)
    prev_wd = (truth.modes[:-1] == WD) & truth.alive[1:] & truth.alive[:-1]
    assert np.abs(step[..., [0, 2]][prev_wd]).max() < 3.0  # WD wanders by σ = 0.5 m


def test_truth_is_deterministic_for_a_seed() -> None:
    """The same seed gives the same truth; another seed a different one."""
    a = simulate_truth(PAPER, np.random.default_rng(5))
    b = simulate_truth(PAPER, np.random.default_rng(5))
    c = simulate_truth(PAPER, np.random.default_rng(6))
    np.testing.assert_array_equal(a.states, b.states)
    np.testing.assert_array_equal(a.modes, b.modes)
    assert not np.array_equal(a.states, c.states, equal_nan=True)
    with pytest.raises(InvalidInputError, match="rng"):
        simulate_truth(PAPER, 5)  # type: ignore[arg-type]
