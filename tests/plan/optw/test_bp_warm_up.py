"""Branch-and-price's warm-up compiles every kernel of its pricing join, route enumeration and
arc fixing, so that none compiles inside a timed solve."""

from __future__ import annotations

import json
import subprocess
import sys

from searchtrack.plan.optw import bp_enumeration, bp_fixing, bp_warm_up, labelling_join
from searchtrack.plan.optw.solve import BACKENDS, BP_KERNELS
from searchtrack.sim.kernels import KERNEL_SETS, is_cold


def test_it_readies_the_set_for_a_later_process() -> None:
    """After :func:`warm_up`, every module of the set has machine code in numba's cache (kernels
    folded into their callers have none of their own, so one per module counts)."""
    bp_warm_up.warm_up()
    assert not is_cold(KERNEL_SETS[BP_KERNELS])
    assert {m.__name__ for m in (labelling_join, bp_enumeration, bp_fixing)} == set(
        KERNEL_SETS[BP_KERNELS].modules)


def test_the_backends_that_price_list_the_set() -> None:
    """``bp`` and ``auto`` (which proves m ≥ 2 by branch-and-price) name the set, so
    ``searchtrack warm-up`` and a solve's own warm-up compile it before the clock starts."""
    for name in ("bp", "auto"):
        assert BP_KERNELS in BACKENDS.get(name).kernels
    assert BP_KERNELS not in BACKENDS.get("labelling").kernels


def test_the_small_instance_is_a_two_vehicle_team_problem() -> None:
    """The warm-up's instance has two vehicles and twelve customers."""
    inst = bp_warm_up.small_instance()
    assert inst.vehicles == 2
    assert inst.customers.size == 12


def test_auto_on_one_vehicle_leaves_the_set_alone() -> None:
    """``auto`` proves one vehicle by the labelling DP, so its warm-up skips the set there; on
    two vehicles, and for ``bp`` on one, it readies it (each in a fresh process)."""
    code = ("import importlib, json, sys\n"
            "solve = importlib.import_module('searchtrack.plan.optw.solve')\n"
            "from searchtrack.plan.optw.bp_warm_up import small_instance\n"
            "solve.warm_up(sys.argv[1], small_instance().with_vehicles(int(sys.argv[2])))\n"
            "print(json.dumps(sorted(solve._WARMED)))")
    for backend, vehicles, warmed in (("auto", 1, False), ("auto", 2, True), ("bp", 1, True)):
        done = subprocess.run([sys.executable, "-c", code, backend, str(vehicles)],
                              capture_output=True, text=True, timeout=600, check=True)
        sets = json.loads(done.stdout.strip().splitlines()[-1])
        assert (BP_KERNELS in sets) is warmed, (backend, vehicles, sets)
