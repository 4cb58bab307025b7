"""SCANS.json documents for the tests of the offline SMC-PHD job and of ``searchtrack track``."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.sim.particles.scenario import standard_scenario


def scans_document(n_scans: int = 25) -> tuple[dict[str, Any], np.ndarray]:
    """A valid SCANS.json document (3 CV targets, ``n_scans`` scans) and the true states."""
    sc = standard_scenario(2, n_targets=3, n_scans=n_scans)
    doc = {"area": [[0.0, 1000.0], [0.0, 1000.0]], "dt": 1.0,
           "sensor": {"pd": 0.9, "sigma": 10.0, "clutter_rate": 10.0},
           "motion": {"model": "cv", "q": 0.5}, "birth_weight": 0.25,
           "scans": [z.tolist() for z in sc.scans]}
    return doc, sc.truth


def write_json(tmp_path: Path, doc: object, name: str = "scans.json") -> Path:
    """``doc`` written as JSON to ``tmp_path / name``."""
    path = tmp_path / name
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def mutated(path: str, value: object) -> dict[str, Any]:
    """A 3-scan document with the dotted ``path`` set to ``value`` (deleted for ``KeyError``)."""
    doc, _ = scans_document(3)
    doc = copy.deepcopy(doc)
    keys = path.split(".")
    target: Any = doc
    for key in keys[:-1]:
        target = target[int(key)] if key.isdigit() else target[key]
    last = keys[-1]
    if value is KeyError:
        del target[last]
    elif last.isdigit():
        target[int(last)] = value
    else:
        target[last] = value
    return doc
