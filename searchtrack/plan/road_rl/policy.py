"""A trained road-search policy evaluated with NumPy (Moore et al. 2021, §4.3).

Training needs a deep-learning stack (the ``rl`` extra: Stable-Baselines3 PPO on PyTorch); flying
a policy does not. :class:`RoadPolicy` holds the actor network as plain arrays, loaded from a
small ``.npz`` file: dense layers ``x ← act(W x + b)`` with ``tanh`` or ``relu`` between them
and linear logits at the end, over the observation of
:class:`~searchtrack.plan.road_rl.features.RoadFeatures`. The action is the index ``k`` of the
road to take among those leaving the UAV's node (``k`` modulo its degree, so every action is
valid); in flight the policy acts greedily (the most probable action).

The file also stores the feature signature the policy was trained with (map size, targets, bins,
...); loading it against other features is refused with the differing entries named. Reading a
file checks every part of it (its ``meta`` JSON field by field, then each layer's arrays) and
names the file and the part at fault.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.files import atomic_path, read_npz
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.belief import RoadParticleBelief
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.plan.road_rl.features import RoadFeatures

ACTIVATIONS = ("tanh", "relu")

FEATURE_KEYS = ("n_targets", "n_uavs", "bins_per_edge", "gain", "include_map", "road_values")
"""The :class:`RoadFeatures` settings a policy's signature records."""

MAX_POLICY_BYTES = 64 * 2**20
"""Largest policy file read (bytes)."""

MAX_UNPACKED_BYTES = 256 * 2**20
"""Most bytes a policy file's arrays may unpack to."""

MAX_LAYERS = 64
"""Most layers a policy file may declare."""

META_KEYS = ("activation", "layers", "signature")
"""The fields of a policy file's ``meta`` JSON object."""

SIGNATURE_TYPES: dict[str, str] = {
    "n_nodes": "count", "n_edges": "count", "size": "count", "n_targets": "positive",
    "n_uavs": "positive", "bins_per_edge": "positive", "total_length_m": "number",
    "gain": "number", "include_map": "bool", "road_values": "bool"}
"""Each signature entry a policy file may record, and its kind: an integer ≥ 0 (``count``) or
≥ 1 (``positive``), a finite number ≥ 0, or a boolean."""


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
        """Read a policy written by :meth:`save`, checking every part of the file.

        Raises
        ------
        ParseError
            Naming the file and, where one is at fault, the ``meta`` field (``meta.layers``,
            ``meta.signature.n_targets``, ...) or array (``w1``): missing, too big, not an
            ``.npz`` archive, corrupt, or a part missing, unknown or ill-typed.
        """
        p = Path(path)
        if not p.is_file():
            raise ParseError(p, None, None, "no such policy file")
        if p.stat().st_size > MAX_POLICY_BYTES:
            raise ParseError(p, None, None, f"larger than {MAX_POLICY_BYTES // 2**20} MiB")
        try:
            data = read_npz(p, max_bytes=MAX_UNPACKED_BYTES)
        except ParseError as exc:
            raise ParseError(p, None, exc.field, f"not a policy file: {exc.reason}") from None
        names = set(data)
        meta = _meta(p, data.get("meta"))
        n = meta["layers"]
        wanted = {"meta"} | {f"{x}{i}" for x in "wb" for i in range(n)}
        odd = sorted(wanted - names) + sorted(names - wanted)
        if odd:
            raise ParseError(p, None, odd[0], f"not a policy file: "
                             f"{'missing' if odd[0] in wanted else 'unknown'} array (a "
                             f"policy of {n} layers has w0..w{n - 1} and b0..b{n - 1})")
        weights = tuple(_layer(p, data, f"w{i}", 2) for i in range(n))
        biases = tuple(_layer(p, data, f"b{i}", 1) for i in range(n))
        try:
            return cls(weights, biases, meta["activation"], meta["signature"])
        except InvalidInputError as exc:
            raise ParseError(p, None, exc.field, exc.reason) from None


