"""The library's compiled kernels: which numba kernel sets exist, whether their machine code is
already in numba's on-disk cache, and how to compile each one ahead of use.

Several hot loops are numba kernels compiled with ``cache=True``: the OPTW iterated local search
and labelling DP, the network simplex behind EMD association, the road particle filter and the
radio TBD likelihood. The first process to call one compiles it (seconds to tens of seconds per
set) and numba stores the machine code on disk; later processes load it in well under a second.
:func:`cold_sets` tells, without compiling anything, which sets a command would have to compile,
so that the command can say so before it goes quiet; :func:`warm` compiles them (the
``searchtrack warm-up`` command and the install step of ``make`` run it for every set).

Which sets a solve compiles is said once, by its backend (:attr:`~searchtrack.core.registry.
Backend.kernels`): :func:`kernels_of` reads it from the registries, and the sets ``warm-up``
compiles are those the registered backends list plus the estimators' (:func:`warm_up_sets`).
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import logging
import multiprocessing
import time
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from searchtrack.core.registry import Registry
from searchtrack.plan.optw.solve import BACKENDS as OPTW_BACKENDS
from searchtrack.plan.optw.solve import BP_KERNELS, ILS_KERNELS, LABELLING_KERNELS, warm_set

log = logging.getLogger(__name__)


def _warm_simplex() -> None:
    from searchtrack.estimate.transport import simplex

    simplex.warm_up()


def _warm_road_filter() -> None:
    """One filter on a 3 × 3 grid of roads through a hit, a miss and a resampling, and RBPFs
    with the robust prior's jumps and with the draws near detections through a hit (the joins of
    their draws)."""
    from searchtrack.estimate.road_births import DetectionBirths
    from searchtrack.estimate.road_jumps import TargetJumps
    from searchtrack.estimate.road_pf import RoadParticleFilter
    from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
    from searchtrack.models import grid_network
    from searchtrack.models.road_particles import DirectedRoads

    rng = np.random.default_rng(0)
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    pf = RoadParticleFilter(roads, 200, rng)
    pf.predict(1.0, rng)
    pf.update(np.array([100.0, 100.0]), np.array([100.0, 100.0]), rng)
    pf.update(None, np.array([0.0, 0.0]), rng)
    pf.likelihood_sum(np.array([100.0, 100.0]))
    small = RBPFConfig(n_targets=1, n_histories=2, n_particles=50)
    for config in (dataclasses.replace(small, jumps=TargetJumps()),
                   dataclasses.replace(small, births=DetectionBirths())):
        rbpf = RoadRBPF(roads, config, rng)
        rbpf.predict(1.0, rng)
        rbpf.update(np.array([[100.0, 100.0]]), np.array([100.0, 100.0]), rng)


def _warm_radio() -> None:
    """Two seconds of each radio filter, with one planning call, on the paper's scenario."""
    from searchtrack.models.radio import RadioScenario
    from searchtrack.plan.radio import RadioPlanSettings
    from searchtrack.sim.radio.config import RadioMissionConfig
    from searchtrack.sim.radio.mission import run_radio_mission

    scenario = dataclasses.replace(RadioScenario.paper(), duration_s=2.0)
    plan = RadioPlanSettings(horizon=1, plan_particles=20)
    for filt, planner in (("tbd", "renyi"), ("dtt", "straight")):
        config = RadioMissionConfig(filter=filt, planner=planner, particles_per_label=20,
                                    plan=plan)
        run_radio_mission(scenario, config, seed=0)


def _warm_phd() -> None:
    """Three scans of the standard SMC-PHD scenario (prediction, the gated update, resampling
    and extraction)."""
    from searchtrack.estimate.phd import PHDConfig, PHDState, SensorScan, step
    from searchtrack.sim.particles.scenario import standard_scenario

    scenario = standard_scenario(0, n_targets=2, n_scans=3)
    rng = np.random.default_rng(0)
    state = PHDState.empty(scenario.motion.state_dim, scenario.motion.position_dim)
    config = PHDConfig(region=scenario.sensor.area)
    for z in scenario.scans:
        state, _ = step(state, [SensorScan(scenario.sensor, np.zeros(3), z)], scenario.motion,
                        config, scenario.dt_s, rng)


