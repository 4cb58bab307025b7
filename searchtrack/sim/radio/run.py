"""Recorded radio runs (paper 002): what a UAV's receiver saw, written to a file and filtered
later.

RUN.npz (NumPy ``savez``, no pickles) holds::

    frames          (K, M, L) float32  |STFT| of each measurement interval (eq. 11)
    uav_poses       (K, 3)             x, y (m) and heading (rad) at each measurement
    times_s         (K,)               measurement times t_k (s), increasing by T0
    labels          (Λ,)               the tag set: label λ of each known frequency
    frequencies_hz  (Λ,)               its baseband frequency f^(λ) (Table III)
    scenario        JSON text          the world without its truth (signal, motion, UAV,
                                       area, births): what a filter may know
    seed            the simulation seed

The truth (each tag's states, modes and offsets over time) is written apart, as JSON, so a
filter never reads it. Every field is checked on reading: its header before it is loaded (no
array may claim more bytes than the file holds, nor the file more than :data:`MAX_RUN_BYTES`),
then numeric types, shapes, finite non-negative frames, a tag set equal to the scenario's
frequencies and frames of the scenario's M × L. A run holds at most :data:`MAX_RUN_CELLS`
spectrogram cells (K · M · L).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.files import atomic_path, read_npz, write_text_atomic
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.registry import check_seed
from searchtrack.core.types import FloatArray
from searchtrack.models.radio import (
    RadioScenario,
    RadioSignal,
    RadioTruth,
    fly_heading,
    simulate_stft,
    simulate_time_domain,
    simulate_truth,
    straight_sweep_heading,
)

SIMULATORS: dict[str, Callable[..., FloatArray]] = {"stft": simulate_stft,
                                                     "time": simulate_time_domain}
"""How spectrograms are simulated: directly in the STFT domain (i.i.d. cells, the likelihood's
model) or from time-domain samples of the windows (physical, correlated neighbouring bins)."""

FIELDS = ("frames", "uav_poses", "times_s", "labels", "frequencies_hz", "scenario", "seed")
"""The arrays of a RUN.npz, all required."""

MAX_RUN_CELLS = 2**27
"""Most spectrogram cells K · M · L a run may hold (512 MiB as float32; the paper's 400 s run
holds 11.4 million)."""

MAX_RUN_BYTES = 2**30
"""Largest RUN.npz read, and most bytes its arrays may declare together."""

_KINDS = {"frames": "fiu", "uav_poses": "fiu", "times_s": "fiu", "labels": "iu",
          "frequencies_hz": "fiu", "scenario": "U", "seed": "iu"}
"""The NumPy dtype kinds each field may have: numbers (float or integer), integers, text."""

_KIND_NAMES = {"fiu": "numbers", "iu": "integers", "U": "text"}


def check_run_size(scenario: RadioScenario, source: str | None = None) -> None:
    """:class:`InvalidInputError` naming ``duration_s`` (and ``source``, the scenario's file)
    unless a run of ``scenario`` holds at most :data:`MAX_RUN_CELLS` spectrogram cells."""
    sig = scenario.signal
    cells = scenario.n_steps * sig.frames * sig.fft_size
    if cells > MAX_RUN_CELLS:
        where = f" (in {source})" if source else ""
        raise InvalidInputError("duration_s", scenario.duration_s, f"a run of {scenario.n_steps} "
                                f"intervals of {sig.frames}×{sig.fft_size} frames would hold "
                                f"{cells} cells, above the {MAX_RUN_CELLS} a run may hold{where}")


@dataclass(frozen=True, eq=False)
class RadioRun:
    """A recorded run: the world a filter may know, the frames and the UAV's poses."""

    scenario: RadioScenario
    frames: NDArray[np.floating]
    uav_poses: FloatArray
    times_s: FloatArray
    seed: int = 0

    def __post_init__(self) -> None:
        sig = self.scenario.signal
        frames = np.asarray(self.frames)
        k = frames.shape[0] if frames.ndim == 3 else -1
        if frames.ndim != 3 or frames.shape[1:] != (sig.frames, sig.fft_size):
            raise InvalidInputError("frames", frames.shape,
                                    f"must be (K, {sig.frames}, {sig.fft_size}): K spectrograms "
                                    "of the scenario's M frames × L bins")
        if not np.all(np.isfinite(frames)) or np.any(frames < 0):
            bad = int(np.argmax(~np.isfinite(frames).reshape(k, -1).all(axis=1)
                                | (frames < 0).reshape(k, -1).any(axis=1)))
            raise InvalidInputError("frames", f"interval {bad}",
                                    "magnitudes must be finite and non-negative")
        poses = np.asarray(self.uav_poses, dtype=float)
        if poses.shape != (k, 3) or not np.all(np.isfinite(poses)):
            raise InvalidInputError("uav_poses", poses.shape,
                                    f"must be ({k}, 3) finite x, y, heading rows, one per frame")
        times = np.asarray(self.times_s, dtype=float)
        if times.shape != (k,) or not np.all(np.isfinite(times)) or (
                k > 1 and np.any(np.diff(times) <= 0)):
            raise InvalidInputError("times_s", times.shape,
                                    f"must be {k} finite increasing times, one per frame")
        check_seed(self.seed)
        object.__setattr__(self, "frames", frames)
        object.__setattr__(self, "uav_poses", poses)
        object.__setattr__(self, "times_s", times)

    @property
    def n_steps(self) -> int:
        """Number of measurement intervals ``K``."""
        return int(self.frames.shape[0])


def _public(scenario: RadioScenario) -> RadioScenario:
    """``scenario`` without its truth (the tags)."""
    return dataclasses.replace(scenario, tags=())


def simulate_run(scenario: RadioScenario, seed: int, *,
                 measurement: str = "stft") -> tuple[RadioRun, RadioTruth]:
    """Fly the straight diagonal sweep of Exp. 2 over ``scenario`` and record every interval's
    spectrogram (``measurement``: ``"stft"`` direct, ``"time"`` from time-domain windows).

    The run may hold at most :data:`MAX_RUN_CELLS` cells (:func:`check_run_size`). A stop
    request (Ctrl-C) ends it between intervals: the run and its truth then hold the intervals
    done."""
    seed = check_seed(seed)
    if measurement not in SIMULATORS:
        raise InvalidInputError("measurement", measurement, f"must be one of {list(SIMULATORS)}")
    check_run_size(scenario)
    streams = np.random.SeedSequence(seed).spawn(2)
    truth = simulate_truth(scenario, np.random.default_rng(streams[0]))
    rng = np.random.default_rng(streams[1])
    simulate = SIMULATORS[measurement]
    uav, sig = scenario.uav, scenario.signal
    pose = np.array([*uav.start_xy, uav.start_heading], dtype=float)
    n = scenario.n_steps
    frames = np.empty((n, sig.frames, sig.fft_size), dtype=np.float32)
    poses = np.empty((n, 3))
    done = 0
    for k in range(min(n, truth.times_s.size)):
        if stop_requested():
            break
        heading = straight_sweep_heading(uav, pose, scenario.area_m)
        pose = fly_heading(uav, pose, heading, uav.step_s)[-1]
        frames[k] = spectrogram(sig, truth, k, pose, simulate, rng)
        poses[k] = pose
        done = k + 1
    run = RadioRun(_public(scenario), frames[:done], poses[:done],
                   truth.times_s[:done].copy(), seed)
    if done < truth.times_s.size:
        truth = RadioTruth(**{f.name: getattr(truth, f.name)[:done]
                              for f in dataclasses.fields(truth)})
    return run, truth


def spectrogram(signal: RadioSignal, truth: RadioTruth, k: int, pose: FloatArray,
                simulate: Callable[..., FloatArray], rng: np.random.Generator) -> FloatArray:
    """The ``(M, L)`` spectrogram of measurement ``k`` (row ``k`` of the truth) from ``pose``."""
    labels, xy = truth.positions(k)
    return simulate(signal, xy, labels, truth.taus_s[k, labels], pose, rng)


def write_run(run: RadioRun, path: str | Path) -> Path:
    """Write ``run`` to ``path`` (RUN.npz) atomically."""
    sig = run.scenario.signal
    with atomic_path(path) as temp, temp.open("wb") as fh:
        np.savez(fh, frames=run.frames.astype(np.float32), uav_poses=run.uav_poses,
                 times_s=run.times_s, labels=np.arange(sig.n_labels),
                 frequencies_hz=np.asarray(sig.frequencies_hz, dtype=float),
                 scenario=np.array(json.dumps(run.scenario.to_dict())),
                 seed=np.array(run.seed))
    return Path(path)


def read_run(path: str | Path) -> RadioRun:
    """Read a RUN.npz written by :func:`write_run` (or by hand, with the same fields).

    Raises
    ------
    ParseError
        Not a readable ``.npz`` (:func:`~searchtrack.core.files.read_npz`: also an array whose
        header claims more than the file holds), larger than :data:`MAX_RUN_BYTES`, a field
        missing or unknown, of the wrong type, or a value that fails its check (the message
        names the field).
    """
    p = Path(path)
    arrays = read_npz(p, max_bytes=MAX_RUN_BYTES)
    missing = [f for f in FIELDS if f not in arrays]
    unknown = sorted(set(arrays) - set(FIELDS))
    if missing or unknown:
        field = (missing or unknown)[0]
        raise ParseError(p, None, field, f"missing fields {missing}" if missing
                         else f"unknown fields {unknown} (known: {list(FIELDS)})")
    for name, kinds in _KINDS.items():
        if arrays[name].dtype.kind not in kinds:
            raise ParseError(p, None, name,
                             f"must hold {_KIND_NAMES[kinds]}, not {arrays[name].dtype}")
    if arrays["scenario"].shape != ():
        raise ParseError(p, None, "scenario", "must be one JSON text")
    try:
        scenario = RadioScenario.from_dict(json.loads(str(arrays["scenario"])),
                                           source=f"{p} scenario")
    except json.JSONDecodeError as exc:
        raise ParseError(p, None, "scenario", f"not JSON ({exc.msg})") from None
    except InvalidInputError as exc:
        raise ParseError(p, None, f"scenario.{exc.field}", exc.reason) from None
    except (RecursionError, ValueError) as exc:
        raise ParseError(p, None, "scenario", f"not valid JSON ({exc})") from None
    sig = scenario.signal
    labels, freqs = arrays["labels"], arrays["frequencies_hz"]
    if labels.shape != (sig.n_labels,) or not np.array_equal(labels, np.arange(sig.n_labels)):
        raise ParseError(p, None, "labels", f"the tag set must be labels 0..{sig.n_labels - 1}, "
                         f"one per frequency of the scenario, not {labels.tolist()}")
    if freqs.shape != (sig.n_labels,) or not np.allclose(freqs, sig.frequencies_hz):
        raise ParseError(p, None, "frequencies_hz",
                         f"{freqs.tolist()} does not match the scenario's tag frequencies "
                         f"{list(sig.frequencies_hz)}")
    try:
        seed = int(arrays["seed"])
        return RadioRun(scenario, arrays["frames"], arrays["uav_poses"], arrays["times_s"],
                        seed)
    except (InvalidInputError, TypeError, ValueError) as exc:
        field = exc.field if isinstance(exc, InvalidInputError) else "seed"
        raise ParseError(p, None, field, str(exc)) from None


def truth_json(truth: RadioTruth) -> dict[str, Any]:
    """The truth as JSON: times, and per tag its states ``[px, vx, py, vy]``, mode (0 WD, 1 CV)
    and offset τ per step (``null`` while absent)."""
    tags = []
    for lab in range(truth.alive.shape[1]):
        alive = truth.alive[:, lab]
        tags.append({
            "label": lab,
            "states": [[round(float(v), 4) for v in s] if a else None
                       for s, a in zip(truth.states[:, lab], alive, strict=True)],
            "modes": [int(m) if a else None for m, a in zip(truth.modes[:, lab], alive,
                                                             strict=True)],
            "tau_s": [round(float(t), 6) if a else None
                      for t, a in zip(truth.taus_s[:, lab], alive, strict=True)]})
    return {"times_s": [float(t) for t in truth.times_s], "tags": tags}


def write_truth(truth: RadioTruth, path: str | Path) -> Path:
    """Write :func:`truth_json` to ``path`` atomically."""
    return write_text_atomic(path, json.dumps(truth_json(truth)) + "\n")
