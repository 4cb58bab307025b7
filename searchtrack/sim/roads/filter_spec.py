"""What a road mission estimates with (thesis 001 Ch. 3–4, or paper 000's RBPF), as a frozen,
validated part of a :class:`~searchtrack.sim.roads.scenario.Scenario`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from searchtrack.core.checks import non_negative, positive
from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.association import BACKENDS as ASSOCIATION_BACKENDS

ASSOCIATORS: tuple[str, ...] = tuple(ASSOCIATION_BACKENDS.names())
SEARCH_FIELDS: tuple[str, ...] = ("particles", "lrt")


@dataclass(frozen=True)
class FilterSpec:
    """The graph LRT and node trackers (Tables 6.2 and 6.4).

    Parameters
    ----------
    alpha
        Target diffusivity ``α`` (on the unweighted Laplacian: hops²/s).
    decay_c
        LRT decay term ``C``.
    phi_max
        Detection threshold ``φ_max``.
    p_min
        Tracker dissolution threshold ``P_min``.
    gate_m
        EMD gate ``ℰ`` (m of road distance).
    associator
        The pairing backend of the EMD association, a name of
        :data:`searchtrack.estimate.association.BACKENDS`: ``"greedy"`` (Algorithm 1),
        ``"optimal"`` (gated assignment) or ``"auto"``.
    birth_weighting
        ``"llr"`` or ``"likelihood_ratio"`` (see :class:`~searchtrack.estimate.LRTInitiator`).
    merge_radius_m
        A detection within this distance of a live tracker's peak is suppressed without a birth
        (100 m, the default validity distance: a second tracker that close to the same target
        would count as spurious; 0 births every detection, the thesis read literally).
    llr_floor
        Lower bound on ``φ`` where the sensors update it: −20 (−2 φ_max) by default; ``-inf`` is
        the thesis read literally. Without it, negative evidence piles up to hundreds of nats
        where the UAVs fly and buries a target that later drives there: in experiment 1 on the
        small maps over half the runs then never find every target (see
        :func:`~searchtrack.estimate.lrt.update_likelihood_field`).
    negative_information
        Trackers a UAV covers without an associated fix lose ``P_d`` of their probability on
        the footprint (renormalised; a rule of this library, the thesis has none). On by default:
        with the floor, a tracker that lost its target spreads and dissolves instead of lingering
        as a spurious track while the target is found again (demo, 4 seeds: MOC 36 % → 53 %,
        PVT 85 % → 92 %).
    belief
        What the mission estimates with: ``"lrt"`` (default), the thesis's likelihood-ratio
        field and node trackers (every setting above), or ``"rbpf"``, the Rao-Blackwellized
        particle filter of Moore et al. 2021 (paper 000) for the known number of targets, read
        by the same guidance (:mod:`searchtrack.sim.roads.rbpf_belief`; it uses ``p_min``, and
        ``alpha`` — or ``tracker_alpha`` when set — for the reacquisition horizon; the
        settings above also set the LRT whose ``φ`` is its search field, see
        ``search_field``).
    histories, particles
        The RBPF's association histories ``H`` and particles per target filter ``N`` (10 and
        500, the paper's); integers ≥ 1, used when ``belief = "rbpf"``.
    jump_rate_per_s
        ``λ ≥ 0`` of the RBPF's robust prior (:mod:`searchtrack.estimate.road_jumps`, beyond
        paper 000): the rate at which a target may leave its predicted cloud; 0 (default): the
        paper's prior. Used when ``belief = "rbpf"``.
    kld_epsilon
        KLD-sampling of the RBPF (beyond paper 000; Fox 2003, see
        :class:`~searchtrack.estimate.road_resampling.KLDSampling`): each target filter's
        particle count follows its spread, at most ``particles``, bounding the
        Kullback-Leibler error by this ``ε`` in ``(0, 1)`` on bins of the sensor's position noise
        and of the particles' speeds (:func:`~searchtrack.sim.roads.rbpf_belief.rbpf_config`).
        ``None`` (default): every filter keeps ``particles``. Used when ``belief = "rbpf"``.
    search_field
        The field the RBPF mission's searching UAVs climb (``belief = "rbpf"``; see
        :mod:`searchtrack.sim.roads.rbpf_belief`): ``"lrt"`` (default), the thesis's
        likelihood-ratio field ``φ`` of an LRT flown beside the RBPF on the same scans (reading
        the footprints' ``ζ``), which keeps a look for about ``C/α``; or ``"particles"``, the
        untracked targets' particle mass, which refills a searched footprint as fast as the
        couriers drive in, so the gradient search wanders on it. The mission scores the RBPF's
        tracks either way.
    node_resolution_m
        The RBPF's node beliefs as the guidance reads them (``belief = "rbpf"``): each
        localised target's node belief blurred along the roads by a Gaussian of this standard
        deviation (m; :mod:`searchtrack.estimate.road_kernel`). ``None`` (default): the
        sensor's position noise ``s``, the resolution the thesis's trackers and its ``ϱ`` work
        at; 0: the cloud's own nearer-end-node beliefs (paper 000's binning), whose peak stays
        near 1 while a tight cloud drives on unseen, so under (5.16) a UAV comes back only once
        the cloud has split. Localisation (``p_min``) reads the cloud's own beliefs either way.
    tracker_alpha
        Diffusivity of the node trackers' prediction (4.2) (hops²/s), ``None`` (default): the
        thesis's one ``alpha`` for the LRT and the trackers. It also sets the reacquisition
        horizon ``T_r`` (the time a tracker's peak takes to fall to ``P_min`` under that same
        prediction). The courier targets spread far faster than ``alpha`` = 0.447: the mean
        square road distance they cover grows as ``2·α·t`` with α ≈ 14 hops²/s on the
        Aguascalientes map (t = 20–120 s), while the LRT's slow spread is what keeps search
        evidence local.
    handover
        Identity hand-over on re-detection (a rule of this library, the thesis has none): a
        tracker born where a live tracker has lost its target (no fix for 1 s, half its mass
        within ``2·gate_m`` road distance of the birth) replaces that tracker's distribution,
        which keeps its ``track_id``, instead of becoming a second tracker (see
        :mod:`searchtrack.estimate.handover`; ``belief = "lrt"`` only). On by default:
        in experiment 2 (10 seeds × 4 altitudes × 2 strategies per fleet) it raised PVT from
        0.82 to 0.88 (3 UAVs / 2 targets) and 0.84 to 0.88 (1 / 4) at an unchanged MOC;
        ``false`` is the thesis read literally.
    """

    alpha: float = 0.447
    decay_c: float = 50.0
    phi_max: float = 10.0
    p_min: float = 0.07
    gate_m: float = 300.0
    associator: str = "greedy"
    birth_weighting: Literal["llr", "likelihood_ratio"] = "llr"
    merge_radius_m: float = 100.0
    llr_floor: float = -20.0
    negative_information: bool = True
    belief: str = "lrt"
    histories: int = 10
    particles: int = 500
    jump_rate_per_s: float = 0.0
    kld_epsilon: float | None = None
    search_field: str = "lrt"
    node_resolution_m: float | None = None
    tracker_alpha: float | None = None
    handover: bool = True

    def __post_init__(self) -> None:
        for name in ("alpha", "decay_c", "phi_max", "gate_m"):
            positive(name, getattr(self, name))
        if self.tracker_alpha is not None:
            positive("tracker_alpha", self.tracker_alpha)
        non_negative("jump_rate_per_s", self.jump_rate_per_s)
        if self.kld_epsilon is not None and not (
                isinstance(self.kld_epsilon, (int, float)) and 0.0 < self.kld_epsilon < 1.0):
            raise InvalidInputError("kld_epsilon", self.kld_epsilon, "must be in (0, 1) or unset")
        if self.node_resolution_m is not None:
            non_negative("node_resolution_m", self.node_resolution_m)
        if not isinstance(self.handover, bool):
            raise InvalidInputError("handover", self.handover, "must be true or false")
        from searchtrack.sim.roads.filters import FILTERS  # the registry imports this module

        if self.belief not in FILTERS.names():
            raise InvalidInputError("belief", self.belief, f"must be one of {FILTERS.names()}")
        if self.search_field not in SEARCH_FIELDS:
            raise InvalidInputError("search_field", self.search_field,
                                    f"must be one of {list(SEARCH_FIELDS)}")
        for name in ("histories", "particles"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise InvalidInputError(name, value, "must be an integer ≥ 1")
        if math.isnan(self.llr_floor) or self.llr_floor >= 0.0:
            raise InvalidInputError("llr_floor", self.llr_floor, "must be < 0 (or -inf: none)")
        if not (math.isfinite(self.merge_radius_m) and self.merge_radius_m >= 0.0):
            raise InvalidInputError("merge_radius_m", self.merge_radius_m, "must be finite, ≥ 0")
        if not 0.0 < self.p_min < 1.0:
            raise InvalidInputError("p_min", self.p_min, "must be in (0, 1)")
        if self.associator not in ASSOCIATORS:
            raise InvalidInputError("associator", self.associator,
                                    f"must be one of {list(ASSOCIATORS)}")
        if self.birth_weighting not in ("llr", "likelihood_ratio"):
            raise InvalidInputError("birth_weighting", self.birth_weighting,
                                    "must be 'llr' or 'likelihood_ratio'")

    @property
    def tracker_diffusivity(self) -> float:
        """The trackers' diffusivity: ``tracker_alpha`` when set, else ``alpha``."""
        return self.alpha if self.tracker_alpha is None else self.tracker_alpha
