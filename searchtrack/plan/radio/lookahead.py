"""The action-independent part of one planning call: the predicted particle cloud and the
predicted ideal measurement set (Nguyen et al., §III-D, eqs. 33, 39; footnote 3).

* Draw: ``plan_particles`` per label from the belief by systematic resampling
  (:func:`~searchtrack.estimate.labelled_particles.resample`), so the prediction ``π₁`` has equal
  weights.
* Predict: the cloud is propagated second by second over the look-ahead (``H · N_p`` seconds)
  with the full motion model — kinematics, mode jumps and the ``τ`` random walk
  (:func:`~searchtrack.models.radio.motion.propagate`, by the filter's fused step
  :func:`~searchtrack.estimate.labelled_motion.propagate`, draw for draw the same) — but
  without birth or death (footnote 3): ``r`` stays that of the belief. One cloud serves every
  action sequence: the posterior ``π₂`` of a sequence is the same particles with other weights
  and existences (eq. 39).
* Ideal measurement set (PIMS, [15]): at the end of each planning interval, the labels with
  ``r > 0.5`` are estimated at their weighted mean position with the weighted mode of their pulse
  frame; the ideal measurement is the noise-free magnitude of those estimates
  (:mod:`~searchtrack.plan.radio.ideal`).

The random draws come from one generator seeded by the solve's ``seed``: the resampling offsets
first (one per label), then each second's propagation.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numba import njit

from searchtrack.core.kernel_cache import follow_callees
from searchtrack.core.types import BoolArray, FloatArray, IntArray
from searchtrack.estimate.labelled_motion import propagate
from searchtrack.estimate.labelled_particles import LabelledParticles, resample
from searchtrack.models.radio import propagate as model_propagate
from searchtrack.plan.radio.divergences import label_radii
from searchtrack.plan.radio.problem import EXISTENCE_THRESHOLD, RadioPlanProblem, keep_out_radii


@dataclass(frozen=True, eq=False)
class LookAhead:
    """The predicted cloud and ideal-measurement estimates of one planning call.

    Parameters
    ----------
    xy
        ``(T, Λ, N, 2)`` ground positions of the cloud after each second ``1..T``,
        ``T = H · N_p``.
    frames
        ``(H, Λ, N)`` pulse frames ``m(τ)`` (eq. 16) at the end of each planning interval.
    r
        ``(Λ,)`` existence probabilities of the prediction (those of the belief).
    w
        ``(Λ, N)`` particle weights of the prediction (equal).
    estimated
        ``(Λ,)`` labels in the ideal measurement set (``r > 0.5``).
    estimate_xy
        ``(H, Λ, 2)`` weighted mean positions at the end of each interval.
    estimate_frame
        ``(H, Λ)`` weighted-mode pulse frames at the end of each interval.
    radii
        ``(Λ,)`` radius of each label's void region (eq. 44):
        :func:`~searchtrack.plan.radio.problem.keep_out_radii` of the drawn cloud.
    """

    xy: FloatArray
    frames: IntArray
    r: FloatArray
    w: FloatArray
    estimated: BoolArray
    estimate_xy: FloatArray
    estimate_frame: IntArray
    radii: FloatArray

    @property
    def n_labels(self) -> int:
        """``Λ``."""
        return int(self.xy.shape[1])

    @property
    def n_particles(self) -> int:
        """``N``, particles per label."""
        return int(self.xy.shape[2])

    @cached_property
    def _columns(self) -> tuple[FloatArray, FloatArray]:
        """``(T, Λ, N)`` ground ``x`` and ``y`` of the cloud, each contiguous."""
        return (np.ascontiguousarray(self.xy[..., 0]), np.ascontiguousarray(self.xy[..., 1]))

    def disc_mass(self, second: int, centres: FloatArray,
                  radius_m: float | FloatArray) -> FloatArray:
        """``(K, Λ)`` weight of each label's particles strictly within ``radius_m`` (ground
        distance; one radius, or ``(Λ,)`` one per label) of each of ``K`` centres ``(K, 2)``,
        at look-ahead second ``second`` (0-based: the cloud after ``second + 1`` seconds); a
        label whose particles' bounding box lies beyond the radius is skipped."""
        k = centres.shape[0]
        radii = label_radii(radius_m, self.n_labels)
        out = np.zeros((k, self.n_labels))
        if radii.max() <= 0.0 or k == 0:
            return out
        x, y = self._columns
        _disc_mass(x[second], y[second], self.w,
                   np.ascontiguousarray(centres, dtype=np.float64), radii, out)
        return out

    def void(self, second: int, centres: FloatArray,
             radius_m: float | FloatArray | None = None) -> FloatArray:
        """``(K,)`` void probability ``Π_λ (1 − r_λ P_λ)`` (eq. 44) of the discs of radius
        ``radius_m`` (default: :attr:`radii`) around ``centres`` at look-ahead second
        ``second`` (0-based)."""
        if radius_m is None:
            radius_m = self.radii
        mass = self.disc_mass(second, centres, radius_m)
        return np.asarray(np.prod(1.0 - self.r * mass, axis=1), dtype=np.float64)


