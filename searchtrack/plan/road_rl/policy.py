"""A trained road-search policy evaluated with NumPy (Moore et al. 2021, §4.3).

Training needs a deep-learning stack (the ``rl`` extra: Stable-Baselines3 PPO on PyTorch); flying
a policy does not. :class:`RoadPolicy` holds the actor network as plain arrays, loaded from a
small ``.npz`` file: dense layers ``x ← act(W x + b)`` with ``tanh`` or ``relu`` between them
and linear logits at the end, over the observation of
:class:`~searchtrack.plan.road_rl.features.RoadFeatures`. The action is the index ``k`` of the
road to take among those leaving the UAV's node (``k`` modulo its degree, so every action is
valid); in flight the policy acts greedily (the most probable action).

The file also stores the feature signature the policy was trained with (map size, targets, bins,
...); loading it against other features is refused with the differing entries named.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.files import atomic_path
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.belief import RoadParticleBelief
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.plan.road_rl.features import RoadFeatures

ACTIVATIONS = ("tanh", "relu")

FEATURE_KEYS = ("n_targets", "n_uavs", "bins_per_edge", "gain", "include_map", "road_values")
"""The :class:`RoadFeatures` settings a policy's signature records."""

MAX_POLICY_BYTES = 64 * 2**20


@dataclass(frozen=True, eq=False)
class RoadPolicy:
    """A dense actor network: ``weights[i]`` is ``(out, in)``, ``biases[i]`` ``(out,)``.

    Parameters
    ----------
    weights, biases
        The layers, the last one giving the action logits.
    activation
        Between hidden layers: ``"tanh"`` or ``"relu"``.
    signature
        The :meth:`RoadFeatures.signature` the policy was trained with.
    """

    weights: tuple[FloatArray, ...]
    biases: tuple[FloatArray, ...]
    activation: str = "tanh"
    signature: dict[str, int | float | bool] | None = None

    def __post_init__(self) -> None:
        if not self.weights or len(self.weights) != len(self.biases):
            raise InvalidInputError("weights", len(self.weights),
                                    f"need one bias per layer ({len(self.biases)} given), ≥ 1")
        if self.activation not in ACTIVATIONS:
            raise InvalidInputError("activation", self.activation, f"must be in {ACTIVATIONS}")
        width = self.weights[0].shape[1]
        for i, (w, b) in enumerate(zip(self.weights, self.biases, strict=True)):
            if w.ndim != 2 or b.shape != (w.shape[0],) or w.shape[1] != width:
                raise InvalidInputError(f"weights[{i}]", w.shape,
                                        f"must be (out, {width}) with a bias of (out,)")
            if not (np.all(np.isfinite(w)) and np.all(np.isfinite(b))):
                raise InvalidInputError(f"weights[{i}]", "non-finite", "must be finite")
            width = w.shape[0]

    @property
    def n_inputs(self) -> int:
        """Length of the observation."""
        return int(self.weights[0].shape[1])

    @property
    def n_actions(self) -> int:
        """Number of actions (logits)."""
        return int(self.weights[-1].shape[0])

    def logits(self, obs: FloatArray) -> FloatArray:
        """Action logits of one observation ``(n_inputs,)`` or a batch ``(k, n_inputs)``."""
        x = np.asarray(obs, dtype=np.float64)
        if x.shape[-1] != self.n_inputs:
            raise InvalidInputError("obs", x.shape, f"needs {self.n_inputs} features")
        for i, (w, b) in enumerate(zip(self.weights, self.biases, strict=True)):
            x = x @ w.T + b
            if i < len(self.weights) - 1:
                x = np.tanh(x) if self.activation == "tanh" else np.maximum(x, 0.0)
        return x

    def act(self, obs: FloatArray) -> int:
        """The most probable action (lowest index on ties)."""
        return int(np.argmax(self.logits(obs)))

    def check_features(self, features: RoadFeatures) -> None:
        """Raise :class:`InvalidInputError` unless ``features`` match the training ones."""
        have = features.signature()
        if self.signature is not None:
            diff = {k: (v, have.get(k)) for k, v in self.signature.items() if have.get(k) != v}
            if diff:
                raise InvalidInputError("policy", diff, "was trained for other features "
                                        "(trained, here)")
        if features.size != self.n_inputs:
            raise InvalidInputError("policy", self.n_inputs,
                                    f"takes {self.n_inputs} features, these give {features.size}")

    def choose(self, features: RoadFeatures, belief: RoadParticleBelief, uav_xy: FloatArray,
               node: int, leaving: IntArray) -> int:
        """The directed edge to take from ``node`` (``leaving``: the edges leaving it, in order)."""
        if leaving.size == 0:
            raise InvalidInputError("node", node, "has no road leaving it")
        return int(leaving[self.act(features.observe(belief, uav_xy, node)) % leaving.size])

    def save(self, path: str | Path) -> Path:
        """Write the policy as ``.npz`` (atomically; weights in single precision, which moves a
        logit by about 1e-6)."""
        meta = json.dumps({"activation": self.activation, "layers": len(self.weights),
                           "signature": self.signature})
        arrays: dict[str, np.ndarray] = {"meta": np.array(meta)}
        arrays.update({f"w{i}": w.astype(np.float32) for i, w in enumerate(self.weights)})
        arrays.update({f"b{i}": b.astype(np.float32) for i, b in enumerate(self.biases)})
        target = Path(path)
        with atomic_path(target) as tmp, tmp.open("wb") as fh:
            np.savez_compressed(fh, allow_pickle=False, **arrays)
        return target

    @classmethod
    def load(cls, path: str | Path) -> RoadPolicy:
        """Read a policy written by :meth:`save`.

        Raises
        ------
        ParseError
            Not a policy file (missing, too big, corrupt or missing arrays).
        """
        p = Path(path)
        if not p.is_file():
            raise ParseError(p, None, None, "no such policy file")
        if p.stat().st_size > MAX_POLICY_BYTES:
            raise ParseError(p, None, None, f"larger than {MAX_POLICY_BYTES // 2**20} MiB")
        try:
            with np.load(p, allow_pickle=False) as data:
                meta = json.loads(str(data["meta"]))
                n = int(meta["layers"])
                weights = tuple(np.asarray(data[f"w{i}"], dtype=np.float64) for i in range(n))
                biases = tuple(np.asarray(data[f"b{i}"], dtype=np.float64) for i in range(n))
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise ParseError(p, None, None, f"not a policy file ({exc})") from None
        try:
            return cls(weights, biases, str(meta.get("activation", "tanh")),
                       meta.get("signature"))
        except InvalidInputError as exc:
            raise ParseError(p, None, None, str(exc)) from None


def policy_for(roads: DirectedRoads, policy: RoadPolicy) -> RoadFeatures:
    """The features ``policy`` was trained with, on ``roads`` (checked)."""
    sig = policy.signature or {}
    given = {k: sig[k] for k in FEATURE_KEYS if k in sig}  # the rest: RoadFeatures' defaults
    features = RoadFeatures(roads, **given)  # type: ignore[arg-type]
    policy.check_features(features)
    return features
