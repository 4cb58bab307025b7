"""A filter over a recorded radio run (paper 002): the TBD-LMB on the raw spectrograms or the
detection-then-track baseline, one step per measurement interval.

EST.json::

    {"filter": "tbd", "particles_per_label": N, "seed": s,
     "estimates": [[{"label": λ, "xy": [x, y]}, ...] per step],
     "cardinality": [mean per step], "cardinality_var": [...],
     "existence": [[r per label] per step], "ms_per_step": float, "interrupted": bool}

A stop request (Ctrl-C) ends the run between steps; what was done is kept and marked
``interrupted``.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core import checks
from searchtrack.core.files import write_text_atomic
from searchtrack.core.interrupt import stop_requested
from searchtrack.core.registry import check_seed
from searchtrack.estimate.radio import DttLmbFilter, FilterConfig, LabelledFilter, TbdLmbFilter
from searchtrack.models.radio import RadioScenario
from searchtrack.sim.radio.config import FILTERS as FILTER_NAMES
from searchtrack.sim.radio.run import RadioRun

FILTERS: dict[str, type[TbdLmbFilter] | type[DttLmbFilter]] = dict(
    zip(FILTER_NAMES, (TbdLmbFilter, DttLmbFilter), strict=True))
"""The filters by name (:data:`searchtrack.sim.radio.config.FILTERS`): the TBD-LMB on the raw
STFT, detection-then-track (§IV-B)."""


def make_filter(name: str, scenario: RadioScenario, particles_per_label: int,
                seed: int, temper: float = 1.0, roughening_m: float = 0.0) -> LabelledFilter:
    """The filter ``name`` (:data:`FILTERS`) for ``scenario``, its likelihood tempered by
    ``temper`` and its particles roughened by ``roughening_m``
    (:class:`~searchtrack.estimate.radio.filter.FilterConfig`)."""
    checks.choice("filter", name, tuple(FILTERS))
    config = FilterConfig(particles_per_label=particles_per_label, temper=temper,
                          roughening_m=roughening_m)
    return FILTERS[name](scenario, config, seed=seed)


@dataclass
class RadioTrackResult:
    """Per-step output of a filter over a run."""

    filter: str
    particles_per_label: int
    seed: int
    estimates: list[list[tuple[int, tuple[float, float]]]] = field(default_factory=list)
    cardinality: list[float] = field(default_factory=list)
    cardinality_var: list[float] = field(default_factory=list)
    existence: list[list[float]] = field(default_factory=list)
    seconds: float = 0.0
    interrupted: bool = False

    @property
    def steps(self) -> int:
        """Steps filtered."""
        return len(self.estimates)

    @property
    def ms_per_step(self) -> float:
        """Mean wall time of one filter step (ms)."""
        return 1e3 * self.seconds / max(1, self.steps)

    def to_json(self) -> dict[str, Any]:
        """The EST.json document."""
        return {"filter": self.filter, "particles_per_label": self.particles_per_label,
                "seed": self.seed,
                "estimates": [[{"label": lab, "xy": [round(x, 3), round(y, 3)]}
                               for lab, (x, y) in row] for row in self.estimates],
                "cardinality": [round(c, 6) for c in self.cardinality],
                "cardinality_var": [round(c, 6) for c in self.cardinality_var],
                "existence": [[round(r, 6) for r in row] for row in self.existence],
                "ms_per_step": round(self.ms_per_step, 3), "interrupted": self.interrupted}


def run_radio_track(run: RadioRun, filter_name: str, particles_per_label: int, seed: int,
                    progress: Callable[[int, int], None] | None = None) -> RadioTrackResult:
    """Filter every interval of ``run`` with ``filter_name`` (``"tbd"`` or ``"dtt"``)."""
    checks.choice("filter", filter_name, tuple(FILTERS))
    seed = check_seed(seed)
    filt = make_filter(filter_name, run.scenario, particles_per_label, seed)
    result = RadioTrackResult(filter_name, particles_per_label, seed)
    n = run.n_steps
    for k in range(n):
        if stop_requested():
            result.interrupted = True
            break
        t0 = time.perf_counter()
        filt.step(np.asarray(run.frames[k], dtype=float), run.uav_poses[k])
        result.seconds += time.perf_counter() - t0
        result.estimates.append([(int(lab), (float(xy[0]), float(xy[1])))
                                 for lab, xy in filt.estimates()])
        result.cardinality.append(float(filt.cardinality_mean()))
        result.cardinality_var.append(float(filt.cardinality_variance()))
        result.existence.append([float(r) for r in filt.state.r])
        if progress is not None:
            progress(k + 1, n)
    return result


def write_radio_estimates(result: RadioTrackResult, path: str | Path) -> Path:
    """Write EST.json atomically."""
    return write_text_atomic(path, json.dumps(result.to_json()) + "\n")
