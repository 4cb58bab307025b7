"""The radio-tag scenario of Nguyen et al. §IV-A (Tables II–IV) and its simulated ground truth.

:class:`RadioScenario` gathers the signal, the motion model, the UAV, the tags (label, birth and
death times, initial state ``[px, vx, py, vy]``, pulse offset τ, mode schedule) and the filter's
birth model (Gaussians at the four release sites, ``r_B = 10⁻⁶``, ``p_S = 0.99``).
:meth:`RadioScenario.paper` is the §7.1 set-up: four tags with ``(birth, death)`` = (1, 250),
(50, 300), (100, 350), (150, 400) s and τ = 0.1..0.4 s. All start in WD; tags 0 and 2 switch to
CV one second after birth, tags 1 and 3 stay in WD for 65 s (the rest of the paper's schedule is
only drawn in its Fig. 6): after the last scheduled switch the modes follow the Markov chain.

A scenario reads from a mapping or a TOML file with tables ``[signal]``, ``[motion]``,
``[uav]``, ``[[tags]]`` and top-level fields; missing keys take the defaults, unknown keys are
errors naming their dotted path. :func:`simulate_truth` draws the ground truth.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.core.files import read_text
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.types import BoolArray, FloatArray, IntArray
from searchtrack.models.radio.motion import TagMotion, propagate
from searchtrack.models.radio.signal import RadioSignal
from searchtrack.models.radio.uav import UavModel

#: Largest scenario file read (bytes).
MAX_SCENARIO_BYTES = 2**20
#: Most measurement intervals ``duration_s / T0`` of a scenario (28 h at the paper's T0 = 1 s).
MAX_STEPS = 100_000


def _vector(name: str, value: object, size: int) -> tuple[float, ...]:
    arr = checks.finite_array(name, value, (size,))  # type: ignore[arg-type]
    return tuple(float(v) for v in arr)


def _schedule(value: object) -> tuple[tuple[float, int], ...]:
    name = "mode_schedule"
    try:
        entries = [tuple(e) for e in value]  # type: ignore[attr-defined]
    except TypeError:
        raise InvalidInputError(name, value, "must be (seconds, mode) pairs") from None
    if not entries or any(len(e) != 2 for e in entries):
        raise InvalidInputError(name, value, "must be a non-empty sequence of (seconds, mode)")
    out = tuple((checks.non_negative(name, t), checks.count(name, m)) for t, m in entries)
    if out[0][0] != 0.0 or any(b[0] <= a[0] for a, b in itertools.pairwise(out)):
        raise InvalidInputError(name, value, "times must start at 0 and increase strictly")
    if any(m > 1 for _, m in out):
        raise InvalidInputError(name, value, "modes must be 0 (WD) or 1 (CV)")
    return out


@dataclass(frozen=True)
class TagSpec:
    """One tag of the ground truth.

    Parameters
    ----------
    label
        Its label λ (the index of its frequency).
    birth_s, death_s
        It is present at ``t_k`` when ``birth_s ≤ t_k < death_s``.
    initial_state
        ``[px, vx, py, vy]`` at its first step (m, m/s).
    tau_s
        Initial pulse offset τ (s).
    mode_schedule
        ``(seconds after birth, mode)`` pairs starting at 0: the mode is forced to the latest
        entry until the last entry's time; the Markov chain takes over after it.
    """

    label: int
    birth_s: float
    death_s: float
    initial_state: tuple[float, float, float, float]
    tau_s: float
    mode_schedule: tuple[tuple[float, int], ...] = ((0.0, 0),)

    def __post_init__(self) -> None:
        put = object.__setattr__
        put(self, "label", checks.count("label", self.label))
        put(self, "birth_s", checks.non_negative("birth_s", self.birth_s))
        put(self, "death_s", checks.real("death_s", self.death_s, low=self.birth_s,
                                         low_open=True))
        put(self, "initial_state", _vector("initial_state", self.initial_state, 4))
        put(self, "tau_s", checks.non_negative("tau_s", self.tau_s))
        put(self, "mode_schedule", _schedule(self.mode_schedule))

    def scheduled_mode(self, age_s: float) -> int | None:
        """The mode forced at ``age_s`` seconds after birth, ``None`` once the chain runs."""
        if age_s > self.mode_schedule[-1][0] + 1e-9:
            return None
        return next(m for t, m in reversed(self.mode_schedule) if t <= age_s + 1e-9)


def _paper_tags() -> tuple[TagSpec, ...]:
    to_cv, hold_wd = ((0.0, 0), (1.0, 1)), ((0.0, 0), (65.0, 0))
    return (
        TagSpec(0, 1.0, 250.0, (800.0, 0.13, 300.0, -1.44), 0.1, to_cv),
        TagSpec(1, 50.0, 300.0, (200.0, 0.18, 700.0, -2.17), 0.2, hold_wd),
        TagSpec(2, 100.0, 350.0, (1200.0, -1.94, 1000.0, 0.42), 0.3, to_cv),
        TagSpec(3, 150.0, 400.0, (900.0, 1.91, 1300.0, -2.04), 0.4, hold_wd),
    )


PAPER_TAGS = _paper_tags()
PAPER_BIRTH_MEANS = ((800.0, 0.0, 300.0, 0.0), (200.0, 0.0, 700.0, 0.0),
                     (1200.0, 0.0, 1000.0, 0.0), (900.0, 0.0, 1300.0, 0.0))

_TABLES: dict[str, type] = {"signal": RadioSignal, "motion": TagMotion, "uav": UavModel}


@dataclass(frozen=True)
class RadioScenario:
    """Signal, motion, UAV, tags and birth model of a radio-tag mission (§IV-A defaults).

    ``n_steps = round(duration_s / T0)`` measurement intervals at ``t_k = k T0``, at most
    :data:`MAX_STEPS`. The motion and UAV step must equal the signal period ``T0``; labels must
    be unique and below the number of frequencies; τ must lie in ``[0, T0)``.
    """

    signal: RadioSignal = field(default_factory=RadioSignal)
    motion: TagMotion = field(default_factory=TagMotion)
    uav: UavModel = field(default_factory=UavModel)
    tags: tuple[TagSpec, ...] = PAPER_TAGS
    area_m: tuple[float, float] = (1500.0, 1500.0)
    duration_s: float = 400.0
    birth_means: tuple[tuple[float, float, float, float], ...] = PAPER_BIRTH_MEANS
    birth_cov_diag: tuple[float, float, float, float] = (100.0, 4.0, 100.0, 4.0)
    birth_probability: float = 1e-6
    survival_probability: float = 0.99

    def __post_init__(self) -> None:
        put = object.__setattr__
        for name, kind in _TABLES.items():
            if not isinstance(getattr(self, name), kind):
                raise InvalidInputError(name, getattr(self, name), f"must be a {kind.__name__}")
        t0 = self.signal.period_s
        if not math.isclose(self.motion.period_s, t0):
            raise InvalidInputError("motion.period_s", self.motion.period_s,
                                    f"must equal the signal period {t0:g} s")
        if not math.isclose(self.uav.step_s, t0):
            raise InvalidInputError("uav.step_s", self.uav.step_s,
                                    f"must equal the signal period {t0:g} s")
        area = _vector("area_m", self.area_m, 2)
        if min(area) <= 0.0:
            raise InvalidInputError("area_m", self.area_m, "must be two positive sizes (m)")
        put(self, "area_m", area)
        x0, y0 = self.uav.start_xy
        if not (0.0 <= x0 <= area[0] and 0.0 <= y0 <= area[1]):
            raise InvalidInputError("uav.start_xy", self.uav.start_xy, "must lie in the area")
        put(self, "duration_s", checks.positive("duration_s", self.duration_s))
        steps = self.duration_s / t0
        if not steps < MAX_STEPS + 0.5:
            raise InvalidInputError("duration_s", self.duration_s, f"must span at most "
                                    f"{MAX_STEPS} measurement intervals of T0 = {t0:g} s")
        if self.n_steps < 1:
            raise InvalidInputError("duration_s", self.duration_s, "must span at least one T0")
        put(self, "tags", self._checked_tags())
        means = tuple(self.birth_means) if isinstance(self.birth_means, (list, tuple)) else ()
        if not means:
            raise InvalidInputError("birth_means", self.birth_means,
                                    "must be a non-empty sequence of [px, vx, py, vy]")
        put(self, "birth_means", tuple(_vector(f"birth_means[{i}]", m, 4)
                                       for i, m in enumerate(means)))
        cov = _vector("birth_cov_diag", self.birth_cov_diag, 4)
        if min(cov) <= 0.0:
            raise InvalidInputError("birth_cov_diag", self.birth_cov_diag, "must be positive")
        put(self, "birth_cov_diag", cov)
        for name in ("birth_probability", "survival_probability"):
            put(self, name, checks.probability(name, getattr(self, name)))

    def _checked_tags(self) -> tuple[TagSpec, ...]:
        tags = tuple(self.tags) if isinstance(self.tags, (list, tuple)) else None
        if tags is None:
            raise InvalidInputError("tags", self.tags, "must be a sequence of TagSpec")
        seen: set[int] = set()
        for i, tag in enumerate(tags):
            if not isinstance(tag, TagSpec):
                raise InvalidInputError(f"tags[{i}]", tag, "must be a TagSpec")
            if tag.label >= self.signal.n_labels or tag.label in seen:
                raise InvalidInputError(f"tags[{i}].label", tag.label, "must be unique and "
                                        f"below the {self.signal.n_labels} frequencies")
            if tag.tau_s >= self.signal.period_s:
                raise InvalidInputError(f"tags[{i}].tau_s", tag.tau_s,
                                        f"must be below the period {self.signal.period_s:g} s")
            seen.add(tag.label)
        return tags

    @property
    def n_steps(self) -> int:
        """Number of measurement intervals, ``round(duration_s / T0)``."""
        return round(self.duration_s / self.signal.period_s)

    @classmethod
    def paper(cls, noise_var_v2: float = 0.025**2) -> RadioScenario:
        """The §IV-A scenario (Tables II–IV) with receiver noise ``Σ_η = noise_var_v2`` (V²)."""
        return cls(signal=RadioSignal(noise_var_v2=noise_var_v2))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, source: str = "scenario") -> RadioScenario:
        """The scenario described by ``data`` (nested tables as in the TOML form).

        Raises
        ------
        InvalidInputError
            Naming the dotted key path (``"signal.foo"``, ``"tags[1].tau_s"``) of an unknown,
            mistyped or out-of-range entry.
        """
        _check_keys(data, "", [f.name for f in dataclasses.fields(cls)], source)
        kwargs: dict[str, Any] = dict(data)
        for name, kind in _TABLES.items():
            if name in data:
                kwargs[name] = _build(kind, data[name], name, source)
        if "tags" in data:
            tags = data["tags"]
            if not isinstance(tags, (list, tuple)):
                raise InvalidInputError("tags", tags, f"must be a list of tables (in {source})")
            kwargs["tags"] = tuple(_build(TagSpec, t, f"tags[{i}]", source)
                                   for i, t in enumerate(tags))
        try:
            return cls(**kwargs)
        except InvalidInputError as exc:
            raise InvalidInputError(exc.field, exc.value, f"{exc.reason} (in {source})") from None

    @classmethod
    def from_toml(cls, path: str | Path) -> RadioScenario:
        """The scenario in TOML file ``path``.

        Raises
        ------
        ParseError
            The file is missing, unreadable, too large or not valid TOML.
        InvalidInputError
            A key is unknown or a value is bad (naming the dotted key and the file).
        """
        p = Path(path)
        text = read_text(p, max_bytes=MAX_SCENARIO_BYTES)
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise ParseError(p, getattr(exc, "lineno", None), None,
                             f"not valid TOML: {exc}") from None
        return cls.from_dict(data, source=str(p))

    def to_dict(self) -> dict[str, Any]:
        """The scenario as nested plain data (tuples as lists); :meth:`from_dict` inverts it."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name == "tags":
                out[f.name] = [_plain(dataclasses.asdict(t)) for t in value]
            elif dataclasses.is_dataclass(value):
                out[f.name] = {g.name: _plain(getattr(value, g.name))
                               for g in dataclasses.fields(value)}
            else:
                out[f.name] = _plain(value)
        return out


