"""The reference scoring of the look-ahead tree: the plain NumPy form of eqs. 29–33 and 44
(Nguyen et al., §III-D) that :class:`~searchtrack.plan.radio.tree.Scorer` computes fused.

:func:`reference_look_ahead` draws and predicts the cloud by the documented recipe of
:mod:`~searchtrack.plan.radio.lookahead` with the motion model's NumPy propagation
(:func:`searchtrack.models.radio.motion.propagate`), second by second, and counts the particle
mass of each void disc (eq. 44) with a k-d tree of the cloud per second (:class:`TreeLookAhead`).
:class:`ReferenceScorer` expands a batch of nodes step by step: the ideal-measurement
log-likelihoods of every child (:func:`~searchtrack.plan.radio.kernels.ideal_log_likelihoods`),
the update of eqs. 29–30 in log space, ``w_i ← w_i g_i / η``, ``r ← r η / (1 − r + r η)``,
then ``D(π₂, π₁)`` (:func:`~searchtrack.plan.radio.divergences.renyi` or
:func:`~searchtrack.plan.radio.divergences.cauchy_schwarz`) on the posterior's weights. It scores
every sequence as :class:`Scorer` does (the same draws, the same rewards up to rounding) and is
what the tests compare the fused path with; a backend runs on it when handed it as its scorer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from searchtrack.core.types import FloatArray
from searchtrack.models.radio import RadioSignal
from searchtrack.plan.radio.divergences import disc_mass, label_radii
from searchtrack.plan.radio.ideal import IdealLikelihood, amplitudes
from searchtrack.plan.radio.kernels import ideal_log_likelihoods
from searchtrack.plan.radio.lookahead import LookAhead, look_ahead_arrays
from searchtrack.plan.radio.problem import RadioPlanProblem
from searchtrack.plan.radio.tree import Actions, Nodes, Scorer


def reference_look_ahead(problem: RadioPlanProblem, rng: np.random.Generator) -> LookAhead:
    """The look-ahead cloud of ``problem`` propagated by the motion model's NumPy step."""
    arrays = look_ahead_arrays(problem, rng, fused=False)
    xy, radii, total = arrays[0], arrays[-1], problem.n_poses
    trees = tuple(cKDTree(xy[t].reshape(-1, 2), balanced_tree=False, compact_nodes=False)
                  for t in range(total)) if radii.max() > 0 else ()
    return TreeLookAhead(*arrays, trees=trees)


@dataclass(frozen=True, eq=False)
class TreeLookAhead(LookAhead):
    """:class:`~searchtrack.plan.radio.lookahead.LookAhead` whose disc masses are counted with
    one k-d tree of the cloud per second (``trees``, none when ``r_min = 0``)."""

    trees: tuple[cKDTree, ...] = ()

    def disc_mass(self, second: int, centres: FloatArray,
                  radius_m: float | FloatArray) -> FloatArray:
        """As :meth:`LookAhead.disc_mass <searchtrack.plan.radio.lookahead.LookAhead.
        disc_mass>`, by the k-d trees when built, else densely."""
        k = centres.shape[0]
        n_labels, n = self.n_labels, self.n_particles
        radii = label_radii(radius_m, n_labels)
        if radii.max() <= 0.0 or k == 0:
            return np.zeros((k, n_labels))
        if not self.trees:
            return disc_mass(self.w, self.xy[second], centres, radii)
        pairs = cKDTree(centres).sparse_distance_matrix(
            self.trees[second], float(radii.max()), output_type="ndarray")
        label = pairs["j"] // n
        keep = pairs["v"] < radii[label]
        pairs, label = pairs[keep], label[keep]
        mass = np.bincount(pairs["i"] * n_labels + label,
                           weights=self.w.ravel()[pairs["j"]], minlength=k * n_labels)
        return np.asarray(mass.reshape(k, n_labels), dtype=np.float64)


def update(log_w: FloatArray, r: FloatArray, log_g: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Eqs. 29–30 in log space for ``(B, Λ, N)`` normalised log weights and ``(B, Λ)``
    existences: the posterior log weights and existences."""
    post = log_w + log_g
    peak = post.max(axis=2, keepdims=True)
    log_eta = peak[..., 0] + np.log(np.exp(post - peak).sum(axis=2))
    post -= log_eta[..., None]
    with np.errstate(divide="ignore"):
        a = np.log(r) + log_eta
        b = np.log1p(-r)
        r_new = np.exp(a - np.logaddexp(a, b))
    return post, np.where(r > 0.0, r_new, 0.0)


class ReferenceScorer(Scorer):
    """:class:`~searchtrack.plan.radio.tree.Scorer` with the reference look-ahead and
    expansion (module docstring)."""

    @staticmethod
    def predict(problem: RadioPlanProblem, rng: np.random.Generator) -> LookAhead:
        """The look-ahead cloud of ``problem`` (:func:`reference_look_ahead`)."""
        return reference_look_ahead(problem, rng)

    @staticmethod
    def table(signal: RadioSignal) -> IdealLikelihood:
        """The likelihood table of ``signal``, tabulated anew."""
        return IdealLikelihood.of(signal)

    def expand(self, nodes: Nodes, actions: Actions | None = None, *,
               posterior: bool = True) -> Nodes:
        """Every child of every node, in node order then action order (always with their
        posterior weights)."""
        act = self.primitives if actions is None else actions
        heads, paths, counts = [], [], []
        for b in range(nodes.size):
            h, p = act(nodes.pose[b])
            heads.append(h)
            paths.append(p)
            counts.append(h.size)
        parent = np.repeat(np.arange(nodes.size), counts)
        head = np.concatenate(heads)
        path = np.concatenate(paths, axis=0)                     # (C, N_p, 3)
        j = nodes.level
        n_p = path.shape[1]
        look, st = self.look, self.settings
        void = np.stack([look.void(j * n_p + s, path[:, s, :2]) for s in range(n_p)], axis=1)
        end = path[:, -1, :]
        signal = self.problem.scenario.signal
        gamma_hat = amplitudes(signal, look.estimate_xy[j], end) * look.estimated  # (C, Λ)
        log_g = ideal_log_likelihoods(signal, self.likelihood, look.xy[j * n_p + n_p - 1], end,
                                      gamma_hat, self._counts[j], self._overlap[j])
        log_w, r = update(nodes.log_w[parent], nodes.r[parent], log_g)
        reward = self.divergence(r, np.exp(log_w))
        return Nodes(end, np.concatenate([nodes.headings[parent], head[:, None]], axis=1),
                     np.concatenate([nodes.path[parent], path], axis=1),
                     np.concatenate([nodes.void[parent], void], axis=1),
                     np.concatenate([nodes.rewards[parent], reward[:, None]], axis=1),
                     log_w, r, nodes.value[parent] + st.discount**j * reward)
