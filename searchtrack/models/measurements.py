"""Simulated sensor output: scalar LRT measurements and position measurements (thesis 001 §3.3,
§4.3), vectorised over UAVs and seeded by the caller's ``numpy.random.Generator``.

*Scalar measurements* (§3.3) feed the likelihood-ratio tracker. ``ζ = w`` where no target is and
``ζ = m + w`` where one is, ``w ~ N(0, 1)``. The thesis draws one ``ζ`` per UAV and applies its
increment ``m(ζ − m/2)`` to every node of the footprint (Fig. 3.1, §6.1: "the UAV raises the
likelihood for all nodes in sensor range"): ``per_node=False``. With ``per_node=True`` (the
default) each footprint node gets its own ``ζ``, ``N(m, 1)`` on a node holding a target and
``N(0, 1)`` elsewhere, which localises the evidence.

*Position measurements* (§4.3) feed the trackers: each target in a footprint is detected with
probability ``P_d`` and measured at its true position plus ``N(0, s²)`` noise on each axis; each
footprint adds a Poisson number of false alarms, uniform over the disc (the thesis: "a uniform
distribution centred on the UAV", support unstated).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.lrt_sensor import SensorModel
from searchtrack.models.roads import RoadNetwork

FALSE_ALARM = -1
"""The ``target`` index of a false position measurement."""


@dataclass(frozen=True)
class LrtScan:
    """Scalar measurements ``ζ`` on footprint nodes: one row per (UAV, node) pair.

    Attributes
    ----------
    uav
        ``(k,)`` index of the UAV that measured.
    node
        ``(k,)`` road node measured (in the UAV's footprint).
    zeta
        ``(k,)`` measurement in standard-deviation units.
    target_present
        ``(k,)`` truth: whether ``ζ`` was drawn from ``N(m, 1)``.
    """

    uav: IntArray
    node: IntArray
    zeta: FloatArray
    target_present: NDArray[np.bool_]

    def log_likelihood_ratio(self, sensor: SensorModel) -> FloatArray:
        """The LRT increments ``m(ζ − m/2)`` for ``sensor`` (§3.3)."""
        return sensor.log_likelihood_ratio(self.zeta)


@dataclass(frozen=True)
class PositionScan:
    """Position measurements: one row per measurement, target detections first per UAV.

    Attributes
    ----------
    uav
        ``(q,)`` index of the UAV that measured.
    xy_m
        ``(q, 2)`` measured position (m).
    target
        ``(q,)`` truth: the index of the target measured, or ``FALSE_ALARM`` (−1).
    """

    uav: IntArray
    xy_m: FloatArray
    target: IntArray

    @property
    def n_false_alarms(self) -> int:
        """Number of false alarms in the scan."""
        return int(np.count_nonzero(self.target == FALSE_ALARM))


def lrt_measurements(
    network: RoadNetwork,
    uav_xy_m: ArrayLike,
    target_nodes: ArrayLike,
    sensor: SensorModel,
    rng: np.random.Generator,
    *,
    per_node: bool = True,
) -> LrtScan:
    """Draw the scalar measurements of every UAV on the road nodes in its footprint (§3.3).

    Parameters
    ----------
    network
        The road network.
    uav_xy_m
        ``(n_uav, 2)`` UAV positions (m).
    target_nodes
        Node index of each target still to be sensed (for example
        :meth:`~searchtrack.models.targets.TargetState.nodes`); a node holding several targets
        counts once.
    sensor
        Sensitivity ``m`` and footprint radius ``ρ``.
    rng
        Source of randomness.
    per_node
        One ``ζ`` per footprint node (default), ``N(m, 1)`` on the nodes within
        ``sensor.cell_radius_m`` of a target, or one per UAV shared by its footprint nodes,
        ``N(m, 1)`` when any target is in the footprint (the thesis's Fig. 3.1).
    """
    xy = checks.points("uav_xy_m", uav_xy_m)
    targets = checks.index_array("target_nodes", np.atleast_1d(target_nodes), network.n_nodes)
    rng = checks.generator("rng", rng)
    uav, node = network.nodes_within(xy, sensor.footprint_radius_m)
    occupied = np.zeros(network.n_nodes, dtype=bool)
    occupied[targets] = True
    if per_node and sensor.cell_radius_m > 0.0 and targets.size:
        occupied[network.nodes_within(network.coords[targets], sensor.cell_radius_m)[1]] = True
    present = occupied[node]
    noise: FloatArray
    if per_node:
        noise = rng.standard_normal(node.size)
    else:
        seen = np.zeros(xy.shape[0], dtype=bool)
        seen[uav[present]] = True
        present = seen[uav]
        noise = rng.standard_normal(int(xy.shape[0]))[uav]
    zeta = noise + sensor.sensitivity * present
    return LrtScan(uav=uav, node=node, zeta=zeta, target_present=present)


def position_measurements(
    uav_xy_m: ArrayLike,
    target_xy_m: ArrayLike,
    sensor: SensorModel,
    rng: np.random.Generator,
) -> PositionScan:
    """Draw each UAV's position measurements of the targets in its footprint, plus false alarms.

    A target within ``ρ`` of a UAV is detected with probability ``P_d`` and reported at its
    position plus ``N(0, s²)`` noise per axis (§4.3). A UAV sees several targets independently,
    and a target in several footprints is measured by each. Each UAV also reports
    ``Poisson(sensor.false_alarm_mean)`` false alarms uniform over its footprint disc.

    Parameters
    ----------
    uav_xy_m
        ``(n_uav, 2)`` UAV positions (m).
    target_xy_m
        ``(n_target, 2)`` true target positions (m).
    sensor
        ``P_d``, ``ρ``, ``s`` and the false alarm mean.
    rng
        Source of randomness.
    """
    xy = checks.points("uav_xy_m", uav_xy_m)
    truth = checks.points("target_xy_m", target_xy_m)
    rng = checks.generator("rng", rng)
    rho, s = sensor.footprint_radius_m, sensor.position_noise_m
    dist = np.linalg.norm(xy[:, None, :] - truth[None, :, :], axis=2)
    in_view = (dist <= rho) & (rng.random(dist.shape) < sensor.pd)
    det_uav, det_target = np.nonzero(in_view)
    det_xy = truth[det_target] + s * rng.standard_normal((det_target.size, 2))
    n_false = rng.poisson(sensor.false_alarm_mean, size=xy.shape[0])
    fa_uav = np.repeat(np.arange(xy.shape[0]), n_false)
    radius = rho * np.sqrt(rng.random(fa_uav.size))
    angle = rng.uniform(-np.pi, np.pi, fa_uav.size)
    fa_xy = xy[fa_uav] + radius[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    uav = np.concatenate([det_uav, fa_uav]).astype(np.int64)
    order = np.argsort(uav, kind="stable")
    return PositionScan(
        uav=uav[order],
        xy_m=np.concatenate([det_xy, fa_xy])[order],
        target=np.concatenate([det_target, np.full(fa_uav.size, FALSE_ALARM)]).astype(
            np.int64)[order],
    )
