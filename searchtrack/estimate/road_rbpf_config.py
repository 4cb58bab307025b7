"""The sizes, models and options of the Rao-Blackwellized road filter
(:class:`~searchtrack.estimate.road_rbpf.RoadRBPF`, Moore et al. 2021 §3)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.road_births import DetectionBirths
from searchtrack.estimate.road_jumps import TargetJumps
from searchtrack.estimate.road_resampling import KLDSampling, ResamplePolicy, SpeedRoughening
from searchtrack.models.disc_sensor import DiscSensor
from searchtrack.models.road_particles import CourierRoadMotion, RoadMotion


@dataclass(frozen=True)
class RBPFConfig:
    """Sizes and models of a :class:`RoadRBPF`.

    Parameters
    ----------
    n_targets
        ``M ≥ 1``, known and fixed (paper §1).
    n_histories
        ``H ≥ 1`` top-level (association history) particles (10 in the paper).
    n_particles
        ``N ≥ 1`` particles per target filter (500), the cap when ``counts`` is set.
    motion, sensor
        Target motion (Eq. 9, or the drive-and-stop
        :class:`~searchtrack.models.road_particles.CourierRoadMotion`, whose speeds the
        particles then carry) and measurement model (Eq. 10–11).
    resample, history_resample
        When the target filters and the histories resample (default: every update).
    association
        ``"sequential"`` (one DAS draw per detection, duplicates allowed) or ``"joint"``
        (one-to-one within a scan).
    history_weight
        ``"marginal"`` (``(1/M) Σ_m L_m``) or ``"sampled"`` (``L_c``).
    weigh_misses
        Multiply the history weights by the no-detection likelihood of negative updates.
    miss_undetected
        Negative update on the filters without a detection in a scan that had detections.
    bin_m
        Bin length (m) of the entropies and MAP positions.
    keep_history
        Keep every history's full association sequence (:meth:`RoadRBPF.association_history`).
    break_symmetry
        Give the first detection to target 0 in every history (for exchangeable priors; turn it
        off when the initial clouds tell the targets apart).
    jumps
        The robust prior of :mod:`searchtrack.estimate.road_jumps` (targets may leave their
        predicted clouds, beyond the paper); ``None``: paper 000's motion prior alone.
    births
        The rejuvenation near detections of :mod:`searchtrack.estimate.road_births` (each
        cloud's prior regularised near a detection, beyond the paper); ``None``: the clouds
        weighed as they are. Not with ``jumps`` (each replaces the detection update).
    roughening
        Roughening of the particles' speeds after each resampling of the weights (not after a
        join with draws near a detection, which bring fresh speeds;
        :class:`~searchtrack.estimate.road_resampling.SpeedRoughening`, beyond the paper;
        needs the drive-and-stop motion); ``None``: none.
    counts
        KLD-sampling (beyond the paper): each target filter's particle count follows its spread,
        at most ``N`` (:class:`~searchtrack.estimate.road_resampling.KLDSampling`); ``None``:
        ``N`` for every filter, as the paper.
    """

    n_targets: int
    n_histories: int = 10
    n_particles: int = 500
    motion: RoadMotion | CourierRoadMotion = field(default_factory=RoadMotion)
    sensor: DiscSensor = field(default_factory=DiscSensor)
    resample: ResamplePolicy = field(default_factory=ResamplePolicy)
    history_resample: ResamplePolicy = field(default_factory=ResamplePolicy)
    association: Literal["sequential", "joint"] = "sequential"
    history_weight: Literal["marginal", "sampled"] = "marginal"
    weigh_misses: bool = True
    miss_undetected: bool = True
    bin_m: float = 5.0
    keep_history: bool = False
    break_symmetry: bool = True
    jumps: TargetJumps | None = None
    births: DetectionBirths | None = None
    roughening: SpeedRoughening | None = None
    counts: KLDSampling | None = None

    def __post_init__(self) -> None:
        for name in ("n_targets", "n_histories", "n_particles"):
            object.__setattr__(self, name, checks.count(name, getattr(self, name), 1))
        if not isinstance(self.motion, (RoadMotion, CourierRoadMotion)):
            raise InvalidInputError("motion", self.motion,
                                    "must be a RoadMotion or a CourierRoadMotion")
        for name, kind in (("sensor", DiscSensor), ("resample", ResamplePolicy),
                           ("history_resample", ResamplePolicy)):
            if not isinstance(getattr(self, name), kind):
                raise InvalidInputError(name, getattr(self, name), f"must be a {kind.__name__}")
        if self.association not in ("sequential", "joint"):
            raise InvalidInputError("association", self.association,
                                    "must be 'sequential' or 'joint'")
        if self.history_weight not in ("marginal", "sampled"):
            raise InvalidInputError("history_weight", self.history_weight,
                                    "must be 'marginal' or 'sampled'")
        object.__setattr__(self, "bin_m", checks.positive("bin_m", self.bin_m))
        if self.jumps is not None and not isinstance(self.jumps, TargetJumps):
            raise InvalidInputError("jumps", self.jumps, "must be a TargetJumps or None")
        if self.births is not None and not isinstance(self.births, DetectionBirths):
            raise InvalidInputError("births", self.births, "must be a DetectionBirths or None")
        if self.roughening is not None and (not isinstance(self.roughening, SpeedRoughening)
                                            or self.speeds is None):
            raise InvalidInputError("roughening", self.roughening, "must be a SpeedRoughening "
                                    "or None, and needs the drive-and-stop motion")
        if self.counts is not None and not isinstance(self.counts, KLDSampling):
            raise InvalidInputError("counts", self.counts, "must be a KLDSampling or None")
        if self.births is not None and self.jumps is not None:
            raise InvalidInputError("births", self.births, "jumps are set: choose one of the "
                                    "two detection proposals")

    @property
    def speeds(self) -> CourierRoadMotion | None:
        """The speed state the particles carry: the motion when it is the drive-and-stop
        model, else ``None``."""
        return self.motion if isinstance(self.motion, CourierRoadMotion) else None