@dataclass(frozen=True)
class KernelSet:
    """A group of numba kernels compiled together.

    Attributes
    ----------
    name
        Short name (``searchtrack warm-up --only NAME``).
    description
        What the kernels compute.
    modules
        The modules whose ``cache=True`` dispatchers form the set.
    warm
        Compiles every kernel of the set, with the argument types real calls use.
    """

    name: str
    description: str
    modules: tuple[str, ...]
    warm: Callable[[], None]


ROAD_FILTER_KERNELS, RADIO_KERNELS, PHD_KERNELS = "road-filter", "radio", "phd"
"""The sets of the road particle filter, of the radio filters and of the SMC-PHD filter."""

KERNEL_SETS: dict[str, KernelSet] = {s.name: s for s in (
    KernelSet(ILS_KERNELS, "OPTW iterated local search",
              ("searchtrack.plan.optw.ils_kernels", "searchtrack.plan.optw.ils_search"),
              functools.partial(warm_set, ILS_KERNELS)),
    KernelSet(LABELLING_KERNELS, "OPTW labelling DP",
              ("searchtrack.plan.optw.labelling_kernels",
               "searchtrack.plan.optw.labelling_primitives"),
              functools.partial(warm_set, LABELLING_KERNELS)),
    KernelSet("simplex", "network simplex (EMD association)",
              ("searchtrack.estimate.transport.simplex_kernels",
               "searchtrack.estimate.transport.dijkstra_kernels",
               "searchtrack.estimate.transport.simplex_start",
               "searchtrack.estimate.transport.pair_batch",
               "searchtrack.estimate.signature_kernels"), _warm_simplex),
    KernelSet(ROAD_FILTER_KERNELS, "road particle filter",
              ("searchtrack.estimate.road_filter_kernels",
               "searchtrack.estimate.road_resample_kernels", "searchtrack.estimate.road_births"),
              _warm_road_filter),
    KernelSet(PHD_KERNELS, "SMC-PHD prediction, gated update and resampling",
              ("searchtrack.estimate.phd.kernels", "searchtrack.estimate.phd.gated"), _warm_phd),
    KernelSet(RADIO_KERNELS, "radio TBD likelihood and propagation",
              ("searchtrack.estimate.radio.likelihood", "searchtrack.estimate.labelled_motion",
               "searchtrack.estimate.labelled_particles", "searchtrack.plan.radio.fused"),
              _warm_radio),
    # last: the install's pool compiles the sets in this order, and this one is short
    KernelSet(BP_KERNELS, "OPTW branch-and-price: pricing join, route enumeration, arc fixing",
              ("searchtrack.plan.optw.labelling_join", "searchtrack.plan.optw.bp_enumeration",
               "searchtrack.plan.optw.bp_fixing"),
              functools.partial(warm_set, BP_KERNELS)),
)}
"""Every kernel set of the library, by name."""

FILTER_KERNELS = (ROAD_FILTER_KERNELS, PHD_KERNELS, RADIO_KERNELS)
"""The sets the estimators compile, which no solver registry lists: the road particle filter
(and the RBPF built on it), the SMC-PHD filter, and the radio TBD-LMB / detection-then-track
filters (whose look-ahead kernels the radio planning backends share)."""


def kernels_of(*registries: Registry[Any, Any]) -> tuple[str, ...]:
    """The kernel sets the backends of ``registries`` list (:attr:`~searchtrack.core.registry.
    Backend.kernels`), each once, in :data:`KERNEL_SETS` order (names of no set last)."""
    named = {k for r in registries for name in r.names() for k in r.get(name).kernels}
    return (*(n for n in KERNEL_SETS if n in named), *sorted(named - KERNEL_SETS.keys()))


OPTW_KERNELS = kernels_of(OPTW_BACKENDS)
"""The sets an OPTW solve may use (the ``auto`` backend runs both)."""


def solver_registries() -> list[Registry[Any, Any]]:
    """Every solver registry of the library (importing the solver families)."""
    from searchtrack.estimate.association import BACKENDS as association
    from searchtrack.estimate.emd_matrix import EMD_MATRIX_BACKENDS
    from searchtrack.estimate.transport.solve import EMD_BACKENDS, GRAPH_EMD_BACKENDS
    from searchtrack.plan.assign.solve import BACKENDS as assign
    from searchtrack.plan.guidance.solve import BACKENDS as guidance
    from searchtrack.plan.radio.solve import BACKENDS as radio
    from searchtrack.plan.road_search.solve import BACKENDS as road_search
    from searchtrack.plan.search.solve import BACKENDS as search
    from searchtrack.plan.trajectory.solve import BACKENDS as trajectory

    return [OPTW_BACKENDS, assign, search, trajectory, road_search, radio, guidance,
            association, EMD_MATRIX_BACKENDS, EMD_BACKENDS, GRAPH_EMD_BACKENDS]


