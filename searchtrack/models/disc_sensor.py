"""A downward-looking camera with a circular field of view over roads (Moore et al. 2021, §2.4–2.5).

The UAV sees the disc of radius ``fov_radius_m`` beneath it. A target inside the disc is detected
with probability ``1 − p_fn`` and measured at its position plus ``N(0, σ² I)`` noise, with
``σ² = sigma2_m2`` (the paper's ``σ_τ`` is a variance: its code uses covariance ``R·I``).

Positive measurement likelihood, Eq. 10: a mixture of the Gaussian detection and uniform clutter,
``p(y | x) = (1 − P_FA) N(y; G(x), σ² I) + P_FA · c``. The paper's clutter density ``1/A_R`` is
"one over the area spanned by the roads"; we take it per metre of road, as the authors' code does,
with two conventions (``clutter``):

- ``"roads"`` (default): ``c = 1 / L`` with ``L`` the total directed road length (each two-way
  road counted twice);
- ``"view"``: ``c = 1 / L_F`` with ``L_F`` the directed road length inside the field of view,
  which is where :meth:`DiscSensor.detect` puts its false alarms (0 when no road is in view).

Negative information, Eq. 11: as printed, the in-view value ``(1 − P_FN)/A_F`` exceeds the
out-of-view value, so a miss would pull particles *into* the view. We use the intended (and coded)
model: likelihood ``P_FN`` for a particle inside a disc of ``negative_radius_factor ×
fov_radius_m`` (0.75 × 30 m in the code, a margin for targets at the edge of the image), 1
outside.

Simulated detections (:meth:`DiscSensor.detect`), not specified by the paper: each target in view
is detected independently with probability ``1 − p_fn``; with probability ``p_fa`` one false
alarm falls uniformly (by length) on the roads inside the view, without noise; the detections are
returned in random order so that their order carries no identity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import BoolArray, FloatArray, IntArray
from searchtrack.models.road_particles import DirectedRoads

ClutterConvention = Literal["roads", "view"]


@dataclass(frozen=True)
class DiscSensor:
    """A circular field of view under the UAV with noisy position detections.

    Parameters
    ----------
    fov_radius_m
        Radius of the field of view (m), > 0 (30 m in the paper's simulation).
    sigma2_m2
        Measurement noise variance per axis (m²), > 0: covariance ``sigma2_m2 · I`` (5).
    p_fa
        Probability of one false alarm per scan, in ``[0, 1)`` (0.02).
    p_fn
        Probability of missing a target in view, in ``[0, 1)`` (0.05).
    negative_radius_factor
        The negative update (Eq. 11) applies inside ``negative_radius_factor · fov_radius_m``,
        in ``(0, 1]`` (0.75).
    clutter
        Clutter density convention of Eq. 10: ``"roads"`` or ``"view"`` (see the module).
    """

    fov_radius_m: float = 30.0
    sigma2_m2: float = 5.0
    p_fa: float = 0.02
    p_fn: float = 0.05
    negative_radius_factor: float = 0.75
    clutter: ClutterConvention = "roads"

    def __post_init__(self) -> None:
        object.__setattr__(self, "fov_radius_m", checks.positive("fov_radius_m",
                                                                 self.fov_radius_m))
        object.__setattr__(self, "sigma2_m2", checks.positive("sigma2_m2", self.sigma2_m2))
        object.__setattr__(self, "p_fa", checks.real("p_fa", self.p_fa, low=0.0, high=1.0,
                                                     high_open=True))
        object.__setattr__(self, "p_fn", checks.real("p_fn", self.p_fn, low=0.0, high=1.0,
                                                     high_open=True))
        object.__setattr__(self, "negative_radius_factor", checks.real(
            "negative_radius_factor", self.negative_radius_factor, low=0.0, high=1.0,
            low_open=True))
        if self.clutter not in ("roads", "view"):
            raise InvalidInputError("clutter", self.clutter, "must be 'roads' or 'view'")

    @property
    def negative_radius_m(self) -> float:
        """Radius (m) of the disc where a miss lowers the particle weights (Eq. 11)."""
        return self.negative_radius_factor * self.fov_radius_m

    @property
    def detection_gain(self) -> float:
        """``(1 − P_FA) / (2π σ²)``: the peak of the Gaussian term of Eq. 10 (1/m²)."""
        return (1.0 - self.p_fa) / (2.0 * math.pi * self.sigma2_m2)

    def in_view(self, points: ArrayLike, uav_xy: ArrayLike) -> BoolArray:
        """Whether each planar point ``(..., 2)`` is inside the field of view."""
        d = np.asarray(points, dtype=np.float64) - checks.finite_array("uav_xy", uav_xy, (2,))
        return np.asarray(np.einsum("...i,...i->...", d, d) <= self.fov_radius_m ** 2)

    def clutter_density(self, roads: DirectedRoads, uav_xy: ArrayLike | None = None) -> float:
        """The clutter density ``c`` of Eq. 10 (per metre of directed road) under the sensor's
        convention; ``"view"`` needs ``uav_xy`` and gives 0 when no road is in view."""
        if self.clutter == "roads":
            return 1.0 / roads.total_length_m
        if uav_xy is None:
            raise InvalidInputError("uav_xy", None, "the 'view' clutter convention needs it")
        s0, s1 = roads.disc_intervals(np.asarray(uav_xy, dtype=np.float64), self.fov_radius_m)
        inside = float((s1 - s0).sum())
        return 1.0 / inside if inside > 0.0 else 0.0

    def likelihood(self, points: ArrayLike, y: ArrayLike, clutter_density: float) -> FloatArray:
        """Eq. 10: ``p(y | x)`` for particles at planar ``points`` ``(..., 2)`` and one detection
        ``y`` ``(2,)``, with clutter density ``clutter_density`` (see :meth:`clutter_density`).
        """
        yy = checks.finite_array("y", y, (2,))
        c = checks.non_negative("clutter_density", clutter_density)
        d = np.asarray(points, dtype=np.float64) - yy
        d2 = np.einsum("...i,...i->...", d, d)
        out = self.detection_gain * np.exp(-0.5 * d2 / self.sigma2_m2) + self.p_fa * c
        return np.asarray(out, dtype=np.float64)

    def miss_likelihood(self, points: ArrayLike, uav_xy: ArrayLike) -> FloatArray:
        """Eq. 11 as intended: ``P_FN`` for points ``(..., 2)`` within :attr:`negative_radius_m`
        of the UAV, 1 elsewhere."""
        d = np.asarray(points, dtype=np.float64) - checks.finite_array("uav_xy", uav_xy, (2,))
        inside = np.einsum("...i,...i->...", d, d) <= self.negative_radius_m ** 2
        return np.where(inside, self.p_fn, 1.0)

    def detect(self, uav_xy: ArrayLike, target_points: ArrayLike, rng: np.random.Generator,
               roads: DirectedRoads) -> FloatArray:
        """One scan: ``(k, 2)`` detections of the targets at ``target_points`` ``(M, 2)`` plus
        clutter on ``roads``, in random order (see :meth:`detect_labelled`)."""
        return self.detect_labelled(uav_xy, target_points, rng, roads)[0]

    def detect_labelled(self, uav_xy: ArrayLike, target_points: ArrayLike,
                        rng: np.random.Generator,
                        roads: DirectedRoads) -> tuple[FloatArray, IntArray]:
        """One scan with its truth: ``(detections (k, 2), source (k,))``, ``source`` the index of
        the detected target or −1 for a false alarm.

        Each target in view is detected with probability ``1 − p_fn`` at its point plus
        ``N(0, σ² I)``; with probability ``p_fa`` one false alarm falls uniformly on the directed
        roads inside the view (none if no road is in view). The random numbers drawn do not
        depend on the geometry, so a seed gives the same stream whatever the targets do.
        """
        uav = checks.finite_array("uav_xy", uav_xy, (2,))
        pts = checks.points("target_points", target_points)
        checks.generator("rng", rng)
        k = pts.shape[0]
        hit = self.in_view(pts, uav) & (rng.random(k) >= self.p_fn)
        noise = math.sqrt(self.sigma2_m2) * rng.standard_normal((k, 2))
        ys = [pts[hit] + noise[hit]]
        source = [np.flatnonzero(hit)]
        u_fa, u_edge, u_s = rng.random(3)
        if u_fa < self.p_fa:
            s0, s1 = roads.disc_intervals(uav, self.fov_radius_m)
            cdf = np.cumsum(s1 - s0)
            if cdf[-1] > 0.0:
                d = min(int(np.searchsorted(cdf, u_edge * cdf[-1], side="right")),
                        roads.n_edges - 1)
                s = s0[d] + u_s * (s1[d] - s0[d])
                ys.append(roads.point(np.array([d]), np.array([s])))
                source.append(np.array([-1]))
        y = np.concatenate(ys).reshape(-1, 2)
        src = np.concatenate(source).astype(np.int64)
        order = rng.permutation(y.shape[0])
        return y[order], src[order]