def _plain(value: Any) -> Any:
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _check_keys(data: object, path: str, known: list[str], source: str) -> None:
    if not isinstance(data, Mapping):
        raise InvalidInputError(path or "scenario", data, f"must be a table (in {source})")
    for key in data:
        if key not in known:
            where = f"{path}.{key}" if path else str(key)
            raise InvalidInputError(where, data[key],
                                    f"unknown key in {source} (known here: {sorted(known)})")


def _build(kind: type, data: object, path: str, source: str) -> Any:
    """``kind(**data)``, with every error naming ``path.<field>``."""
    fields = [f for f in dataclasses.fields(kind) if f.init]
    _check_keys(data, path, [f.name for f in fields], source)
    assert isinstance(data, Mapping)
    for f in fields:
        missing = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        if missing and f.name not in data:
            raise InvalidInputError(f"{path}.{f.name}", None, f"missing (in {source})")
    try:
        return kind(**data)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{path}.{exc.field}", exc.value,
                                f"{exc.reason} (in {source})") from None
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(path, data, f"{exc} (in {source})") from None


@dataclass(frozen=True)
class RadioTruth:
    """Ground truth on the step grid ``t_k = k T0``, ``k = 1..K``, indexed by label.

    Rows are 0-based: row ``i`` is time ``times_s[i]``. Absent tags hold NaN states and
    offsets and mode ``-1``.
    """

    times_s: FloatArray
    states: FloatArray
    alive: BoolArray
    modes: NDArray[np.int8]
    taus_s: FloatArray

    def positions(self, k: int) -> tuple[IntArray, FloatArray]:
        """Labels alive at row ``k`` and their ``(n, 2)`` ground positions."""
        row = checks.count("k", k)
        if row >= self.times_s.size:
            raise InvalidInputError("k", k, f"must be below {self.times_s.size} steps")
        labels = np.flatnonzero(self.alive[row]).astype(np.int64)
        return labels, self.states[row, labels][:, [0, 2]]


