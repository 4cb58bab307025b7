"""Plans and missions as files that flight software and GIS tools open: QGroundControl ``.plan``
files and MAVLink waypoint lists (``QGC WPL 110``) for an autopilot, GeoJSON for QGIS or a
browser (:mod:`~searchtrack.sim.export.autopilot`, :mod:`~searchtrack.sim.export.geojson`), in
geographic coordinates through a :class:`~searchtrack.sim.export.geo.GeoFrame`; what a road
mission and an OPTW plan export (:mod:`~searchtrack.sim.export.plans`)."""