@njit(cache=True, error_model="numpy")
def _disc_mass(x: FloatArray, y: FloatArray, w: FloatArray, centres: FloatArray,
               radii: FloatArray, out: FloatArray) -> None:
    """``out[k, λ] = Σ_i w[λ, i] [ (x − c_x)² + (y − c_y)² < ρ_λ² ]`` for particles at ``x``,
    ``y`` ``(Λ, N)``, skipping the labels whose bounding box is farther than ``ρ_λ``."""
    n_labels, n = x.shape
    for lab in range(n_labels):
        rr = radii[lab] * radii[lab]
        if rr <= 0.0 or n == 0:
            continue
        xr, yr, wr = x[lab], y[lab], w[lab]
        lo_x, hi_x, lo_y, hi_y = xr.min(), xr.max(), yr.min(), yr.max()
        for k in range(centres.shape[0]):
            cx, cy = centres[k, 0], centres[k, 1]
            gx = max(lo_x - cx, 0.0, cx - hi_x)
            gy = max(lo_y - cy, 0.0, cy - hi_y)
            if gx * gx + gy * gy >= rr:
                continue
            s = 0.0
            for i in range(n):
                dx = xr[i] - cx
                dy = yr[i] - cy
                s += wr[i] if dx * dx + dy * dy < rr else 0.0
            out[k, lab] = s


def look_ahead(problem: RadioPlanProblem, rng: np.random.Generator) -> LookAhead:
    """Draw, predict and estimate the look-ahead cloud of ``problem`` (module docstring)."""
    return LookAhead(*look_ahead_arrays(problem, rng))


LookAheadArrays = tuple[FloatArray, IntArray, FloatArray, FloatArray, BoolArray, FloatArray,
                        IntArray, FloatArray]
"""The fields of a :class:`LookAhead`, in order, read-only."""


def look_ahead_arrays(problem: RadioPlanProblem, rng: np.random.Generator, *,
                      fused: bool = True) -> LookAheadArrays:
    """The fields of the look-ahead of ``problem``, the cloud propagated by the filter's fused
    step (:func:`~searchtrack.estimate.labelled_motion.propagate`) or, with ``fused`` false, by
    the motion model's NumPy step (:func:`searchtrack.models.radio.motion.propagate`): the same
    draws either way."""
    sc = problem.scenario
    st = problem.settings
    n_p = problem.steps_per_interval
    total = problem.n_poses
    drawn = resample(problem.belief, rng, st.plan_particles)
    x, mode, tau = drawn.x, drawn.mode, drawn.tau
    w = drawn.w
    r = np.array(problem.belief.r, dtype=np.float64)
    radii = keep_out_radii(x[:, :, ::2], r, st)
    n_labels, n = w.shape
    xy = np.empty((total, n_labels, n, 2))
    frames = np.empty((st.horizon, n_labels, n), dtype=np.int64)
    est_xy = np.empty((st.horizon, n_labels, 2))
    est_frame = np.empty((st.horizon, n_labels), dtype=np.int64)
    buffers = ((x, mode, tau), (np.empty_like(x), np.empty_like(mode), np.empty_like(tau)))
    for t in range(total):
        if fused:
            x, mode, tau = propagate(sc.motion, x, mode, tau, rng, out=buffers[(t + 1) % 2])
        else:
            x, mode, tau = model_propagate(sc.motion, x, mode, tau, rng)
        xy[t] = x[:, :, ::2]
        if (t + 1) % n_p == 0:
            j = (t + 1) // n_p - 1
            cloud = LabelledParticles(x, mode, tau, w, r)
            frames[j] = sc.signal.frame_of(tau)
            est_xy[j] = cloud.mean_xy()
            est_frame[j] = cloud.frame_mode(sc.signal)
    arrays = (xy, frames, r, w, r > EXISTENCE_THRESHOLD, est_xy, est_frame, radii)
    for arr in arrays:
        arr.setflags(write=False)
    return arrays


follow_callees(__name__, globals())