def warm_up_sets() -> tuple[str, ...]:
    """The sets ``searchtrack warm-up`` compiles by default: every set a registered backend
    lists, and the estimators' (:data:`FILTER_KERNELS`), in :data:`KERNEL_SETS` order."""
    named = {*kernels_of(*solver_registries()), *FILTER_KERNELS}
    return (*(n for n in KERNEL_SETS if n in named), *sorted(named - KERNEL_SETS.keys()))


def road_mission_kernels() -> tuple[str, ...]:
    """The sets a road mission may use: reacquisition routes (OPTW), EMD association (the EMD
    matrix backends) and the road filter."""
    from searchtrack.estimate.emd_matrix import EMD_MATRIX_BACKENDS

    return (*kernels_of(OPTW_BACKENDS, EMD_MATRIX_BACKENDS), ROAD_FILTER_KERNELS)


def dispatchers(module: str) -> list[Any]:
    """The numba dispatchers compiled with ``cache=True`` that ``module`` defines."""
    from numba.core.dispatcher import Dispatcher

    mod = importlib.import_module(module)
    return [f for f in vars(mod).values()
            if isinstance(f, Dispatcher) and getattr(f, "__module__", None) == module
            and getattr(f, "_cache", None) is not None
            and type(getattr(f, "_cache", None)).__name__ != "NullCache"]


def _cached(dispatcher: Any) -> bool:
    """True when numba's index for ``dispatcher`` is on disk and matches its source file."""
    try:
        return bool(dispatcher._cache._cache_file._load_index())
    except Exception:  # numba internals moved: say "cold" rather than fail
        log.debug("cannot read numba's cache index of %s", dispatcher, exc_info=True)
        return False


def uncached(kernel_set: KernelSet) -> list[str]:
    """The kernels of ``kernel_set`` with no machine code in numba's cache (``module.name``)."""
    return [f"{m}.{f.__name__}" for m in kernel_set.modules for f in dispatchers(m)
            if not _cached(f)]


def is_cold(kernel_set: KernelSet) -> bool:
    """True when some module of ``kernel_set`` has none of its kernels in numba's cache (never
    compiled here, or its source changed since). Kernels that numba folds into their callers
    never get an index of their own, so one cached kernel per module is taken as warm."""
    return any(not any(_cached(f) for f in dispatchers(m)) for m in kernel_set.modules)


def cold_sets(names: Iterable[str]) -> list[KernelSet]:
    """The sets among ``names`` that a process would have to compile before using them."""
    return [KERNEL_SETS[n] for n in names if is_cold(KERNEL_SETS[n])]


def _warm_by_name(name: str) -> float:
    """Compile the set ``name`` in this process; the seconds it took (a pool worker's task)."""
    started = time.perf_counter()
    KERNEL_SETS[name].warm()
    return time.perf_counter() - started


def warm(kernel_sets: Iterable[KernelSet], jobs: int = 1) -> dict[str, float]:
    """Compile (or load from the cache) every set; seconds each took, by name.

    With ``jobs > 1`` the sets compile in that many fresh processes at once (numba compiles on
    one core, and each process writes its machine code to the shared on-disk cache, replacing
    files atomically), so the whole install-time compile takes about as long as its largest
    share rather than the sum (this process then loads them from the cache on first use)."""
    sets = list(kernel_sets)
    took: dict[str, float] = {}
    if jobs > 1 and len(sets) > 1:
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(min(jobs, len(sets)), mp_context=context) as pool:
            for ks, seconds in zip(sets, pool.map(_warm_by_name, [ks.name for ks in sets]),
                                   strict=True):
                took[ks.name] = seconds
                log.info("%s kernels ready in %.1f s", ks.name, seconds)
        return took
    for ks in sets:
        took[ks.name] = _warm_by_name(ks.name)
        log.info("%s kernels ready in %.1f s", ks.name, took[ks.name])
    return took
