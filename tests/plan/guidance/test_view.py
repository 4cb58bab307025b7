"""What guidance sees, answers and is configured by: ``StrategyConfig``, ``GuidanceView``,
``Reacquisition`` and ``Guidance``, with validation naming the field."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.estimate.node_tracker import TrackerBank
from searchtrack.plan.guidance import (
    Guidance,
    GuidanceProblem,
    GuidanceView,
    Pairing,
    Reacquisition,
    StrategyConfig,
    reacquire_time,
    reacquisition_instance,
    solve,
)

from .helpers import path_road, view_of


def test_bad_inputs() -> None:
    """Bad configs, views, problems and instance arguments raise InvalidInputError naming the
    field."""
    net = path_road(5)
    diff = GraphDiffusion.on_network(net, 1.0, 0.3)
    with pytest.raises(InvalidInputError, match="p_min"):
        StrategyConfig(p_min=0.5, revisit_threshold=0.3)
    with pytest.raises(InvalidInputError, match="optw_backend"):
        StrategyConfig(optw_backend="nope")
    with pytest.raises(InvalidInputError, match="sensor_range_m"):
        StrategyConfig(sensor_range_m=0.0)
    with pytest.raises(InvalidInputError, match="field"):
        GuidanceView(net, np.zeros((1, 2)), np.zeros(1), np.ones(1),
                     LikelihoodField(np.zeros(4)), TrackerBank(5), 0.0)
    with pytest.raises(InvalidInputError, match="field"):
        GuidanceView(net, np.zeros((1, 2)), np.zeros(1), np.ones(1),
                     np.zeros(5), TrackerBank(5), 0.0)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="bank"):
        GuidanceView(net, np.zeros((1, 2)), np.zeros(1), np.ones(1),
                     LikelihoodField(np.zeros(5)), TrackerBank(4), 0.0)
    with pytest.raises(InvalidInputError, match="uav_heading_rad"):
        GuidanceView(net, np.zeros((2, 2)), np.zeros(1), np.ones(2),
                     LikelihoodField(np.zeros(5)), TrackerBank(5), 0.0)
    view = view_of(net, [[0.0, 0.0]])
    with pytest.raises(InvalidInputError, match="predictor"):
        GuidanceProblem(view, StrategyConfig(), "not a diffusion")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="predictor"):
        GuidanceProblem(view, StrategyConfig(), GraphDiffusion.on_network(path_road(6), 1.0, 0.3))
    with pytest.raises(InvalidInputError, match="reacquisitions"):
        GuidanceProblem(view, StrategyConfig(), diff, (Reacquisition.planned(0, 1, (2,)),))
    with pytest.raises(InvalidInputError, match="reacquisitions"):
        GuidanceProblem(view, StrategyConfig(), diff, (Reacquisition.planned(0, 0, (2,)),
                                                       Reacquisition.planned(0, 0, (3,))))
    with pytest.raises(InvalidInputError, match="served"):
        Reacquisition(0, 0, (1, 2), (False,))
    problem = GuidanceProblem(view, StrategyConfig(), diff)
    with pytest.raises(InvalidInputError, match="backend"):
        solve(problem, backend="chase")
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve(problem, backend="search", time_limit_s=0.0)
    with pytest.raises(InvalidInputError, match="seed"):
        solve(problem, backend="search", seed=-1)
    with pytest.raises(InvalidInputError, match="horizon_s"):
        reacquisition_instance(net, np.full(5, 0.2), np.zeros(2), 10.0, -1.0)
    with pytest.raises(InvalidInputError, match="probability"):
        reacquire_time(diff, np.ones(4))
    with pytest.raises(InvalidInputError, match="predictor"):
        reacquire_time("not a diffusion", np.ones(5))  # type: ignore[arg-type]


def test_config_resolves_the_missing_constants() -> None:
    """σ = 2ρ, K of ∇Q = 4/ρ and K of ∇L = (2S/ρ)² when not given; given values are kept."""
    cfg = StrategyConfig(sensor_range_m=100.0, speed_mps=20.0)
    assert cfg.sigma == 200.0
    assert cfg.k_spring == pytest.approx(0.04)
    assert cfg.k_loiter == pytest.approx(0.16)
    mine = StrategyConfig(sigma_m=50.0, spring_k=0.5, loiter_k=0.25)
    assert (mine.sigma, mine.k_spring, mine.k_loiter) == (50.0, 0.5, 0.25)


def test_config_bad_fields() -> None:
    """Thresholds outside (0, 1), non-integer caps and bad constants raise naming the field;
    a support mass of 1 is allowed."""
    for kwargs, field in (({"revisit_threshold": 1.0}, "revisit_threshold"),
                          ({"support_mass": 1.5}, "support_mass"),
                          ({"max_route_nodes": 0}, "max_route_nodes"),
                          ({"max_reacquire_steps": True}, "max_reacquire_steps"),
                          ({"epsilon": 0.0}, "epsilon"), ({"loiter_k": -1.0}, "loiter_k"),
                          ({"speed_mps": np.inf}, "speed_mps")):
        with pytest.raises(InvalidInputError, match=field):
            StrategyConfig(**kwargs)  # type: ignore[arg-type]
    assert StrategyConfig(support_mass=1.0).support_mass == 1.0


def test_view_counts_uavs_and_checks_its_fields() -> None:
    """``n_uavs`` is the number of positions; no UAV, a non-network or a non-finite time raise
    naming the field."""
    net = path_road(5)
    assert view_of(net, [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]).n_uavs == 3
    field, bank = LikelihoodField(np.zeros(5)), TrackerBank(5)
    with pytest.raises(InvalidInputError, match="uav_xy_m"):
        GuidanceView(net, np.zeros((0, 2)), np.zeros(0), np.zeros(0), field, bank, 0.0)
    with pytest.raises(InvalidInputError, match="network"):
        GuidanceView("roads", np.zeros((1, 2)), np.zeros(1),  # type: ignore[arg-type]
                     np.ones(1), field, bank, 0.0)
    with pytest.raises(InvalidInputError, match="time_s"):
        GuidanceView(net, np.zeros((1, 2)), np.zeros(1), np.ones(1), field, bank, np.nan)


def test_reacquisition_route_is_served_node_by_node() -> None:
    """A planned route starts unserved; nodes within the radius of the UAV are served, in any
    order; the route is done once all are; an empty route is done at once."""
    net = path_road(6)
    route = Reacquisition.planned(3, 1, (4, 1, 5))
    assert route.served == (False, False, False) and not route.done
    xy = np.array([[0.0, 0.0], [10.0, 3.0]])
    after = route.serve(net, xy, 5.0)
    assert after.served == (False, True, False) and after.remaining() == (4, 5)
    assert after.serve(net, xy, 5.0) is after  # nothing new: the same route
    done = after.serve(net, np.array([[0.0, 0.0], [45.0, 0.0]]), 6.0)
    assert done.remaining() == () and done.done
    empty = Reacquisition.planned(0, 0, ())
    assert empty.done and empty.serve(net, xy, 100.0) is empty
    with pytest.raises(InvalidInputError, match="uav"):
        Reacquisition(0, -1, (), ())
    with pytest.raises(InvalidInputError, match="track_id"):
        Reacquisition(True, 0, (), ())  # type: ignore[arg-type]


def test_guidance_answer_checks_itself() -> None:
    """Forces, modes, routes, planning time and routes kept must agree with the UAV count."""
    pairing = Pairing.none(1)
    Guidance(np.zeros((1, 2)), pairing, ("search",), ((),))
    for kwargs, field in (({"force": np.full((1, 2), np.nan)}, "force"),
                          ({"mode": ("hover",)}, "mode"), ({"route": ((), ())}, "route"),
                          ({"plan_ms": -1.0}, "plan_ms"),
                          ({"reacquisitions": (Reacquisition.planned(0, 1, ()),)},
                           "reacquisitions")):
        args = {"force": np.zeros((1, 2)), "pairing": pairing, "mode": ("search",),
                "route": ((),), **kwargs}
        with pytest.raises(InvalidInputError, match=field):
            Guidance(**args)  # type: ignore[arg-type]


def test_turn_back_selects_the_anchored_uavs() -> None:
    """``"turn_back"`` steering turns back the loitering, reacquiring and routed UAVs, not the
    searching one; ``"thesis"`` none; another name is refused by name."""
    modes = ("search", "loiter", "reacquire", "route")
    guidance = Guidance(np.zeros((4, 2)), Pairing.none(4), modes, ((),) * 4)
    np.testing.assert_array_equal(guidance.turn_back("turn_back"), [False, True, True, True])
    np.testing.assert_array_equal(guidance.turn_back("thesis"), [False] * 4)
    with pytest.raises(InvalidInputError, match="steering"):
        guidance.turn_back("spin")


@pytest.mark.parametrize("weight", [-1.0, float("nan"), float("inf"), True])
def test_coverage_weight_is_checked(weight: float) -> None:
    """The coverage weight is a finite number ≥ 0, refused by name otherwise."""
    with pytest.raises(InvalidInputError) as info:
        StrategyConfig(coverage_weight=weight)
    assert info.value.field == "coverage_weight"
    assert StrategyConfig(coverage_weight=2).coverage_weight == 2.0


@pytest.mark.parametrize("coverage", [np.zeros(4), np.full(5, 1.5), np.full(5, -0.1),
                                      np.full(5, np.nan)])
def test_view_coverage_is_checked(coverage: np.ndarray) -> None:
    """A view's coverage is one value in [0, 1] per road node, or ``None``."""
    net = path_road(5)
    base = view_of(net, [[0.0, 0.0]])
    assert base.coverage is None
    with pytest.raises(InvalidInputError) as info:
        GuidanceView(net, base.uav_xy_m, base.uav_heading_rad, base.uav_speed_mps, base.field,
                     base.bank, 0.0, coverage)
    assert info.value.field == "coverage"
