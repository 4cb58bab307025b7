"""A downward-looking camera on a UAV that detects ground targets (paper 003, eqs. 6–8).

Pose layout
-----------
``pose = [x, y, z, yaw, (pitch, (roll))]``: the camera centre in metres (``z`` = height above
the flat ground ``z = 0``), then radians. ``yaw`` is the heading, counter-clockwise from the world
``x`` axis; ``pitch`` is nose-up positive and ``roll`` right-wing-down positive (both default
to 0). With ``gimballed=True`` (the default; the paper does not say) the camera stays nadir and
only ``yaw`` turns the image; with ``gimballed=False`` it is fixed to the airframe and tilts with
it.

Camera frame
------------
At zero attitude the optical axis points straight down, image columns grow to the aircraft's
right and image rows grow towards its tail, so the top of the image is ahead. The pinhole
projection of a point with camera coordinates ``(X_c, Y_c, Z_c)``, ``Z_c > 0``, is
``c = W/2 + f X_c / Z_c`` (column) and ``r = H/2 + f Y_c / Z_c`` (row), with the focal length
``f = (W/2) / tan(hfov/2)`` in pixels and square pixels. A target is in the image when
``0 ≤ r ≤ H`` and ``0 ≤ c ≤ W``.

Detection and measurement
-------------------------
- Pixels on target, eq. (6): ``n_px = (W / hfov) · arctan(L / d)`` with ``L`` the target length
  and ``d`` the 3-D camera-to-target distance (pixels per radian ``W / hfov``).
- Detection probability, eq. (7): ``p_d = p_d0 + (p_dmax − p_d0) / (1 + exp(−k (n_px − n_px0)))``
  inside the image, 0 outside it.
- Measurement ``z = [r, c]`` (pixels), eq. (8): ``g(z | x) = N(z; [r_x, c_x], σ² I)``.
- Clutter: Poisson, mean ``clutter_rate`` per image, uniform over the image:
  ``c(z) = clutter_rate / (W H)`` inside it.

The paper gives none of the constants; the defaults are ours: a 4.5 m car, a 640 × 480 image
over a 60° horizontal field of view (611 px/rad), ``p_d`` rising from 0 to 0.95 around 20 px on
target with slope 0.25 /px (so ``p_d ≈ 0.82`` straight down from 100 m and ``≈ 0.16`` from
200 m), and 2 px measurement noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import BoolArray, FloatArray

_MIN_DEPRESSION = math.radians(1.0)
"""Rays above this depression below the horizon are clamped to it by :meth:`to_position`."""


def _pose(pose: FloatArray) -> FloatArray:
    arr = np.asarray(pose, dtype=np.float64).reshape(-1)
    if arr.size < 4 or arr.size > 6 or not np.all(np.isfinite(arr)):
        raise InvalidInputError("pose", pose, "must be finite [x, y, z, yaw(, pitch(, roll))]")
    if arr[2] <= 0.0:
        raise InvalidInputError("pose", pose, "the camera height z must be > 0 (m)")
    return arr


def _ground(name: str, positions: FloatArray) -> FloatArray:
    arr = np.asarray(positions, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] < 2:
        raise InvalidInputError(name, arr.shape, "must have shape (N, 2)")
    return arr[:, :2]


@dataclass(frozen=True)
class DownwardCamera:
    """A nadir camera with logistic detection probability in pixels on target (003 eqs. 6–8).

    Parameters
    ----------
    width_px, height_px
        Image size (pixels), ``≥ 1``.
    hfov_rad
        Horizontal field of view (rad), in ``(0, π)``.
    target_length_m
        Length ``L`` of a target (m), ``> 0``.
    pd0, pd_max
        Lower and upper asymptotes of ``p_d``, ``0 ≤ pd0 ≤ pd_max ≤ 1``.
    slope_per_px
        Logistic slope ``k`` (1/px), ``> 0``.
    n_px0
        Pixels on target at the logistic midpoint, ``≥ 0``.
    sigma_px
        Pixel noise standard deviation ``σ`` (px), ``> 0``.
    clutter_rate
        Mean number of false alarms per image, ``≥ 0``.
    gimballed
        Keep the camera nadir whatever the pitch and roll (only ``yaw`` matters).
    """

    width_px: int = 640
    height_px: int = 480
    hfov_rad: float = math.radians(60.0)
    target_length_m: float = 4.5
    pd0: float = 0.0
    pd_max: float = 0.95
    slope_per_px: float = 0.25
    n_px0: float = 20.0
    sigma_px: float = 2.0
    clutter_rate: float = 1.0
    gimballed: bool = True

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "width_px", checks.count("width_px", self.width_px, 1))
        set_(self, "height_px", checks.count("height_px", self.height_px, 1))
        set_(self, "hfov_rad", checks.real("hfov_rad", self.hfov_rad, low=0.0, high=math.pi,
                                            low_open=True, high_open=True))
        set_(self, "target_length_m", checks.positive("target_length_m", self.target_length_m))
        pd0 = checks.real("pd0", self.pd0, low=0.0, high=1.0)
        pd_max = checks.real("pd_max", self.pd_max, low=0.0, high=1.0)
        if pd_max < pd0:
            raise InvalidInputError("pd_max", self.pd_max, f"must be ≥ pd0={pd0!r}")
        set_(self, "pd0", pd0)
        set_(self, "pd_max", pd_max)
        set_(self, "slope_per_px", checks.positive("slope_per_px", self.slope_per_px))
        set_(self, "n_px0", checks.non_negative("n_px0", self.n_px0))
        set_(self, "sigma_px", checks.positive("sigma_px", self.sigma_px))
        set_(self, "clutter_rate", checks.non_negative("clutter_rate", self.clutter_rate))
        checks.boolean("gimballed", self.gimballed)

    # ----- geometry --------------------------------------------------------------------------

    @property
    def meas_dim(self) -> int:
        """Measurements are pixels ``[row, column]``."""
        return 2

    @property
    def focal_px(self) -> float:
        """Focal length ``f = (W/2) / tan(hfov/2)`` (pixels)."""
        return 0.5 * self.width_px / math.tan(0.5 * self.hfov_rad)

    @property
    def pixels_per_rad(self) -> float:
        """``W / hfov``: the pixels-per-radian factor of eq. (6)."""
        return self.width_px / self.hfov_rad

    @property
    def image_area_px2(self) -> float:
        """``W · H`` (px²)."""
        return float(self.width_px * self.height_px)

    def rotation(self, pose: FloatArray) -> FloatArray:
        """``(3, 3)`` matrix whose columns are the camera axes (right, tail, down) in the world."""
        p = _pose(pose)
        yaw = p[3]
        pitch = 0.0 if self.gimballed or p.size < 5 else p[4]
        roll = 0.0 if self.gimballed or p.size < 6 else p[5]
        cy, sy = math.cos(yaw), math.sin(yaw)
        cp, sp = math.cos(-pitch), math.sin(-pitch)  # about the left axis: + tilts the nose down
        cr, sr = math.cos(roll), math.sin(roll)
        rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
        ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
        rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
        body = rz @ ry @ rx  # columns: forward, left, up
        # right = −left, tail = −forward, down = −up
        return np.asarray(np.column_stack([-body[:, 1], -body[:, 0], -body[:, 2]]))

    def project(self, pose: FloatArray, positions: FloatArray) -> tuple[FloatArray, BoolArray]:
        """Noise-free pixels ``(N, 2)`` ``[row, col]`` of ground points, and whether each point is
        in front of the camera (``Z_c > 0``; pixels of the others are NaN)."""
        p = _pose(pose)
        xy = _ground("positions", positions)
        rel = np.column_stack([xy - p[:2], np.full(xy.shape[0], -p[2])])
        cam = rel @ self.rotation(p)
        front = cam[:, 2] > 1e-9
        depth = np.where(front, cam[:, 2], np.nan)
        f = self.focal_px
        pix = np.column_stack([0.5 * self.height_px + f * cam[:, 1] / depth,
                               0.5 * self.width_px + f * cam[:, 0] / depth])
        return pix, np.asarray(front)

    def in_image(self, pixels: FloatArray) -> BoolArray:
        """``(k,)`` whether each ``[row, col]`` lies in the image (edges included)."""
        z = np.asarray(pixels, dtype=np.float64)
        with np.errstate(invalid="ignore"):
            ok = ((z[:, 0] >= 0.0) & (z[:, 0] <= self.height_px)
                  & (z[:, 1] >= 0.0) & (z[:, 1] <= self.width_px))
        return np.asarray(ok)

    def footprint(self, pose: FloatArray) -> FloatArray:
        """``(4, 2)`` ground corners of the image (clockwise from the top-left pixel corner)."""
        w, h = float(self.width_px), float(self.height_px)
        corners = np.array([[0.0, 0.0], [0.0, w], [h, w], [h, 0.0]])
        return self.to_position(pose, corners)

    # ----- detection model (eqs. 6–7) --------------------------------------------------------

    def pixels_on_target(self, pose: FloatArray, positions: FloatArray) -> FloatArray:
        """``(N,)`` pixels on target ``n_px``, eq. (6)."""
        p = _pose(pose)
        xy = _ground("positions", positions)
        d = np.sqrt(np.sum((xy - p[:2]) ** 2, axis=1) + p[2] ** 2)
        return np.asarray(self.pixels_per_rad * np.arctan(self.target_length_m / d))

    def detection_probability(self, pose: FloatArray, positions: FloatArray) -> FloatArray:
        """``(N,)`` ``p_d(x | q)``: logistic in pixels on target (eq. 7), 0 outside the image."""
        n_px = self.pixels_on_target(pose, positions)
        logistic = 0.5 * (1.0 + np.tanh(0.5 * self.slope_per_px * (n_px - self.n_px0)))
        pd = self.pd0 + (self.pd_max - self.pd0) * logistic
        pix, front = self.project(pose, positions)
        return np.where(front & self.in_image(pix), pd, 0.0)

    def detection_probabilities(self, poses: FloatArray, positions: FloatArray) -> FloatArray:
        """``(K, N)`` :meth:`detection_probability` for ``K`` poses at once.

        A gimballed camera is vectorised over blocks of poses, with the costly arctan and tanh
        evaluated only for points inside each image; a tilting camera loops over the poses.
        """
        q_all = np.asarray(poses, dtype=np.float64)
        if q_all.ndim != 2 or not 4 <= q_all.shape[1] <= 6 or not np.all(np.isfinite(q_all)):
            raise InvalidInputError("poses", poses, "must be a finite (K, 4..6) array")
        if np.any(q_all[:, 2] <= 0.0):
            raise InvalidInputError("poses", poses, "every camera height z must be > 0 (m)")
        xy = _ground("positions", positions)
        if not self.gimballed:
            return np.array([self.detection_probability(q, xy) for q in q_all]).reshape(
                q_all.shape[0], xy.shape[0])
        out = np.zeros((q_all.shape[0], xy.shape[0]))
        px, py, f = xy[None, :, 0], xy[None, :, 1], self.focal_px
        for s in range(0, q_all.shape[0], 16):  # 16 poses at a time stay in cache
            q = q_all[s:s + 16]
            dx, dy = px - q[:, 0:1], py - q[:, 1:2]
            cy, sy, inv = np.cos(q[:, 3:4]), np.sin(q[:, 3:4]), f / q[:, 2:3]
            ok = (np.abs((dx * sy - dy * cy) * inv) <= 0.5 * self.width_px) & (
                np.abs((dx * cy + dy * sy) * inv) <= 0.5 * self.height_px)
            k, j = np.nonzero(ok)
            d = np.sqrt(dx[k, j] ** 2 + dy[k, j] ** 2 + q[k, 2] ** 2)
            n_px = self.pixels_per_rad * np.arctan(self.target_length_m / d)
            out[s + k, j] = self.pd0 + (self.pd_max - self.pd0) * 0.5 * (
                1.0 + np.tanh(0.5 * self.slope_per_px * (n_px - self.n_px0)))
        return out

    # ----- measurement model (eq. 8) ---------------------------------------------------------

    def likelihood(self, pose: FloatArray, measurements: FloatArray,
                   positions: FloatArray) -> FloatArray:
        """``(k, N)`` densities ``N(z_i; [r_x, c_x], σ² I)`` (px⁻²); 0 behind the camera."""
        z = np.asarray(measurements, dtype=np.float64).reshape(-1, 2)
        pix, front = self.project(pose, positions)
        pix = np.where(front[:, None], pix, 0.0)
        s2 = self.sigma_px**2
        dr = z[:, 0:1] - pix[None, :, 0]
        dc = z[:, 1:2] - pix[None, :, 1]
        out = np.exp((dr * dr + dc * dc) * (-0.5 / s2)) * (1.0 / (2.0 * math.pi * s2))
        out[:, ~front] = 0.0
        return np.asarray(out)

    def clutter_intensity(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """``(k,)`` clutter PHD ``clutter_rate / (W H)`` inside the image, 0 outside."""
        z = np.asarray(measurements, dtype=np.float64).reshape(-1, 2)
        return np.where(self.in_image(z), self.clutter_rate / self.image_area_px2, 0.0)

    def to_position(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """``(k, 2)`` ground points seen at the pixels: the ray through each pixel meets ``z = 0``.

        Rays less than 1° below the horizon (only possible with a tilted, non-gimballed camera)
        are lowered to 1° so that every pixel maps to a finite point.
        """
        p = _pose(pose)
        z = np.asarray(measurements, dtype=np.float64).reshape(-1, 2)
        f = self.focal_px
        cam = np.column_stack([(z[:, 1] - 0.5 * self.width_px) / f,
                               (z[:, 0] - 0.5 * self.height_px) / f, np.ones(z.shape[0])])
        ray = cam @ self.rotation(p).T  # world directions
        horiz = np.hypot(ray[:, 0], ray[:, 1])
        down = np.maximum(-ray[:, 2], horiz * math.tan(_MIN_DEPRESSION))
        t = p[2] / down
        return np.asarray(p[:2] + t[:, None] * ray[:, :2])

    def measure(self, pose: FloatArray, positions: FloatArray,
                rng: np.random.Generator) -> tuple[FloatArray, NDArray[np.int64]]:
        """One simulated image of ground targets at ``(N, 2)`` positions.

        Returns
        -------
        (measurements, origin)
            ``(k, 2)`` pixel detections in random order (noisy detections falling off the image
            are dropped), and ``(k,)`` the index of the target behind each one (``-1``: clutter).
        """
        rng = checks.generator("rng", rng)
        pd = self.detection_probability(pose, positions)
        idx = np.flatnonzero(rng.random(pd.size) < pd)
        pix, _ = self.project(pose, np.asarray(positions, dtype=np.float64)[idx])
        det = pix + self.sigma_px * rng.standard_normal(pix.shape)
        keep = self.in_image(det)
        det, idx = det[keep], idx[keep]
        n_clutter = int(rng.poisson(self.clutter_rate))
        clutter = rng.random((n_clutter, 2)) * np.array([self.height_px, self.width_px])
        z = np.vstack([det, clutter])
        origin = np.concatenate([idx, np.full(n_clutter, -1)]).astype(np.int64)
        order = rng.permutation(z.shape[0])
        return z[order], origin[order]
