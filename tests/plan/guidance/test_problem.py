"""The guidance problem of one step: validation naming the field, the gradient structures and
the hand-over to the next step (``following``)."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.plan.guidance import (
    GradientField,
    Guidance,
    GuidanceProblem,
    Pairing,
    Reacquisition,
    StrategyConfig,
)

from .helpers import path_road, view_of


def test_following_carries_the_routes_and_the_gradient() -> None:
    """The next problem keeps configuration, predictor and gradient structures on the same
    network, and takes the answer's reacquisition routes; a new network gets new structures."""
    net = path_road(6)
    diff = GraphDiffusion.on_network(net, 0.447, 0.3)
    problem = GuidanceProblem(view_of(net, [[0.0, 0.0]]), StrategyConfig(), diff)
    assert problem.gradient_field.network is net
    route = Reacquisition.planned(4, 0, (2, 3))
    answer = Guidance(np.zeros((1, 2)), Pairing.none(1), ("reacquire",), ((2, 3),),
                      reacquisitions=(route,))
    nxt = problem.following(view_of(net, [[5.0, 0.0]]), answer)
    assert nxt.config is problem.config and nxt.predictor is diff
    assert nxt.gradient is problem.gradient and nxt.reacquisitions == (route,)
    other = path_road(6)
    moved = GuidanceProblem(view_of(other, [[0.0, 0.0]]), StrategyConfig(),
                            GraphDiffusion.on_network(other, 0.447, 0.3))
    assert moved.gradient_field.network is other and moved.gradient is not problem.gradient
    assert problem.following(view_of(other, [[0.0, 0.0]]), answer).gradient_field.network \
        is other


def test_problem_bad_fields() -> None:
    """Bad views, configurations, routes and gradient structures raise naming the field."""
    net = path_road(5)
    diff = GraphDiffusion.on_network(net, 1.0, 0.3)
    view = view_of(net, [[0.0, 0.0], [10.0, 0.0]])
    with pytest.raises(InvalidInputError, match="view"):
        GuidanceProblem("view", StrategyConfig(), diff)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="config"):
        GuidanceProblem(view, {}, diff)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="reacquisitions"):
        GuidanceProblem(view, StrategyConfig(), diff, (Reacquisition.planned(0, 0, (5,)),))
    with pytest.raises(InvalidInputError, match="reacquisitions"):
        GuidanceProblem(view, StrategyConfig(), diff, ("route",))  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="gradient"):
        GuidanceProblem(view, StrategyConfig(), diff, gradient=GradientField(path_road(5)))
    ok = GuidanceProblem(view, StrategyConfig(), diff, (Reacquisition.planned(0, 1, (4,)),),
                         gradient=GradientField(net))
    assert ok.reacquisitions[0].uav == 1
