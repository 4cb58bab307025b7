"""The mission options of this library (tracker diffusivity, identity hand-over, coverage
search), each off by default: at the defaults a mission flies exactly as before; switched on,
each changes what it should."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import SensorModel
from searchtrack.sim.roads.mission import Mission, World
from searchtrack.sim.roads.scenario import FilterSpec, GuidanceSpec, MapSpec, Scenario

SENSOR = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=150.0, position_noise_m=5.0)


def small(strategy: str = "search_and_loiter", seed: int = 3, **changes: object) -> Scenario:
    """A 6 × 6 grid of 100 m blocks, 2 UAVs, 2 targets, 30 s (as in test_mission)."""
    base = Scenario("small", MapSpec("grid", rows=6, cols=6, block_m=100.0), uav_count=2,
                    target_count=2, sensor=SENSOR, altitude_m=None, duration_s=30.0, seed=seed,
                    guidance=GuidanceSpec(strategy=strategy))
    return dataclasses.replace(base, **changes)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def world() -> World:
    """The grid and its default operators, built once."""
    return World.build(small())


#: (strategy, seed) -> (NVT, NST, NVA, NFA, detected, final UAV positions), recorded from the
#: mission before the options existed.
BEFORE = {
    ("loiter", 3): (100, 0, 76, 0, 1, [[454.8350720590628, 650.9450044311092],
                                       [1054.0939010590287, 794.9099093682432]]),
    ("loiter", 5): (99, 0, 67, 7, 2, [[129.1935146022681, 233.62382402071796],
                                      [124.39518426539465, 891.2588489295371]]),
    ("search_and_loiter", 3): (92, 8, 46, 2, 1, [[425.1755001723169, 377.3792469566529],
                                                 [120.09742899923043, 900.0895808263718]]),
    ("search_and_loiter", 5): (135, 0, 72, 9, 2, [[358.56298423639845, 425.6786773212267],
                                                  [263.5357364180137, 124.44310411438391]]),
}


@pytest.mark.parametrize(("strategy", "seed"), sorted(BEFORE))
def test_options_off_fly_as_before(world: World, strategy: str, seed: int) -> None:
    """With every option off (the thesis's steering too) a mission's counts and paths are those
    recorded before the options existed, whether the other defaults are stated or not."""
    nvt, nst, nva, nfa, detected, uav_final = BEFORE[strategy, seed]
    log = Mission(small(strategy, seed, filter=FilterSpec(handover=False),
                        guidance=GuidanceSpec(strategy=strategy, steering="thesis")), world).run()
    s = log.score
    assert (s.nvt, s.nst, s.nva, s.nfa, s.detected) == (nvt, nst, nva, nfa, detected)
    np.testing.assert_allclose(log.uav_xy_m[-1], uav_final, rtol=0, atol=1e-6)
    explicit = small(strategy, seed, filter=FilterSpec(tracker_alpha=None, handover=False),
                     guidance=GuidanceSpec(strategy=strategy, coverage_weight=0.0,
                                           steering="thesis"))
    again = Mission(explicit, world).run()
    assert again.score == s
    np.testing.assert_array_equal(again.uav_xy_m, log.uav_xy_m)


def test_tracker_alpha_sets_the_tracker_diffusion_only(world: World) -> None:
    """Unset, the trackers diffuse at the LRT's α; set, at their own rate (the LRT's is kept),
    so a tracker spreads differently. A world built for another filter is refused."""
    lrt, trk = world.lrt_diffusion, world.tracker_diffusion
    assert trk.alpha == lrt.alpha == 0.447 and trk.dt_s == lrt.dt_s
    own = World.build(small(filter=FilterSpec(tracker_alpha=0.894)), world.network)
    assert own.tracker_diffusion.alpha == 0.894 and own.lrt_diffusion.alpha == 0.447
    delta = np.zeros(world.network.n_nodes)
    delta[50] = 1.0
    slow, fast = trk.propagate(delta), own.tracker_diffusion.propagate(delta)
    assert fast.max() < slow.max()
    np.testing.assert_array_equal(own.lrt_diffusion.propagate(delta),
                                  lrt.propagate(delta))
    with pytest.raises(InvalidInputError, match="tracker_alpha") as info:
        Mission(small(filter=FilterSpec(tracker_alpha=0.894)), world)
    assert info.value.field == "world"
    lrt_filter = Mission(small(filter=FilterSpec(tracker_alpha=0.894)), own).new_filter()
    predictor = lrt_filter.tracker_predictor  # type: ignore[attr-defined]
    assert predictor.diffusion is own.tracker_diffusion


def test_tracker_alpha_changes_the_mission(world: World) -> None:
    """A mission whose trackers diffuse faster keeps them for less time: its run differs."""
    sc = small(filter=FilterSpec(tracker_alpha=4.47), duration_s=30.0)
    log = Mission(sc, World.build(sc, world.network)).run()
    base = Mission(small(), world).run()
    assert log.score != base.score


def test_handover_mission_keeps_identities_and_cuts_spurious_tracks(world: World) -> None:
    """On the grid (seeds 6, 7, 60 s, the thesis's steering, under which loitering UAVs lose
    their targets now and then) a target re-detected after its tracker lost it is handed to
    that tracker: each hand-over is recorded as a birth of an identity already born, for the
    same true target, and the run holds fewer spurious tracker-steps than without the rule."""
    for seed in (6, 7):
        sc = small(seed=seed, duration_s=60.0,
                   guidance=GuidanceSpec(strategy="search_and_loiter", steering="thesis"))
        log = Mission(dataclasses.replace(sc, filter=FilterSpec(handover=True)), world).run()
        base = Mission(dataclasses.replace(sc, filter=FilterSpec(handover=False)), world).run()
        first: dict[int, int] = {}
        handovers = 0
        for b in log.births:
            if b.handover:
                handovers += 1
                assert first[b.track_id] == b.target
            else:
                assert b.track_id not in first
                first[b.track_id] = b.target
        assert handovers >= 1
        assert log.score.nst < base.score.nst
        assert [len(t) for t in log.tracks] == [st.trackers for st in log.steps]
        live = {tid for step in log.tracks for tid, _, _ in step}
        assert {tid for step in log.associations for _, tid, _ in step} <= live | set(first)


def test_coverage_changes_where_free_uavs_fly(world: World) -> None:
    """A positive coverage weight changes the searchers' paths; the scores stay well formed."""
    base = Mission(small(), world).run()
    log = Mission(small(guidance=GuidanceSpec(coverage_weight=2.0)), world).run()
    assert not np.array_equal(log.uav_xy_m, base.uav_xy_m)
    np.testing.assert_array_equal(log.uav_xy_m[0], base.uav_xy_m[0])
    assert 0.0 <= log.score.moc_mean <= 1.0
