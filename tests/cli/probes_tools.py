"""Inputs that once crashed, hung or misled ``searchtrack fleet-size``, ``rl evaluate`` and
``mission view``: each is now answered with one line naming the file and the key (or the option)
and exit status 2 with nothing written, or (a huge allowed variance) with the right answer.

Probes have the form of :mod:`tests.cli.probes` (``(name, build, status, words)``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from tests.cli.probes import Build, Probe, _write

SHIPPED_POLICY = (Path(__file__).parents[2] / "searchtrack" / "data" / "policies"
                  / "road_grid3x3.npz")


def _fleet(*extra: str) -> Build:
    return lambda tmp: ["fleet-size", "--targets", "10", "--json", str(tmp / "f.json"), *extra]


def policy_with_meta(path: Path, meta: Any) -> Path:
    """The shipped policy's arrays with ``meta`` (a JSON value) as their meta, written to
    ``path``."""
    with np.load(SHIPPED_POLICY, allow_pickle=False) as data:
        arrays = {name: data[name] for name in data.files}
    arrays["meta"] = np.array(json.dumps(meta))
    with path.open("wb") as fh:
        np.savez(fh, **arrays)
    return path


def shipped_meta() -> dict[str, Any]:
    """The shipped policy's meta object."""
    with np.load(SHIPPED_POLICY, allow_pickle=False) as data:
        meta: dict[str, Any] = json.loads(str(data["meta"]))
    return meta


def _evaluate(policy: Path, *extra: str) -> list[str]:
    return ["rl", "evaluate", "--policy", str(policy), "--episodes", "1", "--duration", "1",
            *extra]


def _unsigned(tmp: Path) -> list[str]:
    return _evaluate(policy_with_meta(tmp / "p.npz", {**shipped_meta(), "signature": None}))


TOOL_PROBES: list[Probe] = [
    ("fleet-size: a 1e9 m block", _fleet("--map", "grid:3x3:1000000000", "--max-variance", "16"),
     2, ("--map grid 3x3 @ 1e+09 m", "split profile")),
    ("fleet-size: a huge allowed variance", _fleet("--map", "grid:3x3", "--max-variance",
                                                  "1e300"),
     0, ("1 UAV meets σ² ≤ 1e+300", "B_L ≤ 346.8067 nats")),
    ("rl evaluate: an empty policy file", lambda t: _evaluate(_write(t / "p.npz", b"")), 2,
     ("p.npz", "not a policy file")),
    ("rl evaluate: a null signature", _unsigned, 2,
     ("p.npz", "field 'meta.signature'", "records no n_targets")),
    ("rl evaluate: --duration 1e300", lambda t: ["rl", "evaluate", "--episodes", "1",
                                                "--duration", "1e300"], 2,
     ("--duration", "3000000")),
    ("mission view: not a mission record", lambda t: [
        "mission", "view", str(_write(t / "x.json", '{"a": 1}')), "--out", str(t / "r.html")],
     2, ("x.json", "not a mission record", "'scenario'")),
]
