"""An independent check of a radio plan: its kinematics, the void constraint and the rewards,
recomputed from the belief by brute force.

Nothing of the planner is used (no tree, no likelihood table, no factorised sums):

* kinematics, from the path alone: ``speed · step_s`` between poses, along the chord of the
  step's turn; every turn toward the interval's target heading at the largest rate, then
  straight; each target one of the ``N_θ`` primitive headings from the interval's first
  heading (unless any heading is allowed); every pose inside the area;
* the look-ahead cloud is drawn again by the documented recipe (systematic resampling of
  ``plan_particles`` per label, then the motion model second by second, one generator seeded
  with ``seed``), with the belief seam's resampling and the motion model's propagation;
* the void probability at each pose is eq. 44 summed over all ``2^Λ`` label sets, the particle
  mass in each label's disc (radius ``r_min``, plus ``spread_inflation`` times the RMS distance
  of the label's drawn particles from their centre for a label with ``r > 0.5``) counted by
  distance;
* each reward simulates the ideal measurement with :func:`~searchtrack.models.radio.stft.
  ideal_stft` from the estimates (``r > 0.5``, weighted mean position, weighted-mode frame),
  updates the posterior with the exact likelihood of eq. 22 (every cell of every particle's
  influence region, ``log I0`` by SciPy, amplitudes and frames by the signal model) and the
  belief seam's update (eqs. 29–30,
  :func:`~searchtrack.estimate.labelled_particles.update`), and evaluates eq. 41 or eqs. 42–43
  over all label sets, the densities of the reward holding ``r̃`` for each label with
  ``r ≤ 0.5`` whose ``r`` is below it (``explore_existence``).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from scipy.special import expit, i0e

from searchtrack.core.angles import wrap_angle
from searchtrack.core.result import Result
from searchtrack.core.types import FloatArray
from searchtrack.estimate.labelled_particles import LabelledParticles, resample
from searchtrack.models.radio import RadioSignal, propagate
from searchtrack.models.radio.stft import ideal_stft
from searchtrack.plan.radio.problem import RadioPlan, RadioPlanProblem

#: Tolerance (m, rad) of the kinematic checks.
TOL = 1e-6
_VOID_TOL = 1e-9  # void probabilities agree to this; a void this close to P_vmin is a tie


@dataclass(frozen=True)
class PlanCheck:
    """The verdict on a plan.

    Parameters
    ----------
    valid
        The path is flyable from the problem's pose (speed, turns, primitives, area).
    void
        ``(T,)`` void probability at each pose, recomputed.
    meets_constraint
        Every recomputed void probability exceeds ``P_vmin``.
    rewards
        ``(H,)`` rewards recomputed with the exact likelihood.
    objective
        ``Σ_j γ^{j−1} rewards_j``.
    reasons
        What is wrong with the path, one line per fault.
    """

    valid: bool
    void: FloatArray
    meets_constraint: bool
    rewards: FloatArray
    objective: float
    reasons: tuple[str, ...] = ()


def _path_faults(problem: RadioPlanProblem, plan: RadioPlan, any_heading: bool) -> list[str]:
    uav = problem.scenario.uav
    n_p = problem.steps_per_interval
    if plan.headings.size != problem.settings.horizon or plan.path.shape[0] != problem.n_poses:
        return [f"{plan.headings.size} headings and {plan.path.shape[0]} poses; the horizon "
                f"needs {problem.settings.horizon} and {problem.n_poses}"]
    faults = []
    poses = np.vstack([problem.uav_pose, plan.path])
    step_m, max_turn = uav.speed_mps * uav.step_s, uav.max_turn_rate * uav.step_s
    deltas = -math.pi + 2 * math.pi * np.arange(uav.n_headings) / uav.n_headings
    for k in range(1, poses.shape[0]):
        (x0, y0, h0), (x1, y1, h1) = poses[k - 1], poses[k]
        turn = float(wrap_angle(h1 - h0))
        if abs(math.hypot(x1 - x0, y1 - y0) - step_m) > TOL:
            faults.append(f"step {k}: moves {math.hypot(x1 - x0, y1 - y0):.6g} m, not {step_m:g}")
        if abs(turn) > max_turn + TOL:
            faults.append(f"step {k}: turns {turn:.6g} rad, more than {max_turn:.6g}")
        chord = math.atan2(y1 - y0, x1 - x0)
        if abs(float(wrap_angle(chord - (h0 + turn / 2)))) > TOL:
            faults.append(f"step {k}: moves at bearing {chord:.6g}, not along its turn")
        target = plan.headings[(k - 1) // n_p]
        want = float(np.clip(wrap_angle(target - h0), -max_turn, max_turn))
        if abs(turn - want) > TOL:
            faults.append(f"step {k}: turns {turn:.6g} rad toward {target:.6g}, not {want:.6g}")
    for j in range(0 if any_heading else problem.settings.horizon):
        start = poses[j * n_p, 2]
        if np.min(np.abs(wrap_angle(start + deltas - plan.headings[j]))) > TOL:
            faults.append(f"interval {j}: heading {plan.headings[j]:.6g} is not a primitive "
                          f"from {start:.6g}")
    width, height = problem.scenario.area_m
    out = ((plan.path[:, 0] < 0) | (plan.path[:, 0] > width) | (plan.path[:, 1] < 0)
           | (plan.path[:, 1] > height))
    for j in range(out.size // n_p):
        if out[j * n_p:(j + 1) * n_p].any() and _could_stay_inside(problem, poses[j * n_p], n_p):
            faults.append(f"interval {j}: {int(out[j * n_p:(j + 1) * n_p].sum())} poses outside "
                          "the area, though a heading kept it inside")
    return faults


def _could_stay_inside(problem: RadioPlanProblem, pose: FloatArray, n_p: int) -> bool:
    """Whether some heading held from ``pose`` keeps the next ``n_p`` steps inside the area
    (flown here by turn-rate-limited steps, not by the planner's primitives)."""
    uav, (width, height) = problem.scenario.uav, problem.scenario.area_m
    step = uav.speed_mps * uav.step_s
    max_turn = uav.max_turn_rate * uav.step_s
    for target in np.linspace(-np.pi, np.pi, 72, endpoint=False):
        x, y, h = pose
        ok = True
        for _ in range(n_p):
            turn = float(np.clip(wrap_angle(target - h), -max_turn, max_turn))
            mid = h + 0.5 * turn
            x, y, h = x + step * np.cos(mid), y + step * np.sin(mid), h + turn
            if not (0.0 <= x <= width and 0.0 <= y <= height):
                ok = False
                break
        if ok:
            return True
    return False


def _label_sets(n: int) -> list[tuple[int, ...]]:
    return [s for k in range(n + 1) for s in itertools.combinations(range(n), k)]


def _set_weight(r: FloatArray, subset: tuple[int, ...]) -> float:
    return math.prod(float(r[i]) if i in subset else 1.0 - float(r[i]) for i in range(r.size))


def _void(r: FloatArray, w: FloatArray, xy: FloatArray, centre: FloatArray,
          radii: FloatArray) -> float:
    """Eq. 44 over every label set, label λ's region the disc of radius ``radii[λ]``."""
    inside = np.hypot(xy[..., 0] - centre[0], xy[..., 1] - centre[1]) < radii[:, None]
    mass = (w * inside).sum(axis=1)
    return sum(_set_weight(r, s) * math.prod(1.0 - float(mass[i]) for i in s)
               for s in _label_sets(r.size))


def _divergence(problem: RadioPlanProblem, p1: LabelledParticles, p2: LabelledParticles) -> float:
    """Eq. 41 (Rényi) or eqs. 42–43 (Cauchy–Schwarz) over every label set."""
    st = problem.settings
    sets = _label_sets(p1.n_labels)
    if st.reward == "cs":
        def inner(a: LabelledParticles, b: LabelledParticles) -> float:
            c = [st.cs_k * float(np.sum(a.w[i] * b.w[i])) for i in range(a.n_labels)]
            return sum(_set_weight(a.r, s) * _set_weight(b.r, s) * math.prod(c[i] for i in s)
                       for s in sets)
        return -math.log(inner(p2, p1) / math.sqrt(inner(p2, p2) * inner(p1, p1)))
    a = st.alpha
    if a == 1.0:
        kl = 0.0
        for s in sets:
            w2, w1 = _set_weight(p2.r, s), _set_weight(p1.r, s)
            if w2 > 0:
                kl += w2 * math.log(w2 / w1) if w1 > 0 else math.inf
                for i in s:
                    kl += w2 * _kl_sum(p2.w[i], p1.w[i])
        return kl
    c = [_power_sum(p2.w[i], p1.w[i], a) for i in range(p1.n_labels)]
    total = sum(_power_term(_set_weight(p2.r, s), _set_weight(p1.r, s), a)
                * math.prod(c[i] for i in s) for s in sets)
    return math.log(total) / (a - 1)


def _power_term(q2: float, q1: float, a: float) -> float:
    """``q2^α q1^(1−α)``: 0 where ``q2 = 0`` (for every α > 0), unbounded where only ``q1`` is
    0 and α > 1."""
    if q2 <= 0.0:
        return 0.0
    if q1 <= 0.0:
        return 0.0 if a < 1.0 else math.inf
    return float(q2 ** a * q1 ** (1.0 - a))


def _power_sum(q2: FloatArray, q1: FloatArray, a: float) -> float:
    """``Σ q2^α q1^(1−α)`` over the particles, with :func:`_power_term`'s conventions."""
    seen = q2 > 0
    if a > 1.0 and np.any(q1[seen] <= 0):
        return math.inf
    both = seen & (q1 > 0)
    return float(np.sum(q2[both] ** a * q1[both] ** (1.0 - a)))


def _kl_sum(q2: FloatArray, q1: FloatArray) -> float:
    """``Σ q2 log(q2 / q1)`` over the particles with ``q2 > 0`` (unbounded if ``q1`` is 0 there)."""
    seen = q2 > 0
    if np.any(q1[seen] <= 0):
        return math.inf
    return float(np.sum(q2[seen] * np.log(q2[seen] / q1[seen])))


def _ideal(problem: RadioPlanProblem, cloud: LabelledParticles, pose: FloatArray) -> FloatArray:
    """The noise-free measurement of the estimated labels seen from ``pose``."""
    signal = problem.scenario.signal
    labels, xy, taus = [], [], []
    frames = signal.frame_of(cloud.tau)
    for lab in range(cloud.n_labels):
        if cloud.r[lab] <= 0.5:
            continue
        w = cloud.w[lab]
        mode = int(np.argmax(np.bincount(frames[lab], weights=w)))
        if mode >= signal.frames:
            continue  # the estimated pulse lies past the last frame: no cell lights up
        labels.append(lab)
        xy.append([float(w @ cloud.x[lab, :, 0]) / w.sum(), float(w @ cloud.x[lab, :, 2])
                   / w.sum()])
        taus.append(max(mode - 0.5, 0.0) * signal.hop / signal.sample_rate_hz)
    return ideal_stft(signal, np.array(xy).reshape(-1, 2), np.array(labels, dtype=np.int64),
                      np.array(taus), pose)


def _log_likelihoods(signal: RadioSignal, z: FloatArray, x: FloatArray, tau: FloatArray,
                     pose: FloatArray) -> FloatArray:
    """``(Λ, N)`` eq. 22 of every particle seen from ``pose``: the Rice-over-Rayleigh log ratio
    ``−ν²/(2Σ_z) + log I0(z ν/Σ_z)``, ``ν = γ |W_b|``, summed over the cells
    ``{m, m + 1} ∩ [0, M) × S(λ)`` of its amplitude ``γ`` and pulse frame ``m = m(τ)``."""
    gamma = signal.amplitude(x[:, :, ::2], pose)
    frames = np.asarray(signal.frame_of(tau), dtype=np.int64)
    bins, leak, var = signal.tag_bins(), signal.tag_leakage(), signal.cell_var
    n_frames = z.shape[0]
    out = np.empty(gamma.shape)
    for lab in range(gamma.shape[0]):
        pair = frames[lab][:, None] + np.arange(2)                           # (N, 2)
        inside = (pair >= 0) & (pair < n_frames)
        cells = z[np.clip(pair, 0, n_frames - 1)[:, :, None], bins[lab][None, None, :]]
        nu = gamma[lab][:, None, None] * leak[lab][None, None, :]            # (N, 1, B)
        arg = cells * nu / var
        lit = arg > 0   # log I0(0) = 0: the Bessel term only where the cell carries signal
        bessel = np.zeros(arg.shape)
        bessel[lit] = np.log(i0e(arg[lit])) + arg[lit]
        llr = bessel - (nu**2) / (2.0 * var)
        out[lab] = (llr.sum(axis=2) * inside).sum(axis=1)
    return out


def _log_update(log_w: FloatArray, r: FloatArray,
                log_lik: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Eqs. 29–30 with the weights kept as logarithms from one update to the next, so that a
    particle whose weight falls below the smallest double is not lost to a later, stronger
    likelihood: ``log η = log Σ exp(log w + log g)``, ``log w ← log w + log g − log η``,
    ``r ← r η / (1 − r + r η)``."""
    post = log_w + log_lik
    peak = np.max(post, axis=1, keepdims=True)
    log_eta = peak[:, 0] + np.log(np.sum(np.exp(post - peak), axis=1))
    with np.errstate(divide="ignore"):  # r = 0 or 1 stay where they are
        odds_against = np.log1p(-r) - np.log(r) - log_eta   # log((1 − r) / (r η))
    out = np.asarray(expit(-odds_against), dtype=np.float64)   # 1 / (1 + (1 − r) / (r η))
    return post - log_eta[:, None], out


def check_plan(problem: RadioPlanProblem, plan: RadioPlan, *, seed: int = 0,
               any_heading: bool = False) -> PlanCheck:
    """Check ``plan`` against ``problem`` and recompute its void probabilities and rewards on
    the look-ahead draws of ``seed`` (the seed the plan was solved with). ``any_heading``
    accepts target headings that are not primitives (the straight baseline's)."""
    faults = _path_faults(problem, plan, any_heading)
    if faults and plan.path.shape[0] != problem.n_poses:
        return PlanCheck(False, np.zeros(0), False, np.zeros(0), math.nan, tuple(faults))
    sc, st = problem.scenario, problem.settings
    rng = np.random.default_rng(seed)
    cloud = resample(problem.belief, rng, st.plan_particles)
    radii = np.empty(cloud.n_labels)   # r_min, + κ_σ · RMS distance from the centre if r > 0.5
    for lab in range(cloud.n_labels):
        px, py = cloud.x[lab, :, 0], cloud.x[lab, :, 2]
        rms = math.sqrt(float(np.mean((px - px.mean()) ** 2 + (py - py.mean()) ** 2)))
        radii[lab] = st.r_min_m + (st.spread_inflation * rms if cloud.r[lab] > 0.5 else 0.0)
    unheard = [lab for lab in range(cloud.n_labels) if float(cloud.r[lab]) <= 0.5]
    scored = cloud.r.copy()   # the reward's existences: r̃ for a label not heard yet
    for lab in unheard:
        scored[lab] = max(float(scored[lab]), st.explore_existence)
    with np.errstate(divide="ignore"):
        log_w, r_post = np.log(cloud.w), scored.copy()  # the posterior, weights in log space
    void, rewards = [], []
    n_p = problem.steps_per_interval
    for k in range(problem.n_poses):
        x, mode, tau = propagate(sc.motion, cloud.x, cloud.mode, cloud.tau, rng)
        cloud = LabelledParticles(x, mode, tau, cloud.w, cloud.r)
        pose = plan.path[k]
        void.append(_void(cloud.r, cloud.w, x[:, :, ::2], pose[:2], radii))
        if (k + 1) % n_p == 0:
            z = _ideal(problem, cloud, pose)
            log_w, r_post = _log_update(log_w, r_post,
                                        _log_likelihoods(sc.signal, z, x, tau, pose))
            posterior = LabelledParticles(x, mode, tau, np.exp(log_w), r_post)
            prior = LabelledParticles(x, mode, tau, cloud.w, scored)
            rewards.append(_divergence(problem, prior, posterior))
    voids, gains = np.array(void), np.array(rewards)
    objective = float(np.sum(gains * st.discount ** np.arange(gains.size)))
    meets = st.p_void_min <= 0.0 or bool(np.all(voids > st.p_void_min))  # 0: no constraint
    return PlanCheck(not faults, voids, meets, gains, objective, tuple(faults))


def answer_problems(problem: RadioPlanProblem, result: Result[RadioPlan],
                    seed: int = 0) -> list[str]:
    """What :func:`check_plan` on the look-ahead draws of ``seed`` finds wrong with ``result``:
    path faults, void probabilities or rewards that are not the recomputed ones, a constraint
    verdict that does not hold, and (for a plan that meets it) an objective that is not
    ``Σ_j γ^{j−1} r_j``."""
    plan = result.plan
    assert plan is not None
    check = check_plan(problem, plan, seed=seed, any_heading=result.backend == "straight")
    if not check.valid:
        return list(check.reasons)
    problems = []
    if not np.allclose(check.void, plan.void, rtol=0.0, atol=_VOID_TOL):
        problems.append("void probabilities differ from the recomputed ones")
    at_bound = abs(float(check.void.min()) - problem.settings.p_void_min) <= _VOID_TOL
    if check.meets_constraint != plan.feasible and not at_bound:  # a tie is rounding's call
        problems.append(f"the plan says feasible={plan.feasible}, the recomputed voids "
                        f"say {check.meets_constraint}")
    if not np.allclose(check.rewards, plan.rewards, rtol=1e-6, atol=1e-12):
        problems.append("rewards differ from the recomputed ones")
    obj = result.objective
    if plan.feasible and obj is not None and abs(obj - check.objective) > 1e-6 * (
            1.0 + abs(check.objective)):
        problems.append(f"reported objective {obj} but the path scores {check.objective}")
    return problems
