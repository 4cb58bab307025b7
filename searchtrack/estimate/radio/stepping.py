"""The labelled radio-tag filters of paper 002 as a
:class:`~searchtrack.estimate.stepping.SteppedFilter`.

A :class:`~searchtrack.estimate.radio.filter.LabelledFilter` (the TBD-LMB filter or the DTT
baseline) steps once per signal period ``T0``: its
:meth:`~searchtrack.estimate.radio.filter.LabelledFilter.step` predicts one period (eqs. 24–27,
with re-birth), updates with the STFT magnitudes ``z`` taken at the UAV pose (eqs. 29–30) and
resamples. :class:`LabelledStepping` lets a closed loop call it like any other filter:
:meth:`~LabelledStepping.predict` takes exactly one period and holds it;
:meth:`~LabelledStepping.update` runs the held step on ``z``. The wrapped filter keeps its own
generator, seeded when it was built, so the draws are those of calling ``step`` directly.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.radio.filter import LabelledFilter


class LabelledStepping:
    """A labelled particle LMB filter stepped by predict and update.

    Parameters
    ----------
    labelled
        The filter (a :class:`~searchtrack.estimate.radio.tbd.TbdLmbFilter` or
        :class:`~searchtrack.estimate.radio.dtt.DttLmbFilter`); it is stepped in place.
    """

    def __init__(self, labelled: LabelledFilter) -> None:
        if not isinstance(labelled, LabelledFilter):
            raise InvalidInputError("labelled", labelled, "must be a LabelledFilter")
        self.labelled = labelled
        self._predicted = False

    @property
    def period_s(self) -> float:
        """The signal period ``T0`` (s), the only step the filter takes."""
        return float(self.labelled.scenario.signal.period_s)

    def predict(self, dt_s: float) -> None:
        """Hold one prediction of ``T0`` seconds for the next :meth:`update`.

        Raises
        ------
        InvalidInputError
            ``dt_s`` is not ``T0``, or a prediction is already held.
        """
        dt = checks.real("dt_s", dt_s)
        if not math.isclose(dt, self.period_s):
            raise InvalidInputError("dt_s", dt_s, f"the filter steps one period "
                                    f"T0 = {self.period_s:g} s at a time")
        if self._predicted:
            raise InvalidInputError("dt_s", dt_s, "a period is already predicted: update first")
        self._predicted = True

    def update(self, scan: FloatArray, pose: ArrayLike) -> list[tuple[int, FloatArray]]:
        """Predict the held period and update with the magnitudes ``scan`` ``(M, L)`` taken at
        ``pose`` ``(x, y, heading)``; the labels reported and their positions.

        Raises
        ------
        InvalidInputError
            No period was predicted since the last update, or the filter refused ``scan`` or
            ``pose`` (a prediction is then still held).
        """
        if not self._predicted:
            raise InvalidInputError("scan", "update", "predict one period T0 before each update")
        self.labelled.step(scan, pose)
        self._predicted = False
        return self.labelled.estimates()

    def estimates_xy(self) -> FloatArray:
        """``(k, 2)`` positions of the labels whose existence passes the threshold."""
        found = self.labelled.estimates()
        return np.array([xy for _, xy in found], dtype=np.float64).reshape(-1, 2)
