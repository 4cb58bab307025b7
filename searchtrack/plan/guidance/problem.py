"""One step of guidance as a solver problem: the view, the configuration, the tracker predictor,
and the routes (reacquisition, search) kept flying from the step before."""

from __future__ import annotations

from dataclasses import dataclass

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import NodePredictor
from searchtrack.plan.guidance.forces import GradientField
from searchtrack.plan.guidance.search_routes import SearchCells, SearchRoute
from searchtrack.plan.guidance.view import Guidance, GuidanceView, Reacquisition, StrategyConfig


@dataclass(frozen=True, eq=False)
class GuidanceProblem:
    """The guidance problem of one step (immutable, validated on construction).

    Parameters
    ----------
    view
        What the UAVs see this step.
    config
        The Ch. 5 force-law and reacquisition parameters.
    predictor
        The trackers' prediction (4.2), for the reacquisition horizon ``T_r``: any
        :class:`~searchtrack.estimate.belief.NodePredictor` on the network's nodes (the
        tracker :class:`~searchtrack.estimate.diffusion.GraphDiffusion` in a mission).
    reacquisitions
        The reacquisition routes flown so far, as the previous step's
        :attr:`Guidance.reacquisitions` returned them (at most one per track, per UAV).
    gradient
        The per-network structures of the gradient force; built from ``view.network`` when
        ``None``. Pass the previous step's (:meth:`following` does) to build them once.
    search_routes
        The search routes flown so far, as the previous step's :attr:`Guidance.search_routes`
        returned them (at most one per UAV).
    cells
        The search OPTW's cells of ``view.network`` at ``config``'s cell size; built on first
        use when ``None`` (:attr:`search_cells`), passed on by :meth:`following`.
    """

    view: GuidanceView
    config: StrategyConfig
    predictor: NodePredictor
    reacquisitions: tuple[Reacquisition, ...] = ()
    gradient: GradientField | None = None
    search_routes: tuple[SearchRoute, ...] = ()
    cells: SearchCells | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.view, GuidanceView):
            raise InvalidInputError("view", self.view, "must be a GuidanceView")
        if not isinstance(self.config, StrategyConfig):
            raise InvalidInputError("config", self.config, "must be a StrategyConfig")
        n = self.view.network.n_nodes
        if not isinstance(self.predictor, NodePredictor) or self.predictor.n_nodes != n:
            raise InvalidInputError("predictor", self.predictor,
                                    f"must be a NodePredictor (n_nodes, dt_s, propagate), e.g. "
                                    f"a GraphDiffusion, on the network's {n} nodes")
        routes = tuple(self.reacquisitions)
        tracks = [r.track_id for r in routes if isinstance(r, Reacquisition)]
        if (len(tracks) != len(routes) or len(set(tracks)) != len(tracks)
                or any(r.uav >= self.view.n_uavs or any(v >= n for v in r.nodes)
                       for r in routes)):
            raise InvalidInputError("reacquisitions", self.reacquisitions,
                                    f"must be Reacquisitions of distinct tracks, UAVs in "
                                    f"[0, {self.view.n_uavs}), nodes in [0, {n})")
        object.__setattr__(self, "reacquisitions", routes)
        if self.gradient is None:
            object.__setattr__(self, "gradient", GradientField(self.view.network))
        elif (not isinstance(self.gradient, GradientField)
              or self.gradient.network is not self.view.network):
            raise InvalidInputError("gradient", self.gradient,
                                    "must be a GradientField of view.network")
        searched = tuple(self.search_routes)
        uavs = [r.uav for r in searched if isinstance(r, SearchRoute)]
        if (len(uavs) != len(searched) or len(set(uavs)) != len(uavs)
                or any(r.uav >= self.view.n_uavs or max(r.nodes) >= n for r in searched)):
            raise InvalidInputError("search_routes", self.search_routes,
                                    f"must be SearchRoutes of distinct UAVs in "
                                    f"[0, {self.view.n_uavs}), nodes in [0, {n})")
        object.__setattr__(self, "search_routes", searched)
        if self.cells is not None and (not isinstance(self.cells, SearchCells)
                                       or self.cells.network is not self.view.network
                                       or self.cells.cell_m != self.config.cell_m):
            raise InvalidInputError("cells", self.cells,
                                    "must be SearchCells of view.network at config.cell_m")

    @property
    def gradient_field(self) -> GradientField:
        """The gradient-force structures of ``view.network``."""
        assert self.gradient is not None  # set in __post_init__
        return self.gradient

    @property
    def search_cells(self) -> SearchCells:
        """The search OPTW's cells of ``view.network`` (built on first use, then kept)."""
        if self.cells is None:
            object.__setattr__(self, "cells", SearchCells(self.view.network, self.config.cell_m))
        assert self.cells is not None
        return self.cells

    def following(self, view: GuidanceView, answer: Guidance) -> GuidanceProblem:
        """The next step's problem: this configuration, predictor, gradient structures and
        search cells (when the network is the same), the new ``view``, and the reacquisition
        and search routes of ``answer``, this problem's solution."""
        same = view.network is self.view.network
        return GuidanceProblem(view, self.config, self.predictor, answer.reacquisitions,
                               self.gradient if same else None, answer.search_routes,
                               self.cells if same else None)
