"""The export options shared by the commands that write plans (``--export DIR``, ``--origin``,
``--altitude``): QGroundControl plans, MAVLink waypoint lists and GeoJSON
(:mod:`searchtrack.sim.export`)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from rich.console import Console

from searchtrack.cli.common import positive_float
from searchtrack.cli.output import OutputError, output_dir
from searchtrack.core.errors import InvalidInputError, SearchtrackError
from searchtrack.core.files import write_text_atomic
from searchtrack.models.projection import LocalProjection
from searchtrack.sim.export.geo import GeoFrame

#: Flight altitude above home of an export whose problem states none (m).
DEFAULT_ALTITUDE_M = 120.0


def add_arguments(parser: argparse.ArgumentParser, *,
                  altitude_m: float | None = DEFAULT_ALTITUDE_M, unit: bool = False,
                  speed: bool = False, own_altitude: str = "the scenario's") -> None:
    """Add ``--export``, ``--origin`` and ``--altitude`` (default ``altitude_m``; ``None``: the
    problem's own, which the help names as ``own_altitude``); ``--speed`` when ``speed`` or
    ``unit``, and ``--unit-m`` when ``unit`` (an OPTW instance, whose coordinates and times have
    no unit)."""
    parser.add_argument("--export", default=None, metavar="DIR",
                        help="also write a QGroundControl .plan and a MAVLink .waypoints file "
                             "per vehicle, plan.geojson and its offline map page plan.html "
                             "into DIR")
    parser.add_argument("--origin", default=None, metavar="LAT,LON",
                        help="latitude and longitude (degrees) of the problem's (0, 0), for "
                             "--export (maps read from OpenStreetMap know theirs; a negative "
                             "latitude as --origin=-35,149)")
    parser.add_argument("--altitude", type=positive_float, default=altitude_m, metavar="M",
                        help="flight altitude above home for --export (m; default: "
                             + (own_altitude if altitude_m is None else f"{altitude_m:g}")
                             + ")")
    if unit:
        parser.add_argument("--unit-m", type=positive_float, default=1.0, metavar="M",
                            help="metres per coordinate unit for --export (default: 1)")
    if unit or speed:
        parser.add_argument("--speed", type=positive_float, default=15.0, metavar="M/S",
                            help="cruise speed for --export (m/s; default: 15)"
                                 + ("; a time unit is the time to fly one coordinate unit"
                                    if unit else ""))


def export_dir(args: argparse.Namespace) -> Path | None:
    """The checked ``--export`` folder (before any work), or ``None`` without it; a given
    ``--origin`` is checked too (:func:`require_frame` asks for a missing one once the
    problem's frame is known)."""
    if args.export is None:
        return None
    if args.origin is not None:
        parse_origin(args.origin)   # refused before the work, too
    return output_dir("--export", args.export)


def require_frame(args: argparse.Namespace, projection: LocalProjection | None) -> None:
    """Refuse (before the work) an ``--export`` without ``--origin`` of a problem with no
    geographic frame (``projection`` ``None``)."""
    if args.export is not None and args.origin is None and projection is None:
        raise _no_frame()


def _no_frame() -> SearchtrackError:
    return SearchtrackError("--origin is needed for --export: this problem has no geographic "
                            "frame (give LAT,LON of its (0, 0))")


def geo_frame(args: argparse.Namespace, projection: LocalProjection | None,
              altitude_m: float) -> GeoFrame:
    """The frame of ``--origin`` (or the map's own ``projection``) at ``altitude_m``."""
    unit = float(getattr(args, "unit_m", 1.0))
    if args.origin is not None:
        lat, lon = parse_origin(args.origin)
        return GeoFrame.at(lat, lon, altitude_m, unit)
    if projection is None:
        raise _no_frame()
    return GeoFrame(projection, altitude_m, unit)


def write_files(folder: Path, files: dict[str, str], console: Console) -> None:
    """Write ``files`` (name → text) into ``folder`` and say so."""
    try:
        written = [write_text_atomic(folder / name, text) for name, text in files.items()]
    except OSError as exc:
        raise OutputError("--export", folder, exc.strerror or str(exc)) from None
    console.print("wrote " + ", ".join(str(p) for p in written))


def parse_origin(text: str) -> tuple[float, float]:
    """``"LAT,LON"`` (degrees) as two floats; :class:`InvalidInputError` naming ``--origin``
    otherwise."""
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        lat, lon = float(parts[0]), float(parts[1])
    except ValueError:
        raise InvalidInputError("--origin", text, "must be LAT,LON in degrees, e.g. "
                                "21.88,-102.29") from None
    if not (math.isfinite(lat) and abs(lat) <= 85.0 and math.isfinite(lon)
            and abs(lon) <= 180.0):
        raise InvalidInputError("--origin", text, "must be a latitude within ±85° and a "
                                "longitude within ±180°")
    return lat, lon
