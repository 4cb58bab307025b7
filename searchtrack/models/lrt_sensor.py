"""The UAV sensor of the log-likelihood-ratio tracker: detection statistics and the altitude model
(thesis 001, §3.3, §4.1, §6.2).

A sensor sees the disc of radius ``ρ`` under the UAV. It is summed up by its probability of
detection ``P_d`` and of false alarm ``P_f`` per time step, which fix the sensitivity
``m = z(P_d) − z(P_f)`` (3.9) of the equal-variance Gaussian model (3.10)–(3.11): the scalar
measurement is ``ζ = w`` without a target and ``ζ = m + w`` with one, ``w ~ N(0, 1)``; and by
``s``, the standard deviation of a target's measured position (§4.3). The criterion ``c = m/2``
(§4.1) separates target from no-target measurements. Random draws live in
:mod:`searchtrack.models.measurements`.

The altitude model (6.4)–(6.7) makes ``P_d``, ``P_f``, ``s`` and ``ρ`` linear in the altitude
``h``. The thesis prints ``h/457`` but tabulates (Table 6.3) the values for ``h/457.2`` (457.2 m =
1500 ft): :attr:`AltitudeModel.reference_altitude_m` defaults to the printed 457 m, and 457.2
reproduces the table except ``ρ(1372 m)``, which the table rounds to 280.0 where (6.7) gives
280.5 (an erratum in the table).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import overload

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ndtr, ndtri

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


@overload
def z_score(p: float) -> float: ...
@overload
def z_score(p: ArrayLike) -> float | FloatArray: ...
def z_score(p: ArrayLike) -> float | FloatArray:
    """The standard normal quantile ``z(p) = √2 erf⁻¹(2p − 1)`` (§3.3), for ``p`` in ``(0, 1)``."""
    arr = np.asarray(p, dtype=np.float64)
    if not np.all((arr > 0) & (arr < 1)):
        raise InvalidInputError("p", p, "probabilities must be in (0, 1)")
    out = ndtri(arr)
    return float(out) if out.ndim == 0 else np.asarray(out)


def sensitivity(pd: float, pf: float) -> float:
    """The sensitivity ``m = z(P_d) − z(P_f)`` (3.9) in standard-deviation units."""
    return z_score(checks.probability("pd", pd)) - z_score(checks.probability("pf", pf))


def roc(sensitivity_m: float, criteria: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """The equal-variance Gaussian ROC of Fig. 6.4: ``(P_f, P_d)`` at each criterion ``z_c``.

    ``P_f = 1 − Φ(z_c)`` and ``P_d = 1 − Φ(z_c − m)``: the rates of ``ζ > z_c`` without and with
    a target.
    """
    m = checks.real("sensitivity_m", sensitivity_m)
    zc = checks.finite_array("criteria", np.atleast_1d(np.asarray(criteria, dtype=float)), (None,))
    return np.asarray(ndtr(-zc)), np.asarray(ndtr(m - zc))


@dataclass(frozen=True)
class SensorModel:
    """A downward-looking sensor with a circular footprint (§3.3, §4.3).

    Parameters
    ----------
    pd
        Probability of detection per time step, in ``(0, 1)``; ``pd > pf``.
    pf
        Probability of false alarm per time step, in ``(0, 1)``.
    footprint_radius_m
        Radius ``ρ`` (m) of the disc the sensor sees.
    position_noise_m
        Standard deviation ``s`` (m) of each coordinate of a measured target position; 0 for
        exact positions.
    false_alarms_per_scan
        Mean number of false position measurements (Poisson) per footprint per time step;
        ``None`` (the default) takes ``pf``, the thesis's false alarm rate per time step.
    cell_radius_m
        Resolution cell of the scalar measurement when ``ζ`` is drawn per road node: a target
        raises ``ζ`` (mean ``m``) on every footprint node within this distance of it (20 m, two
        nodes either side at 10 m spacing). With 0 only the target's own node sees it; a lone
        node's evidence is then averaged away by the LRT diffusion (each step it keeps about
        70 % of its value and takes the rest from neighbours that measured ``−m²/2``), so a
        moving target is never detected.
    """

    pd: float
    pf: float
    footprint_radius_m: float
    position_noise_m: float = 0.0
    false_alarms_per_scan: float | None = None
    cell_radius_m: float = 20.0

    def __post_init__(self) -> None:
        pd = checks.probability("pd", self.pd)
        pf = checks.probability("pf", self.pf)
        if pd <= pf:
            raise InvalidInputError("pd", self.pd, f"must exceed pf={pf!r} (sensitivity > 0)")
        set_ = object.__setattr__
        set_(self, "pd", pd)
        set_(self, "pf", pf)
        set_(self, "footprint_radius_m", checks.positive("footprint_radius_m",
                                                          self.footprint_radius_m))
        set_(self, "position_noise_m", checks.non_negative("position_noise_m",
                                                            self.position_noise_m))
        set_(self, "cell_radius_m", checks.non_negative("cell_radius_m", self.cell_radius_m))
        if self.false_alarms_per_scan is not None:
            set_(self, "false_alarms_per_scan",
                 checks.non_negative("false_alarms_per_scan", self.false_alarms_per_scan))

    @property
    def sensitivity(self) -> float:
        """``m = z(P_d) − z(P_f)`` (3.9)."""
        return sensitivity(self.pd, self.pf)

    @property
    def criterion(self) -> float:
        """``c = m/2`` (§4.1): where the no-target and target densities of ``ζ`` cross."""
        return self.sensitivity / 2.0

    @property
    def hit_rate(self) -> float:
        """``P(ζ > c | target) = Φ(m/2)``: how often a target passes the criterion."""
        return float(ndtr(self.sensitivity / 2.0))

    @property
    def false_hit_rate(self) -> float:
        """``P(ζ > c | no target) = 1 − Φ(m/2)``."""
        return float(ndtr(-self.sensitivity / 2.0))

    @property
    def false_alarm_mean(self) -> float:
        """Mean number of false position measurements per footprint per step (``pf`` unless
        ``false_alarms_per_scan`` is set)."""
        fa = self.false_alarms_per_scan
        return self.pf if fa is None else fa

    def log_likelihood_ratio(self, zeta: ArrayLike) -> FloatArray:
        """The LRT increment ``log p(ζ|ξ⁺) − log p(ζ|ξ⁻) = m(ζ − m/2)`` ((3.10), (3.11))."""
        m = self.sensitivity
        return m * (np.asarray(zeta, dtype=np.float64) - m / 2.0)

    @classmethod
    def at_altitude(cls, altitude_m: float, model: AltitudeModel | None = None) -> SensorModel:
        """The sensor flown at ``altitude_m`` under ``model`` (the thesis's by default)."""
        return (model or AltitudeModel()).sensor(altitude_m)


@dataclass(frozen=True)
class AltitudeModel:
    """``P_d``, ``P_f``, ``s`` and ``ρ`` against altitude ``h`` (6.4)–(6.7); thesis values.

    ``P_d = pd_intercept − pd_drop·h/h_ref`` (6.4), ``P_f = pf_rise·h/h_ref`` (6.5),
    ``s = noise_at_reference_m·h/h_ref`` (6.6) and ``ρ = (S_r/F_L)·h`` (6.7).

    Parameters
    ----------
    reference_altitude_m
        ``h_ref``: 457 m as printed in (6.4)–(6.6); 457.2 m reproduces Table 6.3.
    pd_intercept, pd_drop, pf_rise
        The coefficients of (6.4) and (6.5): 0.975, 0.025, 0.025.
    noise_at_reference_m
        ``s`` at ``h_ref``: 5 m (6.6).
    focal_length_m, sensor_radius_m
        ``F_L`` = 90 mm and ``S_r`` = 18.4 mm (6.7).
    """

    reference_altitude_m: float = 457.0
    pd_intercept: float = 0.975
    pd_drop: float = 0.025
    pf_rise: float = 0.025
    noise_at_reference_m: float = 5.0
    focal_length_m: float = 0.090
    sensor_radius_m: float = 0.0184

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "pd_intercept", checks.real("pd_intercept", self.pd_intercept,
                                                low=0.0, high=1.0, low_open=True))
        for name in ("reference_altitude_m", "pd_drop", "pf_rise", "focal_length_m",
                     "sensor_radius_m"):
            set_(self, name, checks.positive(name, getattr(self, name)))
        set_(self, "noise_at_reference_m",
             checks.non_negative("noise_at_reference_m", self.noise_at_reference_m))

    @property
    def max_altitude_m(self) -> float:
        """The altitude where ``P_d`` falls to ``P_f`` (``m = 0``); the model holds below it."""
        return self.pd_intercept / (self.pd_drop + self.pf_rise) * self.reference_altitude_m

    def _altitude(self, altitude_m: ArrayLike) -> FloatArray:
        h = np.asarray(altitude_m, dtype=np.float64)
        if not np.all(np.isfinite(h) & (h > 0) & (h < self.max_altitude_m)):
            raise InvalidInputError("altitude_m", altitude_m,
                                    f"must be in (0, {self.max_altitude_m:.1f}) m, where pd > pf")
        return h

    def pd(self, altitude_m: ArrayLike) -> FloatArray:
        """``P_d(h)`` (6.4)."""
        h = self._altitude(altitude_m)
        return self.pd_intercept - self.pd_drop * h / self.reference_altitude_m

    def pf(self, altitude_m: ArrayLike) -> FloatArray:
        """``P_f(h)`` (6.5)."""
        return self.pf_rise * self._altitude(altitude_m) / self.reference_altitude_m

    def position_noise_m(self, altitude_m: ArrayLike) -> FloatArray:
        """``s(h)`` (6.6), m."""
        h = self._altitude(altitude_m)
        return self.noise_at_reference_m * h / self.reference_altitude_m

    def footprint_radius_m(self, altitude_m: ArrayLike) -> FloatArray:
        """``ρ(h) = (S_r/F_L)·h`` (6.7), m."""
        return self.sensor_radius_m / self.focal_length_m * self._altitude(altitude_m)

    def sensitivity(self, altitude_m: ArrayLike) -> FloatArray:
        """``m(h) = z(P_d(h)) − z(P_f(h))``, decreasing in ``h``."""
        return np.asarray(ndtri(self.pd(altitude_m)) - ndtri(self.pf(altitude_m)))

    def sensor(self, altitude_m: float, false_alarms_per_scan: float | None = None) -> SensorModel:
        """The :class:`SensorModel` at one altitude (m)."""
        h = checks.positive("altitude_m", altitude_m)
        return SensorModel(
            pd=float(self.pd(h)),
            pf=float(self.pf(h)),
            footprint_radius_m=float(self.footprint_radius_m(h)),
            position_noise_m=float(self.position_noise_m(h)),
            false_alarms_per_scan=false_alarms_per_scan,
        )


THESIS_ALTITUDES_M: tuple[float, ...] = (457.2, 914.4, 1372.0, 1828.8)
"""The four altitudes of §6.2 (1500, 3000, 4500 and 6000 ft as printed in Table 6.3)."""

TABLE_6_2_SENSOR = SensorModel(pd=0.95, pf=0.10, footprint_radius_m=120.0)
"""The search experiment's sensor (Table 6.2): ``P_d`` 0.95, ``P_f`` 0.10, ``ρ`` 120 m."""