def _meta(path: Path, raw: Any) -> dict[str, Any]:
    """The checked ``meta`` object of a policy file: ``layers`` (1…MAX_LAYERS), ``activation``
    (default ``"tanh"``) and ``signature`` (``None`` or entries of :data:`SIGNATURE_TYPES`)."""
    if raw is None:
        raise ParseError(path, None, "meta", "missing array: a policy file has a meta JSON text")
    if raw.ndim != 0 or raw.dtype.kind not in "US" or raw.nbytes > 2**20:
        raise ParseError(path, None, "meta", "must be one JSON text of at most 1 MiB")
    try:
        meta = json.loads(str(raw.item() if raw.dtype.kind == "U" else raw.item().decode()))
    except (ValueError, UnicodeDecodeError, RecursionError):
        raise ParseError(path, None, "meta", "is not valid JSON") from None
    if not isinstance(meta, dict):
        raise ParseError(path, None, "meta", f"must be a JSON object, got {type(meta).__name__}")
    unknown = sorted(set(meta) - set(META_KEYS))
    if unknown:
        raise ParseError(path, None, f"meta.{unknown[0]}",
                         f"unknown field; expected {list(META_KEYS)}")
    layers = meta.get("layers")
    if (isinstance(layers, bool) or not isinstance(layers, int)
            or not 1 <= layers <= MAX_LAYERS):
        raise ParseError(path, None, "meta.layers", f"must be an integer in [1, {MAX_LAYERS}], "
                         f"got {layers!r:.40}")
    activation = meta.get("activation", "tanh")
    if activation not in ACTIVATIONS:
        raise ParseError(path, None, "meta.activation", f"must be one of {list(ACTIVATIONS)}, "
                         f"got {activation!r:.40}")
    return {"layers": layers, "activation": activation,
            "signature": _signature(path, meta.get("signature"))}


def _signature(path: Path, raw: Any) -> dict[str, int | float | bool] | None:
    """A policy file's checked signature (``None`` when it records none)."""
    if raw is None:
        return None
    if not isinstance(raw, dict):
        raise ParseError(path, None, "meta.signature", "must be a JSON object or null, got "
                         f"{type(raw).__name__}")
    out: dict[str, int | float | bool] = {}
    for key, value in raw.items():
        kind = SIGNATURE_TYPES.get(key)
        field = f"meta.signature.{key}"
        if kind is None:
            raise ParseError(path, None, field, f"unknown entry; expected {list(SIGNATURE_TYPES)}")
        if kind == "bool":
            ok = isinstance(value, bool)
        elif kind == "number":
            ok = (isinstance(value, (int, float)) and not isinstance(value, bool)
                  and math.isfinite(value) and value >= 0)
        else:
            ok = (isinstance(value, int) and not isinstance(value, bool)
                  and value >= (1 if kind == "positive" else 0))
        if not ok:
            wanted = {"bool": "true or false", "number": "a finite number ≥ 0",
                      "count": "an integer ≥ 0", "positive": "an integer ≥ 1"}[kind]
            raise ParseError(path, None, field, f"must be {wanted}, got {value!r:.40}")
        out[key] = value
    return out


def _layer(path: Path, data: Any, name: str, ndim: int) -> FloatArray:
    """Array ``name`` of a policy file as float64: real numbers, ``ndim`` dimensions."""
    arr = data[name]
    if arr.dtype.kind not in "fiu" or arr.ndim != ndim or arr.size == 0:
        raise ParseError(path, None, name, f"must be a non-empty {ndim}-D array of real numbers, "
                         f"got {arr.dtype} of shape {arr.shape}")
    return np.asarray(arr, dtype=np.float64)


def policy_for(roads: DirectedRoads, policy: RoadPolicy) -> RoadFeatures:
    """The features ``policy`` was trained with, on ``roads`` (checked).

    Raises
    ------
    InvalidInputError
        If the policy's signature does not record ``n_targets`` (field ``signature``: the
        features cannot be rebuilt without it), or the features do not match the policy.
    """
    sig = policy.signature or {}
    if "n_targets" not in sig:
        raise InvalidInputError("signature", policy.signature, "records no n_targets: the "
                                "features the policy was trained with are unknown")
    given = {k: sig[k] for k in FEATURE_KEYS if k in sig}  # the rest: RoadFeatures' defaults
    features = RoadFeatures(roads, **given)  # type: ignore[arg-type]
    policy.check_features(features)
    return features
