"""The settings of paper 002's closed loop (Nguyen et al.) and the names they take: the filters,
the path strategies of Exp. 2, the planning backends and the spectrogram simulators.

:func:`~searchtrack.sim.radio.mission.run_radio_mission` flies a :class:`RadioMissionConfig`;
the names and defaults live here, apart from the filters themselves, so that the command line
and the campaign experiment read them without loading a filter.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.radio import RadioPlanSettings
from searchtrack.plan.radio.problem import REWARDS
from searchtrack.plan.radio.solve import BACKENDS as PLAN_REGISTRY
from searchtrack.sim.radio.run import SIMULATORS

FILTERS = ("tbd", "dtt")
"""The filters: the TBD-LMB on the raw STFT, detection-then-track (§IV-B); their classes are
:data:`searchtrack.sim.radio.track_job.FILTERS`."""

STRAIGHT = "straight"
"""The planner that flies the straight sweep of Exp. 2 instead of planning."""

PLANNERS = (*REWARDS, STRAIGHT)
"""The path strategies of Exp. 2: Rényi and Cauchy–Schwarz planning (the planning rewards of
:data:`~searchtrack.plan.radio.problem.REWARDS`), the straight sweep."""

PLAN_BACKENDS = tuple(name for name in PLAN_REGISTRY.names() if name != STRAIGHT)
"""The backends the ``renyi`` and ``cs`` planners may use: the radio planning registry's, less
the straight sweep (flown as the ``straight`` planner)."""

MEASUREMENTS = tuple(SIMULATORS)
"""How spectrograms are simulated (:data:`~searchtrack.sim.radio.run.SIMULATORS`)."""

MAX_ROUGHENING_M = 1e4
"""Largest roughening floor ``roughening_m`` (m), as the filter's own
(:attr:`~searchtrack.estimate.radio.filter.FilterConfig.roughening_m`)."""


@dataclass(frozen=True)
class RadioMissionConfig:
    """How one closed-loop run is flown and filtered.

    Parameters
    ----------
    filter
        ``"tbd"`` or ``"dtt"``.
    planner
        ``"renyi"``, ``"cs"`` (information planning, eq. 45) or ``"straight"`` (the diagonal
        sweep of Exp. 2).
    backend
        The planning backend for ``renyi``/``cs``, one of :data:`PLAN_BACKENDS`.
    particles_per_label
        Particles of each label's Bernoulli component (the paper: 50 000; at most
        :data:`~searchtrack.estimate.radio.filter.MAX_PARTICLES_PER_LABEL`).
    plan
        Planner settings; its ``reward`` is set from ``planner``.
    plan_time_limit_s
        Time limit of one planning call (the paper assumes it finishes within N_p = 5 s).
    measurement
        ``"stft"`` or ``"time"`` (:data:`MEASUREMENTS`).
    keep_out
        Fly each primitive through a trajectory controller keeping r_min from every estimate.
    roughening_m
        The filter's roughening floor (m,
        :attr:`~searchtrack.estimate.radio.filter.FilterConfig.roughening_m`); 0: none.
    temper_correlated
        On time-domain spectrograms (``measurement = "time"``), temper the TBD likelihood by
        :func:`~searchtrack.estimate.radio.likelihood.correlated_cells_temper` (neighbouring
        bins correlate there); no effect on STFT-domain ones or on DTT.
    replan_on_breach
        Plan again at the next second when, after a measurement, the updated belief's void
        probability (eq. 44, with the plan's keep-out radii) at a pose still to be flown is no
        more than ``P_vmin``, rather than fly the rest of the planning interval.
    ospa_c_m, ospa_p
        OSPA cut-off and order (§IV-B: 100 m, 1).
    """

    filter: str = "tbd"
    planner: str = "renyi"
    backend: str = "exhaustive"
    particles_per_label: int = 50_000
    plan: RadioPlanSettings = field(default_factory=RadioPlanSettings)
    plan_time_limit_s: float = 5.0
    measurement: str = "stft"
    keep_out: bool = False
    roughening_m: float = 0.0
    temper_correlated: bool = True
    replan_on_breach: bool = False
    ospa_c_m: float = 100.0
    ospa_p: float = 1.0

    def __post_init__(self) -> None:
        from searchtrack.estimate.radio.filter import MAX_PARTICLES_PER_LABEL

        checks.choice("filter", self.filter, FILTERS)
        checks.choice("planner", self.planner, PLANNERS)
        checks.choice("measurement", self.measurement, MEASUREMENTS)
        if checks.count("particles_per_label", self.particles_per_label,
                        least=1) > MAX_PARTICLES_PER_LABEL:
            raise InvalidInputError("particles_per_label", self.particles_per_label,
                                    f"must be an integer in [1, {MAX_PARTICLES_PER_LABEL}]")
        checks.positive("plan_time_limit_s", self.plan_time_limit_s)
        checks.real("roughening_m", self.roughening_m, low=0.0, high=MAX_ROUGHENING_M)
        checks.positive("ospa_c_m", self.ospa_c_m)
        checks.positive("ospa_p", self.ospa_p)
        for name in ("keep_out", "temper_correlated", "replan_on_breach"):
            if not isinstance(getattr(self, name), bool):
                raise InvalidInputError(name, getattr(self, name), "must be true or false")
        if self.planner != STRAIGHT and self.plan.reward != self.planner:
            object.__setattr__(self, "plan", dataclasses.replace(self.plan, reward=self.planner))