def simulate_truth(scenario: RadioScenario, rng: np.random.Generator) -> RadioTruth:
    """Draw the tags' trajectories, modes and pulse offsets on the step grid.

    A tag is alive at ``t_k`` when ``birth_s ≤ t_k < death_s``; at its first step it holds its
    ``initial_state`` and ``tau_s``, then each step propagates it by :func:`propagate`
    (kinematics with the previous mode, mode jump, τ step), the mode being overridden by the
    tag's schedule while that runs. A stop request (Ctrl-C) ends the draw early: the truth then
    holds the steps drawn so far.
    """
    checks.generator("rng", rng)
    n_steps, n_labels = scenario.n_steps, scenario.signal.n_labels
    times = scenario.signal.period_s * np.arange(1, n_steps + 1, dtype=np.float64)
    states = np.full((n_steps, n_labels, 4), np.nan)
    modes = np.full((n_steps, n_labels), -1, dtype=np.int8)
    taus = np.full((n_steps, n_labels), np.nan)
    alive_all = np.zeros((n_steps, n_labels), dtype=bool)
    x = np.zeros((n_labels, 4))
    mode = np.zeros(n_labels, dtype=np.int8)
    tau = np.zeros(n_labels)
    was_alive = np.zeros(n_labels, dtype=bool)
    for k, t in enumerate(times):
        if stop_requested():
            n_steps = k
            break
        x, mode, tau = propagate(scenario.motion, x, mode, tau, rng)
        alive = np.zeros(n_labels, dtype=bool)
        for tag in scenario.tags:
            lam = tag.label
            if not tag.birth_s <= t < tag.death_s:
                continue
            alive[lam] = True
            if not was_alive[lam]:
                x[lam], tau[lam] = tag.initial_state, tag.tau_s
            forced = tag.scheduled_mode(float(t) - tag.birth_s)
            if forced is not None:
                mode[lam] = forced
        states[k, alive], modes[k, alive], taus[k, alive] = x[alive], mode[alive], tau[alive]
        alive_all[k] = was_alive = alive

    def ro(a: NDArray[Any]) -> NDArray[Any]:
        return checks.readonly(a[:n_steps], copy=False)

    return RadioTruth(times_s=ro(times), states=ro(states), alive=ro(alive_all), modes=ro(modes),
                      taus_s=ro(taus))
