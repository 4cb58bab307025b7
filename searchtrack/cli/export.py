"""The export options shared by the commands that write plans (``--export DIR``, ``--origin``,
``--altitude``): QGroundControl plans, MAVLink waypoint lists and GeoJSON
(:mod:`searchtrack.sim.export`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from rich.console import Console

from searchtrack.cli.common import positive_float
from searchtrack.cli.output import OutputError, output_dir
from searchtrack.core.errors import SearchtrackError
from searchtrack.core.files import write_text_atomic
from searchtrack.models.projection import LocalProjection
from searchtrack.sim.export.geo import GeoFrame, parse_origin


def add_arguments(parser: argparse.ArgumentParser, *, altitude_m: float | None,
                  unit: bool = False, speed: bool = False) -> None:
    """Add ``--export``, ``--origin`` and ``--altitude`` (default ``altitude_m``; ``None``: the
    problem's own); ``--speed`` when ``speed`` or ``unit``, and ``--unit-m`` when ``unit`` (an
    OPTW instance, whose coordinates and times have no unit)."""
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
                             + ("the scenario's" if altitude_m is None else f"{altitude_m:g}")
                             + ")")
    if unit:
        parser.add_argument("--unit-m", type=positive_float, default=1.0, metavar="M",
                            help="metres per coordinate unit for --export (default: 1)")
    if unit or speed:
        parser.add_argument("--speed", type=positive_float, default=15.0, metavar="M/S",
                            help="cruise speed for --export (m/s; default: 15)"
                                 + ("; a time unit is the time to fly one coordinate unit"
                                    if unit else ""))


def export_dir(args: argparse.Namespace, projection: LocalProjection | None = None,
               *, known: bool = True) -> Path | None:
    """The checked ``--export`` folder (before any work), or ``None`` without it; ``--origin``
    is checked too, and asked for when the problem has no geographic frame (``projection`` is
    ``None`` and ``known``: the frame is known before the work)."""
    if args.export is None:
        return None
    if args.origin is not None:
        parse_origin(args.origin)   # refused before the work, too
    elif known and projection is None:
        raise _no_frame()
    return output_dir("--export", args.export)


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
