"""The look-ahead tree of action sequences, scored in batches (Nguyen et al., eqs. 29–33, 44).

A node at level ``j`` is a prefix of ``j`` primitives. Expanding a batch of nodes flies every
primitive from each node's last pose (:func:`~searchtrack.models.radio.uav.primitives`, all
nodes at once: :func:`batch_primitives`) and, for each child:

* the void probability of the predicted cloud at each of its ``N_p`` poses (eq. 44; the
  prediction ``π₁`` keeps ``r`` and equal weights);
* the update of the parent's posterior ``π₂`` by the ideal measurement at the interval's last
  pose (eqs. 29–30: ``w_i ← w_i g_i / η``, ``r ← r η / (1 − r + r η)``, ``η = Σ_i w_i g_i``;
  :mod:`~searchtrack.plan.radio.ideal`), so a prefix's update is shared by all its sequences;
* the reward ``D(π₂, π₁)`` (eq. 33) and the discounted sum so far (eq. 32).

The reward's densities hold the existences of
:func:`~searchtrack.plan.radio.problem.reward_existence`: a label not yet heard counts as
existing with probability ``r̃`` (``explore_existence``), so the ideal measurement's evidence of
its absence near the UAV (its particles' ``g_i = e^{−n_i γ_i² E_λ}``) is information worth
flying for; the void constraint reads the belief's ``r``.

Work is vectorised over the children and the particles: the update and the reward in fused
passes over ``(children, Λ, N)`` blocks (:func:`~searchtrack.plan.radio.fused.score_children`),
each child reading its parent's posterior by index.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from searchtrack.core.angles import wrap_angle
from searchtrack.core.types import BoolArray, FloatArray, IntArray
from searchtrack.models.radio import RadioSignal, UavModel, primitives
from searchtrack.models.radio.uav import OUTSIDE_TIE_M, fly_toward
from searchtrack.plan.radio.divergences import cauchy_schwarz, renyi
from searchtrack.plan.radio.fused import score_children
from searchtrack.plan.radio.ideal import (
    IdealLikelihood,
    amplitudes,
    frame_counts,
    frame_overlap,
    likelihood_table,
)
from searchtrack.plan.radio.lookahead import LookAhead, look_ahead
from searchtrack.plan.radio.problem import RadioPlan, RadioPlanProblem, reward_existence

#: ``pose (3,) → (headings (A,), paths (A, N_p, 3))``: the actions available from a pose.
Actions = Callable[[FloatArray], tuple[FloatArray, FloatArray]]

#: Largest ``children · Λ · N`` one expansion works on (the callers split larger batches).
BATCH_ELEMENTS = 1 << 20


@dataclass(frozen=True, eq=False)
class Nodes:
    """A batch of ``B`` tree nodes of one level ``j`` (prefixes of ``j`` primitives).

    Parameters
    ----------
    pose
        ``(B, 3)`` last pose.
    headings
        ``(B, j)`` target headings of the primitives.
    path
        ``(B, j · N_p, 3)`` poses so far.
    void
        ``(B, j · N_p)`` void probability at each pose.
    rewards
        ``(B, j)`` undiscounted rewards at each interval end.
    log_w
        ``(B, Λ, N)`` log weights of the posterior ``π₂`` (``(B, Λ, 0)`` for leaves scored
        without them).
    r
        ``(B, Λ)`` existence probabilities of ``π₂``.
    value
        ``(B,)`` discounted reward so far.
    """

    pose: FloatArray
    headings: FloatArray
    path: FloatArray
    void: FloatArray
    rewards: FloatArray
    log_w: FloatArray
    r: FloatArray
    value: FloatArray

    @property
    def size(self) -> int:
        """``B``."""
        return int(self.pose.shape[0])

    @property
    def level(self) -> int:
        """``j``, primitives per node."""
        return int(self.headings.shape[1])

    @property
    def min_void(self) -> FloatArray:
        """``(B,)`` smallest void probability along each prefix (1 at the root)."""
        if self.void.shape[1] == 0:
            return np.ones(self.size)
        return np.asarray(self.void.min(axis=1), dtype=np.float64)

    def violation(self, p_void_min: float) -> FloatArray:
        """``(B,)`` total violation ``Σ_t max(0, P_vmin − B_t)`` along each prefix (it only
        grows as a prefix is extended, so it bounds its sequences' from below)."""
        return np.asarray(np.maximum(0.0, p_void_min - self.void).sum(axis=1),
                          dtype=np.float64)

    def take(self, index: IntArray | BoolArray | slice) -> Nodes:
        """The nodes at ``index``, in that order."""
        return Nodes(*(a[index] for a in (self.pose, self.headings, self.path, self.void,
                                           self.rewards, self.log_w, self.r, self.value)))

    def chunks(self, per_child: int) -> list[Nodes]:
        """This batch split so that each part's children hold at most :data:`BATCH_ELEMENTS`
        particle entries, ``per_child`` entries times the most children a node can have."""
        step = max(1, BATCH_ELEMENTS // max(1, per_child))
        return [self.take(slice(lo, lo + step)) for lo in range(0, self.size, step)]


class Scorer:
    """Everything one solve shares: the look-ahead cloud, the likelihood table and the rules.

    Built once per solve from ``problem`` and ``seed`` (the look-ahead draws); the backends
    only choose which nodes to :meth:`expand`.
    """

    def __init__(self, problem: RadioPlanProblem, seed: int) -> None:
        self.problem = problem
        self.settings = problem.settings
        self.look: LookAhead = self.predict(problem, np.random.default_rng(seed))
        self.likelihood = self.table(problem.scenario.signal)
        m = problem.scenario.signal.frames
        self._counts = frame_counts(self.look.frames, m)
        self._overlap = frame_overlap(self.look.frames, self.look.estimate_frame, m)
        with np.errstate(divide="ignore"):
            self._log_w1 = np.log(self.look.w)
        self.r1 = reward_existence(self.look.r, self.settings)
        """``(Λ,)`` existences of the reward's prediction ``π₁``."""

    @staticmethod
    def predict(problem: RadioPlanProblem, rng: np.random.Generator) -> LookAhead:
        """The look-ahead cloud of ``problem`` drawn from ``rng``
        (:func:`~searchtrack.plan.radio.lookahead.look_ahead`)."""
        return look_ahead(problem, rng)

    @staticmethod
    def table(signal: RadioSignal) -> IdealLikelihood:
        """The likelihood table of ``signal``, shared by the solves of that signal
        (:func:`~searchtrack.plan.radio.ideal.likelihood_table`)."""
        return likelihood_table(signal)

    @property
    def horizon(self) -> int:
        """``H``."""
        return self.settings.horizon

    @property
    def per_child(self) -> int:
        """Particle entries of one child times the most children of a node (for chunking)."""
        return self.problem.scenario.uav.n_headings * self.look.n_labels * self.look.n_particles

    def root(self) -> Nodes:
        """The root: the UAV's pose, no primitive yet, ``π₂ = π₁``."""
        return Nodes(self.problem.uav_pose[None, :].copy(), np.zeros((1, 0)),
                     np.zeros((1, 0, 3)), np.zeros((1, 0)), np.zeros((1, 0)),
                     self._log_w1[None].copy(), self.r1[None].copy(), np.zeros(1))

    def primitives(self, pose: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The action primitives from ``pose`` that stay in the area (all if none does)."""
        sc = self.problem.scenario
        return primitives(sc.uav, pose, sc.area_m)

    def divergence(self, r2: FloatArray, w2: FloatArray) -> FloatArray:
        """``(B,)`` ``D(π₂, π₁)`` of the settings' reward for posteriors ``(B, Λ)``,
        ``(B, Λ, N)``."""
        st = self.settings
        if st.reward == "cs":
            return cauchy_schwarz(self.r1, self.look.w, r2, w2, st.cs_k)
        return renyi(self.r1, self.look.w, r2, w2, st.alpha)

    def children(self, poses: FloatArray,
                 actions: Actions | None = None) -> tuple[IntArray, FloatArray, FloatArray]:
        """``(parent (C,), headings (C,), paths (C, N_p, 3))`` of the actions from each of
        ``B`` poses ``(B, 3)``, pose by pose; the primitives of every pose are flown together
        (:func:`batch_primitives`)."""
        if actions is None:
            sc = self.problem.scenario
            return batch_primitives(sc.uav, poses, sc.area_m)
        heads, paths, counts = [], [], []
        for b in range(poses.shape[0]):
            h, p = actions(poses[b])
            heads.append(h)
            paths.append(p)
            counts.append(h.size)
        return (np.repeat(np.arange(poses.shape[0]), counts), np.concatenate(heads),
                np.concatenate(paths, axis=0))

    def expand(self, nodes: Nodes, actions: Actions | None = None, *,
               posterior: bool = True) -> Nodes:
        """Every child of every node, in node order then action order; ``posterior=False``
        leaves the children's weights out (``log_w`` ``(C, Λ, 0)``: leaves, never expanded)."""
        parent, head, path = self.children(nodes.pose, actions)  # path (C, N_p, 3)
        j = nodes.level
        n_p = path.shape[1]
        look, st = self.look, self.settings
        void = np.stack([look.void(j * n_p + s, path[:, s, :2]) for s in range(n_p)], axis=1)
        end = path[:, -1, :]
        signal = self.problem.scenario.signal
        gamma_hat = amplitudes(signal, look.estimate_xy[j], end) * look.estimated  # (C, Λ)
        order = st.cs_k if st.reward == "cs" else st.alpha
        scores = score_children(signal, self.likelihood, look.xy[j * n_p + n_p - 1], end,
                                gamma_hat, self._counts[j], self._overlap[j], nodes.log_w,
                                nodes.r, parent, self.r1, look.w, st.reward, order,
                                keep=posterior)
        return Nodes(end, np.concatenate([nodes.headings[parent], head[:, None]], axis=1),
                     np.concatenate([nodes.path[parent], path], axis=1),
                     np.concatenate([nodes.void[parent], void], axis=1),
                     np.concatenate([nodes.rewards[parent], scores.reward[:, None]], axis=1),
                     scores.log_w, scores.r, nodes.value[parent] + st.discount**j * scores.reward)

    def expand_all(self, nodes: Nodes, actions: Actions | None = None, *,
                   posterior: bool = True) -> Nodes:
        """:meth:`expand` in parts of bounded memory, the children joined in order."""
        parts = [self.expand(part, actions, posterior=posterior)
                 for part in nodes.chunks(self.per_child)]
        return Nodes(*(np.concatenate(arrays) for arrays in zip(
            *((p.pose, p.headings, p.path, p.void, p.rewards, p.log_w, p.r, p.value)
              for p in parts), strict=True)))

    def feasible(self, nodes: Nodes) -> BoolArray:
        """``(B,)`` whether every void probability so far exceeds ``P_vmin`` (all, when
        ``P_vmin = 0``: no constraint)."""
        p_min = self.settings.p_void_min
        return np.asarray((nodes.min_void > p_min) | (p_min <= 0.0), dtype=np.bool_)

    def plan(self, nodes: Nodes, i: int) -> RadioPlan:
        """Node ``i`` (a complete sequence) as a plan."""
        return RadioPlan(nodes.headings[i], nodes.path[i], nodes.rewards[i], nodes.void[i],
                         bool(self.feasible(nodes)[i]))



def batch_primitives(model: UavModel, poses: FloatArray,
                     area_m: tuple[float, float]) -> tuple[IntArray, FloatArray, FloatArray]:
    """:func:`~searchtrack.models.radio.uav.primitives` of ``B`` poses ``(B, 3)`` at once, the
    same element-wise arithmetic on ``(B, N_θ)`` arrays: ``(parent (C,), headings (C,),
    paths (C, n, 3))`` of the kept primitives, pose by pose, in primitive order."""
    n_headings, n = model.n_headings, model.steps_per_plan
    deltas = -np.pi + 2.0 * np.pi * np.arange(n_headings) / n_headings
    targets = wrap_angle(poses[:, 2:3] + deltas)                          # (B, A)
    x, y, heading = (np.repeat(poses[:, k:k + 1], n_headings, axis=1) for k in range(3))
    paths = fly_toward(model, x, y, heading, targets, n)
    width, height = float(area_m[0]), float(area_m[1])
    px, py = paths[..., 0], paths[..., 1]
    inside = np.all((px >= 0.0) & (px <= width) & (py >= 0.0) & (py <= height), axis=2)
    for b in np.flatnonzero(~inside.any(axis=1)):
        end_x, end_y = px[b, :, -1], py[b, :, -1]
        outside = np.hypot(np.maximum(0.0, np.maximum(-end_x, end_x - width)),
                           np.maximum(0.0, np.maximum(-end_y, end_y - height)))
        inside[b] = outside <= outside.min() + OUTSIDE_TIE_M
    parent = np.repeat(np.arange(poses.shape[0]), inside.sum(axis=1))
    return parent, targets[inside], paths[inside]
