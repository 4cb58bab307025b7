"""The constrained path-planning problem of Nguyen et al. (§III-D, eq. 45) and its plan.

From its pose, the UAV chooses a sequence of ``H`` action primitives (one per planning interval
of ``N_p`` seconds, :func:`~searchtrack.models.radio.uav.primitives`) that maximises the
discounted information reward ``Σ_j γ^{j−1} D(π_{k+j}(·|ẑ), π_{k+j|k})`` (eqs. 32–33, Rényi or
Cauchy–Schwarz) subject to the void constraint: at every second of the look-ahead the predicted
density must put probability above ``P_vmin`` on "no object within ``r_min`` of the UAV"
(eq. 44, checked at every pose, stricter than the paper's look-ahead points).

Beyond the paper, two settings of :class:`RadioPlanSettings`: the reward may read a label not
yet heard at an exploration existence (``explore_existence``, :func:`reward_existence`; the
paper's PIMS gives such a label no value, so its UAV never looks for tags it has not found), and
the void region of an estimate may grow with its spread (``spread_inflation``,
:func:`keep_out_radii`). :mod:`~searchtrack.plan.radio.lookahead` defines how the densities
are predicted and updated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.belief import LabelledParticleBelief
from searchtrack.estimate.labelled_particles import LabelledParticles
from searchtrack.models.radio import RadioScenario

#: Reward names: the Rényi divergence (eq. 41) and the Cauchy–Schwarz divergence (eq. 42).
REWARDS = ("renyi", "cs")

#: A label enters the ideal measurement set (PIMS) when its existence probability exceeds this.
EXISTENCE_THRESHOLD = 0.5

#: Longest horizon ``H`` and most look-ahead particles per label.
MAX_HORIZON, MAX_PLAN_PARTICLES = 10, 100_000
#: Most look-ahead points ``H · N_p/step_s · Λ · plan_particles`` (the paper: 60 000).
MAX_LOOKAHEAD_POINTS = 2**23
#: Largest ``spread_inflation``: how many spreads a void disc may reach beyond ``r_min``.
MAX_SPREAD_INFLATION = 100.0


@dataclass(frozen=True)
class RadioPlanSettings:
    """How action sequences are scored and constrained.

    Parameters
    ----------
    horizon
        ``H``, planning intervals looked ahead (1 to :data:`MAX_HORIZON`; 3 in the paper).
    reward
        ``"renyi"`` (eq. 41) or ``"cs"`` (Cauchy–Schwarz, eqs. 42–43).
    alpha
        Rényi order ``α > 0`` (1: Kullback–Leibler); the paper does not state it, 0.5 here.
    cs_k
        ``K > 0`` of the Cauchy–Schwarz divergence (the unit of hyper-volume).
    discount
        ``γ ∈ (0, 1]`` of eq. 32.
    r_min_m
        Radius ``r_min`` (m, ≥ 0) of the void region, ground distance (eq. 44).
    p_void_min
        ``P_vmin ∈ [0, 1)``: the void probability must exceed it at every pose; 0 means no
        constraint (every path meets it, whatever its void probabilities).
    plan_particles
        Particles per label drawn from the belief for the look-ahead (1 to
        :data:`MAX_PLAN_PARTICLES`).
    spread_inflation
        ``κ_σ ≥ 0``: the void region of an estimated label λ (``r > 0.5``) is the disc of
        radius ``r_min + κ_σ σ_λ``, ``σ_λ`` the root of the summed variances of its drawn
        particles' ground positions (:func:`keep_out_radii`), so that a spread-out estimate is
        kept further off than its particles' mass alone would: an estimate is only as good as
        the belief, and a belief that lags its object still has its spread. 0 is the paper's
        ``r_min`` for every label.
    explore_existence
        ``r̃ ∈ [0, 1)``: the existence a label not in the ideal measurement set (``r ≤ 0.5``)
        is given in the reward, ``max(r, r̃)``, so that the planner values looking for a tag it
        has not heard (:func:`reward_existence`). With the paper's PIMS such a label adds next
        to nothing, its ``r`` being about ``r_B``. It stands for the planner's belief that a
        deployed tag transmits and weighs finding tags against tracking those found; 0 is the
        paper's reward. The void constraint and the ideal measurement keep the belief's ``r``.
    """

    horizon: int = 3
    reward: str = "renyi"
    alpha: float = 0.5
    cs_k: float = 1.0
    discount: float = 1.0
    r_min_m: float = 50.0
    p_void_min: float = 0.9
    plan_particles: int = 1000
    spread_inflation: float = 0.0
    explore_existence: float = 0.5

    def __post_init__(self) -> None:
        if checks.count("horizon", self.horizon, 1) > MAX_HORIZON:
            raise InvalidInputError("horizon", self.horizon,
                                    f"must be an integer in [1, {MAX_HORIZON}]")
        checks.choice("reward", self.reward, REWARDS)
        checks.positive("alpha", self.alpha)
        checks.positive("cs_k", self.cs_k)
        checks.real("discount", self.discount, low=0.0, high=1.0, low_open=True)
        checks.non_negative("r_min_m", self.r_min_m)
        checks.real("p_void_min", self.p_void_min, low=0.0, high=1.0, high_open=True)
        if checks.count("plan_particles", self.plan_particles, 1) > MAX_PLAN_PARTICLES:
            raise InvalidInputError("plan_particles", self.plan_particles,
                                    f"must be an integer in [1, {MAX_PLAN_PARTICLES}]")
        checks.real("spread_inflation", self.spread_inflation, low=0.0,
                    high=MAX_SPREAD_INFLATION)
        checks.real("explore_existence", self.explore_existence, low=0.0, high=1.0,
                    high_open=True)


def reward_existence(r: FloatArray, settings: RadioPlanSettings) -> FloatArray:
    """``(Λ,)`` the existences the reward reads: ``max(r, r̃)`` for the labels with
    ``r ≤`` :data:`EXISTENCE_THRESHOLD` (not in the ideal measurement set), ``r`` for the
    others."""
    rr = np.asarray(r, dtype=np.float64)
    low = rr <= EXISTENCE_THRESHOLD
    return np.asarray(np.where(low, np.maximum(rr, settings.explore_existence), rr),
                      dtype=np.float64)


def keep_out_radii(xy: FloatArray, r: FloatArray, settings: RadioPlanSettings) -> FloatArray:
    """``(Λ,)`` void-region radii of equally weighted particles at ground positions ``xy``
    ``(Λ, N, 2)`` with existences ``r``: ``r_min + κ_σ σ_λ``, ``σ_λ² = var x + var y``
    (``spread_inflation``), for the estimates (``r >`` :data:`EXISTENCE_THRESHOLD`), ``r_min``
    for the other labels (a label not yet heard is spread over its birth region)."""
    radii = np.full(xy.shape[0], settings.r_min_m)
    if settings.spread_inflation == 0.0:
        return radii
    spread = np.sqrt(xy[..., 0].var(axis=1) + xy[..., 1].var(axis=1))
    estimate = np.asarray(r) > EXISTENCE_THRESHOLD
    radii[estimate] += settings.spread_inflation * spread[estimate]
    return radii


def check_lookahead_size(scenario: RadioScenario, settings: RadioPlanSettings) -> None:
    """:class:`InvalidInputError` naming ``plan_particles`` unless the look-ahead of
    ``settings`` over ``scenario`` holds at most :data:`MAX_LOOKAHEAD_POINTS` points."""
    poses = settings.horizon * scenario.uav.steps_per_plan
    points = poses * scenario.signal.n_labels * settings.plan_particles
    if points > MAX_LOOKAHEAD_POINTS:
        raise InvalidInputError("plan_particles", settings.plan_particles,
                                f"{poses} look-ahead poses × {scenario.signal.n_labels} labels × "
                                f"{settings.plan_particles} = {points} points exceed the "
                                f"{MAX_LOOKAHEAD_POINTS} a plan may hold")


def _belief(value: object, n_labels: int, period_s: float) -> LabelledParticles:
    """A read-only copy of ``value`` after checking it is a valid labelled particle density."""
    if not isinstance(value, LabelledParticleBelief):
        raise InvalidInputError("belief", value, "must be a LabelledParticleBelief (x, mode, tau, "
                                "w, r)")
    try:
        b = LabelledParticles(np.array(value.x, dtype=np.float64), np.array(value.mode),
                              np.array(value.tau, dtype=np.float64),
                              np.array(value.w, dtype=np.float64),
                              np.array(value.r, dtype=np.float64))
    except (InvalidInputError, TypeError, ValueError) as exc:
        raise InvalidInputError("belief", type(value).__name__,
                                f"must hold arrays of matching shapes ({exc})") from None
    if b.n_labels != n_labels:
        raise InvalidInputError("belief", b.x.shape,
                                f"must have one row per label of the signal ({n_labels})")
    if b.n_particles < 1:
        raise InvalidInputError("belief", b.x.shape, "must hold at least one particle per label")
    for name in ("x", "tau", "w", "r"):
        if not np.all(np.isfinite(getattr(b, name))):
            raise InvalidInputError(f"belief.{name}", getattr(b, name).shape,
                                    "must be finite (no NaN or inf)")
    if b.mode.dtype.kind not in "iu" or np.any((b.mode != 0) & (b.mode != 1)):
        raise InvalidInputError("belief.mode", b.mode.shape, "must hold modes 0 (WD) or 1 (CV)")
    if np.any(b.tau < 0.0) or np.any(b.tau >= period_s):
        raise InvalidInputError("belief.tau", b.tau.shape, f"must lie in [0, {period_s:g}) s")
    if np.any(b.w < 0.0) or not np.allclose(b.w.sum(axis=1), 1.0, rtol=0.0, atol=1e-6):
        raise InvalidInputError("belief.w", b.w.shape,
                                "must be non-negative and sum to 1 for every label")
    if np.any(b.r < 0.0) or np.any(b.r > 1.0):
        raise InvalidInputError("belief.r", b.r.tolist(), "must be probabilities in [0, 1]")
    b.mode = b.mode.astype(np.int8)
    for arr in (b.x, b.mode, b.tau, b.w, b.r):
        arr.setflags(write=False)
    return b


@dataclass(frozen=True, eq=False)
class RadioPlanProblem:
    """Plan the UAV's next ``H`` planning intervals from a labelled particle belief.

    Parameters
    ----------
    belief
        The filtering density ``π_k``, any
        :class:`~searchtrack.estimate.belief.LabelledParticleBelief` (the radio filter, a
        :class:`~searchtrack.estimate.labelled_particles.LabelledParticles`): per label ``r_λ``
        and weighted particles of ``[px, vx, py, vy]``, mode and ``τ``; one row per label of the
        signal. Its arrays are copied into a read-only
        :class:`~searchtrack.estimate.labelled_particles.LabelledParticles`, which this field
        then holds.
    uav_pose
        ``(3,)`` UAV pose ``(x, y, heading)`` (m, m, rad). It may be outside the area (a UAV
        too close to an edge to turn back in time leaves it), within the area's size of it:
        the primitives then bring it back (:func:`~searchtrack.models.radio.uav.primitives`).
    scenario
        Signal, tag motion, UAV model and area.
    settings
        Horizon, reward and constraint.

    Raises
    ------
    InvalidInputError
        Naming the field: a belief of the wrong shape, non-finite, with weights that do not
        sum to 1 or ``r`` outside ``[0, 1]``; a pose that is not finite or outside the area; a
        look-ahead larger than :func:`check_lookahead_size` allows.
    """

    belief: LabelledParticleBelief
    uav_pose: FloatArray
    scenario: RadioScenario
    settings: RadioPlanSettings = RadioPlanSettings()

    def __post_init__(self) -> None:
        if not isinstance(self.scenario, RadioScenario):
            raise InvalidInputError("scenario", self.scenario, "must be a RadioScenario")
        if not isinstance(self.settings, RadioPlanSettings):
            raise InvalidInputError("settings", self.settings, "must be RadioPlanSettings")
        sc = self.scenario  # its UAV step equals the motion period: one propagation per pose
        check_lookahead_size(sc, self.settings)
        put = object.__setattr__
        put(self, "belief", _belief(self.belief, sc.signal.n_labels, sc.signal.period_s))
        pose = checks.finite_array("uav_pose", self.uav_pose, (3,))
        width, height = sc.area_m
        if not (-width <= pose[0] <= 2 * width and -height <= pose[1] <= 2 * height):
            raise InvalidInputError("uav_pose", pose.tolist(),
                                    f"must lie within one area's size of [0, {width:g}] × "
                                    f"[0, {height:g}]")
        put(self, "uav_pose", pose)

    @property
    def n_labels(self) -> int:
        """Number of labels ``Λ``."""
        return int(self.belief.r.size)

    @property
    def steps_per_interval(self) -> int:
        """Poses per planning interval, ``N_p / step_s``."""
        return self.scenario.uav.steps_per_plan

    @property
    def n_poses(self) -> int:
        """Poses of a whole plan, ``H · N_p / step_s``."""
        return self.settings.horizon * self.steps_per_interval


@dataclass(frozen=True, eq=False)
class RadioPlan:
    """An action sequence and what the planner predicts for it.

    Parameters
    ----------
    headings
        ``(H,)`` target headings (rad) of the primitives, one per planning interval.
    path
        ``(H · N_p/step_s, 3)`` poses ``(x, y, heading)`` after each step.
    rewards
        ``(H,)`` rewards ``D(π_{k+j}(·|ẑ), π_{k+j|k})`` at the end of each interval
        (undiscounted).
    void
        ``(H · N_p/step_s,)`` void probability of the predicted density at each pose.
    feasible
        Whether every void probability exceeds ``P_vmin``; False for the least-violating plan a
        solver returns when no sequence meets the constraint
        (:mod:`~searchtrack.plan.radio.search`).
    """

    headings: FloatArray
    path: FloatArray
    rewards: FloatArray
    void: FloatArray
    feasible: bool

    def __post_init__(self) -> None:
        put = object.__setattr__
        headings = checks.finite_array("headings", self.headings, (None,))
        path = checks.finite_array("path", self.path, (None, 3))
        put(self, "headings", headings)
        put(self, "path", path)
        put(self, "rewards", checks.finite_array("rewards", self.rewards, (headings.size,)))
        put(self, "void", checks.finite_array("void", self.void, (path.shape[0],)))
        if headings.size == 0 or path.shape[0] % headings.size:
            raise InvalidInputError("path", path.shape, f"must hold a whole number of poses "
                                    f"per heading ({headings.size} headings)")
        put(self, "feasible", bool(self.feasible))

    @property
    def min_void(self) -> float:
        """The smallest void probability along the path."""
        return float(self.void.min())

    def violation(self, p_void_min: float) -> float:
        """How far the path breaks the constraint: ``Σ_t max(0, P_vmin − B_t)`` over its poses
        (0 when it meets it; the least-violating plan minimises it)."""
        return float(np.maximum(0.0, p_void_min - self.void).sum())

    def objective(self, discount: float) -> float:
        """``Σ_j γ^{j−1} rewards_j`` (eq. 32)."""
        return float(np.sum(self.rewards * discount ** np.arange(self.rewards.size)))

