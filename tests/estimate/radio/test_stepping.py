"""The labelled radio filter stepped by predict and update is its own ``step``, one period at a
time."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.radio.stepping import LabelledStepping
from searchtrack.estimate.radio.tbd import FilterConfig, TbdLmbFilter
from searchtrack.estimate.stepping import PointEstimates, SteppedFilter
from searchtrack.models.radio.scenario import RadioScenario
from searchtrack.models.radio.stft import simulate_stft

SCENARIO = RadioScenario.paper(noise_var_v2=0.01**2)
SIGNAL = SCENARIO.signal
TAG_XY = np.array([[800.0, 300.0]])
SMALL = FilterConfig(particles_per_label=300, birth_fraction=0.2)


def _pose(k: int) -> np.ndarray:
    """The UAV circles the tag at 100 m."""
    a = 0.3 * k
    return np.array([800.0 + 100.0 * math.cos(a), 300.0 + 100.0 * math.sin(a), a + math.pi])


def test_predict_then_update_is_the_filters_step() -> None:
    """Stepped by predict and update, a filter ends in the state of one stepped directly with
    the same seed and data, and reports the live tag where it is."""
    direct = TbdLmbFilter(SCENARIO, SMALL, seed=3)
    stepped = LabelledStepping(TbdLmbFilter(SCENARIO, SMALL, seed=3))
    assert isinstance(stepped, SteppedFilter) and isinstance(stepped, PointEstimates)
    rng = np.random.default_rng(103)
    for k in range(15):
        pose = _pose(k)
        z = simulate_stft(SIGNAL, TAG_XY, [0], [0.1], pose, rng)
        direct.step(z, pose)
        stepped.predict(SIGNAL.period_s)
        found = stepped.update(z, pose)
        assert [label for label, _ in found] == [label for label, _ in direct.estimates()]
    np.testing.assert_array_equal(stepped.labelled.state.x, direct.state.x)
    np.testing.assert_array_equal(stepped.labelled.state.r, direct.state.r)
    xy = stepped.estimates_xy()
    assert xy.shape == (1, 2) and np.hypot(*(xy[0] - TAG_XY[0])) < 60.0


def test_one_period_before_each_update() -> None:
    """A step other than ``T0``, two predictions in a row and an update without a prediction
    are refused by name; a refused scan leaves the prediction held."""
    stepped = LabelledStepping(TbdLmbFilter(SCENARIO, SMALL, seed=0))
    assert stepped.estimates_xy().shape == (0, 2)
    with pytest.raises(InvalidInputError) as info:
        stepped.update(np.zeros((SIGNAL.frames, SIGNAL.fft_size)), _pose(0))
    assert info.value.field == "scan"
    with pytest.raises(InvalidInputError) as info:
        stepped.predict(2.0 * SIGNAL.period_s)
    assert info.value.field == "dt_s"
    stepped.predict(SIGNAL.period_s)
    with pytest.raises(InvalidInputError) as info:
        stepped.predict(SIGNAL.period_s)
    assert info.value.field == "dt_s"
    with pytest.raises(InvalidInputError):
        stepped.update(np.zeros((2, 2)), _pose(0))
    stepped.update(np.zeros((SIGNAL.frames, SIGNAL.fft_size)), _pose(0))
    assert stepped.labelled.steps == 1
    with pytest.raises(InvalidInputError) as info:
        LabelledStepping(object())  # type: ignore[arg-type]
    assert info.value.field == "labelled"
