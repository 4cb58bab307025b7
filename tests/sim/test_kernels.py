"""The numba kernel sets: a cold cache is seen without compiling, each set's warm-up compiles
every module of the set, and a warmed set is seen as cached by a later process."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from searchtrack.sim.kernels import KERNEL_SETS, dispatchers


def _python(code: str, cache_dir: Path | None = None) -> object:
    """Run ``code`` in a fresh interpreter (optionally on an empty numba cache); its last
    stdout line, parsed as JSON."""
    env = dict(os.environ)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = str(cache_dir)
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          timeout=600, check=False)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_every_set_names_modules_with_cached_kernels() -> None:
    """Each module of each set defines numba kernels compiled with ``cache=True``."""
    for ks in KERNEL_SETS.values():
        for module in ks.modules:
            assert dispatchers(module), (ks.name, module)


def test_an_empty_cache_is_cold_and_a_warmed_set_is_not(tmp_path: Path) -> None:
    """On an empty cache every set is cold (seen without compiling); after one set (the radio
    set, the quickest to compile) is warmed, a later process sees it cached and the others
    still cold."""
    code = ("import json; from searchtrack.sim import kernels as k; "
            "print(json.dumps([s.name for s in k.cold_sets(k.KERNEL_SETS)]))")
    assert _python(code, tmp_path) == list(KERNEL_SETS)
    _python("from searchtrack.sim import kernels as k; k.warm([k.KERNEL_SETS['radio']]); "
            "print(0)", tmp_path)
    assert _python(code, tmp_path) == [n for n in KERNEL_SETS if n != "radio"]


@pytest.mark.slow
def test_each_warm_up_readies_every_module_of_its_set() -> None:
    """After a set's warm-up (in a fresh process, loading from the cache where it can), every
    module of the set has compiled kernels: nothing is left to compile inside a timed solve."""
    code = (
        "import json, sys; from searchtrack.sim import kernels as k\n"
        "out = {}\n"
        "for ks in k.KERNEL_SETS.values():\n"
        "    ks.warm()\n"
        "    out[ks.name] = [m for m in ks.modules\n"
        "                    if not any(f.signatures for f in k.dispatchers(m))]\n"
        "print(json.dumps(out))\n")
    assert _python(code) == {name: [] for name in KERNEL_SETS}
