"""What a road scenario builds once and its missions share: the road network, the diffusion
operators of the LRT (3.8) and of the trackers (4.2), and the road kernels the RBPF's node
beliefs are read through."""

from __future__ import annotations

from dataclasses import dataclass, field

from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.road_kernel import RoadKernel
from searchtrack.models import RoadNetwork
from searchtrack.sim.roads.scenario import Scenario


@dataclass(frozen=True, eq=False)
class World:
    """What a scenario builds once: the road network and the filter's operators.

    The LRT diffuses at ``filter.alpha`` with decay ``C`` (3.8); the trackers (4.2), and with
    them the reacquisition horizon ``T_r`` of the guidance, at ``filter.tracker_alpha`` when
    it is set, else at the same ``alpha`` (the thesis). Road kernels
    (:mod:`searchtrack.estimate.road_kernel`) are built on first use and kept.
    """

    network: RoadNetwork
    lrt_diffusion: GraphDiffusion
    tracker_diffusion: GraphDiffusion
    kernels: dict[float, RoadKernel] = field(default_factory=dict, repr=False)

    @classmethod
    def build(cls, scenario: Scenario, network: RoadNetwork | None = None) -> World:
        """Build (or reuse ``network``) and prepare the diffusion operators."""
        net = network if network is not None else scenario.map.build()
        f = scenario.filter
        world = cls(
            net,
            GraphDiffusion.on_network(net, f.alpha, scenario.dt_s, decay_c=f.decay_c),
            GraphDiffusion.on_network(net, f.tracker_diffusivity, scenario.dt_s),
        )
        _ = world.lrt_diffusion.operator, world.tracker_diffusion.operator  # build them now
        return world

    def road_kernel(self, sigma_m: float) -> RoadKernel:
        """The Gaussian road kernel of ``sigma_m`` (m) on the network, built once."""
        key = float(sigma_m)
        if key not in self.kernels:
            self.kernels[key] = RoadKernel(self.network, key)
        return self.kernels[key]

    def mismatch(self, scenario: Scenario) -> str | None:
        """Why this world's operators are not those ``scenario`` builds (``None``: they are):
        a different LRT or tracker diffusivity, decay or time step."""
        f = scenario.filter
        lrt, trk = self.lrt_diffusion, self.tracker_diffusion
        wanted = {"filter.alpha": (lrt.alpha, f.alpha), "filter.decay_c": (lrt.decay_c, f.decay_c),
                  "filter.tracker_alpha": (trk.alpha, f.tracker_diffusivity),
                  "dt_s": (trk.dt_s, scenario.dt_s)}
        off = [f"{k}: world {have:g}, scenario {want:g}" for k, (have, want) in wanted.items()
               if have != float(want)]
        return "; ".join(off) if off else None
