"""Lemma 5 of paper 000 (§5.3, Algorithms 1–2): how the modes of a target's filter split.

A mode of degree ``D`` holds the fraction ``D`` of the particles. A target starts uniformly on the
roads (Assumption 4) as one mode (``D = 1``); each time a mode leaves a chain it splits into equal
parts on the chain's ``F`` children (Assumption 3) and modes never merge (Assumption 7). ``P_D(t)``
is the expected fraction of the mass held in modes of degree ``D`` at time ``t``, so
``Σ_D P_D(t) = 1`` (Eq. 45 read as ``E[#modes of degree D] = P_D / D``; Eq. 43 has it inverted).

Three computations of the same thing:

- :func:`mode_probabilities`, the recursion of Algorithms 1–2 written without their defects:
  exact in continuous time, per degree, over subdivisions (or over single chains; the results
  are equal). The mode born on ``c`` with degree ``D`` at offset ``b`` after the first exit
  ``U ~ U(0, T_r(s₀))`` of a mode started in ``s₀`` contributes
  ``π(s₀) D [w(t, b, T_r(s₀)) − w(t, b + T_r(c), T_r(s₀))]`` with ``w`` the linear exit
  probability of Eq. 41; its children are ``(c_j, D/F(c), b + T_r(c))`` (Eq. 42, ``f = 1…F``).
- :func:`split_profile`, the same recursion propagated forward on the time-step grid of Theorem 1
  with the degrees folded into ``Σ_D P_D`` and ``Σ_D P_D ln(1/D)``, the only two sums Eq. 29 needs.
  Its cost is ``O(C · T_Q)``, so it serves maps of any size; it equals the exact recursion at the
  grid times when every chain's traversal time is a whole number of steps (and otherwise splits a
  mode's exit between the two nearest steps).
- :func:`mode_split_mc`, a Monte Carlo run of modes splitting on the chain graph, to check both.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import check_stop
from searchtrack.plan.fleet.chains import ChainGraph, subdivisions

#: Most modes :func:`mode_probabilities` enumerates before it refuses (use :func:`split_profile`).
MAX_MODES = 2_000_000

#: Modes × times evaluated at once by :func:`mode_probabilities` (bounds its memory).
EVAL_CELLS = 4_000_000

#: Most steps :func:`split_profile` propagates (a round trip of almost 14 hours at 0.1 s).
MAX_PROFILE_STEPS = 500_000

#: Most numbers :func:`split_profile`'s ring of births may hold (chains × steps of the slowest
#: chain; 512 MB).
MAX_RING_CELLS = 2**26

#: Most chain-steps (chains × steps) :func:`split_profile` propagates, about a minute of work.
MAX_PROFILE_WORK = 5_000_000_000


@dataclass(frozen=True)
class ModeProbabilities:
    """``P_D(t)``: the expected mass fraction in modes of each degree ``D`` (Lemma 5, Fig. 8).

    Parameters
    ----------
    times_s
        ``(T,)`` times (s) since the last sighting.
    degrees
        The degrees present, largest first (1, 1/2, 1/3, ...).
    probability
        ``(len(degrees), T)`` values of ``P_D(t)``.
    """

    times_s: NDArray[np.float64]
    degrees: tuple[Fraction, ...]
    probability: NDArray[np.float64]

    def of(self, degree: Fraction | float) -> NDArray[np.float64]:
        """``P_D(t)`` for one degree (zeros when no mode of that degree ever exists)."""
        wanted = Fraction(degree).limit_denominator(10**12)
        if wanted in self.degrees:
            return np.asarray(self.probability[self.degrees.index(wanted)], dtype=np.float64)
        return np.zeros(self.times_s.size)

    @property
    def total(self) -> NDArray[np.float64]:
        """``Σ_D P_D(t)``, 1 at every time."""
        return np.asarray(self.probability.sum(axis=0), dtype=np.float64)

    @property
    def split_entropy(self) -> NDArray[np.float64]:
        """``Σ_D P_D(t) ln(1/D)`` (nats), the entropy the splitting adds in Eq. 29."""
        logs = np.array([math.log(1 / d) for d in self.degrees])
        return np.asarray(logs @ self.probability, dtype=np.float64)


@dataclass(frozen=True)
class SplitProfile:
    """The two sums over degrees that Eq. 29 needs, at the time steps ``k = 0…K``.

    Parameters
    ----------
    dt_s
        Time step ``δ_t`` (s).
    mass
        ``(K + 1,)`` values of ``Σ_D P_{D,k}`` (1 up to rounding).
    split_entropy
        ``(K + 1,)`` values of ``Σ_D P_{D,k} ln(1/D)`` (nats).
    """

    dt_s: float
    mass: NDArray[np.float64]
    split_entropy: NDArray[np.float64]

    @property
    def times_s(self) -> NDArray[np.float64]:
        """``(K + 1,)`` times ``k δ_t`` (s)."""
        return np.arange(self.mass.size, dtype=np.float64) * self.dt_s


def _times(times_s: ArrayLike) -> NDArray[np.float64]:
    t = checks.finite_array("times_s", np.atleast_1d(np.asarray(times_s, dtype=np.float64)),
                            (None,))
    if t.size == 0 or np.any(t < 0):
        raise InvalidInputError("times_s", times_s, "must be one or more times ≥ 0 (s)")
    return t


def _exit_probability(t: NDArray[np.float64], start: NDArray[np.float64],
                      spread: NDArray[np.float64]) -> NDArray[np.float64]:
    """``w(t, T_s, T_r)`` of Eq. 41 for every mode (rows) and time (columns)."""
    ratio = (t[None, :] - start[:, None]) / spread[:, None]
    return np.asarray(np.clip(ratio, 0.0, 1.0), dtype=np.float64)


def mode_probabilities(graph: ChainGraph, target_speed_mps: float, times_s: ArrayLike, *,
                       grouped: bool = True, max_modes: int = MAX_MODES) -> ModeProbabilities:
    """``P_D(t)`` by the recursion of Lemma 5 (Algorithms 1–2, Eqs. 41–42), exact in time.

    Parameters
    ----------
    graph
        Chains of the road map.
    target_speed_mps
        Target speed; a chain's traversal time is its length over this.
    times_s
        Times (s) at which to evaluate, ≥ 0.
    grouped
        Recurse over subdivisions (equal chains merged) or over single chains; equal results.
    max_modes
        Refuse when the mode tree up to ``max(times_s)`` holds more distinct modes than this.

    Raises
    ------
    InvalidInputError
        On a bad speed or time, or a mode tree past ``max_modes`` (then use :func:`split_profile`).
    """
    speed = checks.positive("target_speed_mps", target_speed_mps)
    t = _times(times_s)
    limit = checks.count("max_modes", max_modes, 1)
    subs = subdivisions(graph, grouped=grouped)
    trip = np.array([s.length_m / speed for s in subs])
    horizon = float(t.max())
    spread: list[float] = []
    weight: list[float] = []
    start: list[float] = []
    end: list[float] = []
    degree: list[Fraction] = []
    first = np.zeros(t.size)
    for s0, sub in enumerate(subs):
        first += sub.share * (1.0 - np.clip(t / trip[s0], 0.0, 1.0))
        frontier = Counter((c, Fraction(1, sub.fanout), 0.0) for c in sub.children)
        while frontier:
            after: Counter[tuple[int, Fraction, float]] = Counter()
            for (c, d, born), n in frontier.items():
                spread.append(trip[s0])
                weight.append(sub.share * n * float(d))
                start.append(born)
                end.append(born + trip[c])
                degree.append(d)
                if born + trip[c] < horizon:
                    for child in subs[c].children:
                        after[(child, d / subs[c].fanout, round(born + trip[c], 9))] += n
            if len(weight) + len(after) > limit:
                raise InvalidInputError("times_s", horizon, f"the mode tree up to {horizon:g} s "
                                        f"has more than max_modes={limit} modes; use "
                                        "split_profile for long horizons on irregular maps")
            frontier = after
    degrees = tuple(sorted({Fraction(1), *degree}, reverse=True))
    index = {d: i for i, d in enumerate(degrees)}
    prob = np.zeros((len(degrees), t.size))
    prob[index[Fraction(1)]] += first
    width, begin, stop, mass = (np.array(v, dtype=np.float64)
                                for v in (spread, start, end, weight))
    row = np.array([index[d] for d in degree], dtype=np.int64)
    block = max(1, EVAL_CELLS // t.size)
    for lo in range(0, row.size, block):
        part = slice(lo, lo + block)
        alive = mass[part, None] * (_exit_probability(t, begin[part], width[part])
                                    - _exit_probability(t, stop[part], width[part]))
        np.add.at(prob, row[part], alive)
    return ModeProbabilities(checks.readonly(t), degrees, checks.readonly(prob, copy=False))


def profile_refusal(graph: ChainGraph, target_speed_mps: float, dt_s: float,
                    n_steps: float) -> str | None:
    """Why :func:`split_profile` refuses ``n_steps`` steps on ``graph`` (its ring of births, its
    step count or its chain-steps over :data:`MAX_RING_CELLS`, :data:`MAX_PROFILE_STEPS` or
    :data:`MAX_PROFILE_WORK`), or ``None`` when it runs; a caller can ask before the work that
    precedes it."""
    speed = checks.positive("target_speed_mps", target_speed_mps)
    dt = checks.positive("dt_s", dt_s)
    longest = float(graph.length_m.max())
    slowest = longest / speed / dt
    cells = (math.floor(slowest) + 2.0) * graph.n_chains
    if cells > MAX_RING_CELLS:
        return (f"its longest chain ({longest:.4g} m) takes {slowest:.3g} steps of {dt:g} s at "
                f"{speed:g} m/s, so the split profile would hold {cells:.3g} numbers, above the "
                f"{MAX_RING_CELLS} it may")
    if n_steps > MAX_PROFILE_STEPS:
        return (f"a round trip takes {n_steps:.3g} steps of {dt:g} s, above the "
                f"{MAX_PROFILE_STEPS} the bound evaluates")
    if n_steps * graph.n_chains > MAX_PROFILE_WORK:
        return (f"{graph.n_chains} chains over {n_steps:.3g} steps are "
                f"{n_steps * graph.n_chains:.3g} chain-steps, above the {MAX_PROFILE_WORK:.3g} "
                "the bound evaluates")
    return None


def split_profile(graph: ChainGraph, target_speed_mps: float, dt_s: float,
                  n_steps: int) -> SplitProfile:
    """``Σ_D P_{D,k}`` and ``Σ_D P_{D,k} ln(1/D)`` for ``k = 0…n_steps`` (Lemma 5 on the step grid).

    The mass leaving the starting chains in each step ``((k−1)δ_t, kδ_t]`` is born on their
    children; a mode born at step ``j`` on chain ``c`` leaves it at step ``j + T_r(c)/δ_t`` (split
    between the two nearest steps when that is fractional, and never before ``j + 1``) and splits
    on ``c``'s children. Only ``O(C · max T_r/δ_t)`` numbers are kept. As modes never merge, each
    unit of mass that leaves a chain with ``F`` children adds ``ln F`` to ``Σ_D P_D ln(1/D)`` for
    good, so that sum is the running total of ``Σ_c (mass leaving c) · ln F(c)``.

    Parameters
    ----------
    graph
        Chains of the road map.
    target_speed_mps
        Target speed (m/s).
    dt_s
        Time step ``δ_t`` (s).
    n_steps
        Last step ``K`` (``T_Q`` in Eq. 27), ≥ 0.

    Raises
    ------
    InvalidInputError
        On a bad value, or sizes :func:`profile_refusal` refuses.
    StopRequested
        On a stop request inside :func:`~searchtrack.core.interrupt.stops_raise`.
    """
    speed = checks.positive("target_speed_mps", target_speed_mps)
    dt = checks.positive("dt_s", dt_s)
    steps_total = checks.count("n_steps", n_steps, 0)
    refusal = profile_refusal(graph, speed, dt, steps_total)
    if refusal is not None:
        raise InvalidInputError("n_steps", n_steps, refusal)
    trip = graph.length_m / speed
    steps = trip / dt
    near = np.round(steps)
    steps = np.maximum(np.where(np.abs(steps - near) < 1e-9 * near, near, steps), 1.0)
    lag = np.floor(steps).astype(np.int64)
    frac = steps - lag
    ring = int(lag.max()) + 2
    fan = graph.fanout
    parent = np.repeat(np.arange(graph.n_chains), fan)
    split = sp.csr_array((1.0 / fan[parent], (graph.child_idx, parent)),
                         shape=(graph.n_chains, graph.n_chains))
    log_fan = np.log(fan)
    n = graph.n_chains
    born = np.zeros(ring * n)             # slot-major ring of the mass born on each chain
    offset = np.arange(n) - lag * n       # ((k − lag) mod ring)·n + c = (k n + offset) mod ring n
    size = ring * n
    whole = not np.any(frac)
    first_steps = math.ceil(float(trip.max()) / dt)
    mass = np.ones(steps_total + 1)
    entropy = np.zeros(steps_total + 1)
    first_left, alive, split_sum = 1.0, 0.0, 0.0
    now = offset % size
    for k in range(1, steps_total + 1):
        check_stop()
        now += n
        now[now >= size] -= size
        leave = np.take(born, now)
        if not whole:
            leave = (1.0 - frac) * leave + frac * np.take(born, (now - n) % size)
        out = leave
        if k <= first_steps:
            first = graph.share * (np.clip(k * dt / trip, 0.0, 1.0)
                                   - np.clip((k - 1) * dt / trip, 0.0, 1.0))
            out = leave + first
            first_left -= float(first.sum())
        new = split @ out
        born[(k % ring) * n:(k % ring + 1) * n] = new
        alive += float(new.sum() - leave.sum())
        split_sum += float(np.sum(out * log_fan))    # not BLAS: no thread start per step
        mass[k], entropy[k] = first_left + alive, split_sum
    return SplitProfile(dt, checks.readonly(mass, copy=False),
                        checks.readonly(entropy, copy=False))


def mode_split_mc(graph: ChainGraph, target_speed_mps: float, times_s: ArrayLike, runs: int,
                  seed: int | np.random.Generator = 0) -> ModeProbabilities:
    """``P_D(t)`` by Monte Carlo, the check of Lemma 5 in §5.3: ``runs`` modes started at uniform
    points on the directed roads, each split on the chain graph until ``max(times_s)``;
    ``P_D`` is ``D`` times the mean number of alive modes of degree ``D`` (Eq. 45).

    Parameters
    ----------
    graph
        Chains of the road map.
    target_speed_mps
        Target speed (m/s).
    times_s
        Times (s) at which to count modes.
    runs
        Number of runs, ≥ 1.
    seed
        Seed or generator; the estimate is deterministic for a seed.
    """
    speed = checks.positive("target_speed_mps", target_speed_mps)
    t = _times(times_s)
    count = checks.count("runs", runs, 1)
    rng = np.random.default_rng(seed)
    chain = rng.choice(graph.n_chains, size=count, p=graph.share).astype(np.int64)
    trip = graph.length_m / speed
    death = rng.uniform(0.0, 1.0, size=count) * trip[chain]       # first exit, U ~ U(0, T_r)
    birth = np.zeros(count)
    denom = np.ones(count, dtype=np.int64)                          # degree D = 1 / denom
    horizon = float(t.max())
    per_time: dict[int, NDArray[np.float64]] = {}
    while chain.size:
        live = (birth[:, None] <= t[None, :]) & (t[None, :] < death[:, None])
        kinds, which = np.unique(denom, return_inverse=True)
        group = sp.csr_array((1.0 / denom, (which.reshape(-1), np.arange(denom.size))),
                             shape=(kinds.size, denom.size))
        mass = np.asarray(group @ live.astype(np.float64))
        for d, row in zip(kinds.tolist(), mass, strict=True):
            per_time[d] = per_time.get(d, 0.0) + row
        going = death < horizon
        fan = graph.fanout[chain[going]]
        first = np.repeat(graph.child_ptr[chain[going]], fan)
        offset = np.arange(first.size) - np.repeat(np.cumsum(fan) - fan, fan)
        kids = graph.child_idx[first + offset]
        birth = np.repeat(death[going], fan)
        death = birth + trip[kids]
        denom = np.repeat(denom[going] * fan, fan)
        chain = kids
    degrees = tuple(sorted((Fraction(1, d) for d in per_time), reverse=True))
    prob = np.array([per_time[d.denominator] / count for d in degrees])
    return ModeProbabilities(checks.readonly(t), degrees, checks.readonly(prob, copy=False))
