"""The geographic frame: metres to degrees through the map's projection or an origin."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.export.geo import GeoFrame


def test_origin_and_metres_to_degrees() -> None:
    """(0, 0) is the origin; 1 km north is about 1/111 of a degree; the unit scales."""
    frame = GeoFrame.at(45.0, 7.0, 100.0)
    latlon = frame.degrees([[0.0, 0.0], [0.0, 1000.0], [1000.0, 0.0]])
    assert latlon[0] == pytest.approx([45.0, 7.0])
    assert latlon[1, 0] - 45.0 == pytest.approx(1000.0 / 111_132.0, rel=1e-3)
    assert latlon[2, 1] - 7.0 == pytest.approx(1000.0 / (111_320.0 * math.cos(math.pi / 4)),
                                               rel=2e-3)
    scaled = GeoFrame.at(45.0, 7.0, 100.0, unit_m=10.0).degrees([[0.0, 100.0]])
    assert np.allclose(scaled, latlon[1:2])
    assert np.allclose(frame.projection.forward(*np.radians(latlon[1])), [[0.0, 1000.0]])


def test_bad_frames_are_refused() -> None:
    with pytest.raises(InvalidInputError, match="altitude_m"):
        GeoFrame.at(0.0, 0.0, 0.0)
    with pytest.raises(InvalidInputError, match="lat_deg"):
        GeoFrame.at(89.0, 0.0, 10.0)
    with pytest.raises(InvalidInputError, match="xy"):
        GeoFrame.at(0.0, 0.0, 10.0).degrees([[math.inf, 0.0]])
