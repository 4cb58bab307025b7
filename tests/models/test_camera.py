"""Downward camera (paper 003, eqs. 6–8): p_d, footprint, pixels, likelihood, clutter, h⁻¹."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.camera import DownwardCamera
from searchtrack.models.footprint import BatchDetectionSensor, detection_matrix
from searchtrack.models.particle_models import DetectionSensor

CAM = DownwardCamera()


def _pose(z: float, yaw: float = 0.0, pitch: float = 0.0, roll: float = 0.0) -> np.ndarray:
    return np.array([10.0, -20.0, z, yaw, pitch, roll])


def test_satisfies_detection_sensor_protocol() -> None:
    """The camera is a DetectionSensor with 2-D pixel measurements."""
    assert isinstance(CAM, DetectionSensor)
    assert CAM.meas_dim == 2


@pytest.mark.parametrize("gimballed", [True, False])
def test_batched_detection_matches_one_pose_at_a_time(gimballed: bool) -> None:
    """detection_probabilities over many poses equals detection_probability pose by pose,
    points on and near the image edges included; the planners' detection matrix uses it."""
    cam = DownwardCamera(gimballed=gimballed)
    rng = np.random.default_rng(4)
    poses = np.column_stack([rng.uniform(-50, 50, (40, 2)), rng.uniform(20, 150, 40),
                             rng.uniform(-np.pi, np.pi, 40), rng.uniform(-0.2, 0.2, (40, 2))])
    points = rng.uniform(-200, 200, (500, 2))
    edges = np.vstack([cam.footprint(p) for p in poses[:5]])  # exactly on the image edges
    points = np.vstack([points, edges, edges + 1e-6])
    batch = cam.detection_probabilities(poses, points)
    one = np.array([cam.detection_probability(p, points) for p in poses])
    interior = np.ones(points.shape[0], dtype=bool)
    interior[500:] = False  # on-edge points may fall either side by round-off
    np.testing.assert_allclose(batch[:, interior], one[:, interior], atol=1e-12)
    assert np.count_nonzero(batch[:, interior]) > 100
    assert isinstance(cam, BatchDetectionSensor)
    np.testing.assert_allclose(detection_matrix(cam, poses, points), batch)
    with pytest.raises(InvalidInputError, match="poses"):
        cam.detection_probabilities(np.array([[0.0, 0.0, -5.0, 0.0]]), points)


def test_pd_decreases_with_altitude_directly_below() -> None:
    """Straight below the camera p_d never rises with altitude and falls from 0.95 towards 0."""
    below = np.array([[10.0, -20.0]])
    pd = np.array([CAM.detection_probability(_pose(z), below)[0]
                   for z in np.linspace(5.0, 800.0, 80)])
    assert np.all(np.diff(pd) <= 1e-12)
    assert pd[0] == pytest.approx(0.95, abs=1e-6)
    assert pd[-1] < 0.02


def test_pd_matches_equations_6_and_7() -> None:
    """p_d at a point in view equals the logistic of pixels-per-radian × arctan(L/d)."""
    pose = _pose(120.0, yaw=0.4)
    x = np.array([[25.0, -5.0]])
    d = math.sqrt(15.0**2 + 15.0**2 + 120.0**2)
    n_px = 640 / math.radians(60.0) * math.atan(4.5 / d)
    want = 0.0 + 0.95 / (1.0 + math.exp(-0.25 * (n_px - 20.0)))
    assert CAM.pixels_on_target(pose, x)[0] == pytest.approx(n_px)
    assert CAM.detection_probability(pose, x)[0] == pytest.approx(want)


def test_pd_is_zero_outside_the_footprint() -> None:
    """Points beyond the image edges get p_d = 0; the footprint turns with yaw."""
    pose = _pose(100.0)
    half_w = 100.0 * math.tan(math.radians(30.0))  # across track (y)
    half_h = half_w * 480 / 640  # along track (x)
    centre = np.array([10.0, -20.0])
    inside = centre + np.array([[0.9 * half_h, 0.9 * half_w], [-0.9 * half_h, -0.9 * half_w]])
    outside = centre + np.array([[1.1 * half_h, 0.0], [0.0, -1.1 * half_w], [500.0, 500.0]])
    assert np.all(CAM.detection_probability(pose, inside) > 0.5)
    assert np.all(CAM.detection_probability(pose, outside) == 0.0)
    # At yaw 90° the along-track axis is y: 1.1·half_h along x is now inside, 1.1·half_w not.
    turned = _pose(100.0, yaw=math.pi / 2)
    assert CAM.detection_probability(turned, outside[:1])[0] > 0.0
    assert CAM.detection_probability(turned, centre + np.array([[1.1 * half_w, 0.0]]))[0] == 0.0


def test_footprint_corners_are_on_the_image_edges() -> None:
    """The footprint corners project back to the image corners."""
    pose = _pose(60.0, yaw=1.1)
    pix, front = CAM.project(pose, CAM.footprint(pose))
    assert np.all(front)
    np.testing.assert_allclose(pix, [[0, 0], [0, 640], [480, 640], [480, 0]], atol=1e-9)


@pytest.mark.parametrize("gimballed", [True, False])
def test_pixel_projection_round_trip(gimballed: bool) -> None:
    """to_position of the noise-free pixels recovers the ground points (tilted camera too)."""
    cam = DownwardCamera(gimballed=gimballed)
    pose = _pose(80.0, yaw=-2.0, pitch=0.15, roll=-0.1)
    rng = np.random.default_rng(3)
    pts = np.array([10.0, -20.0]) + rng.uniform(-30.0, 30.0, (50, 2))
    pix, front = cam.project(pose, pts)
    assert np.all(front)
    np.testing.assert_allclose(cam.to_position(pose, pix), pts, atol=1e-8)


def test_rays_above_the_horizon_map_to_finite_points() -> None:
    """A fixed camera pitched up 80° sees sky at the image top; h⁻¹ still gives finite points."""
    cam = DownwardCamera(gimballed=False)
    pose = _pose(50.0, pitch=1.4)
    ground = cam.to_position(pose, np.array([[0.0, 320.0], [480.0, 320.0]]))
    assert np.all(np.isfinite(ground))
    assert np.linalg.norm(ground[0] - pose[:2]) > 1000.0  # clamped 1° below the horizon


def test_gimbal_ignores_pitch_and_roll() -> None:
    """A gimballed camera sees the same with any pitch and roll; a fixed one does not."""
    pts = np.array([[30.0, -20.0], [10.0, 0.0]])
    level, tilted = _pose(50.0, 0.3), _pose(50.0, 0.3, pitch=0.3, roll=0.2)
    np.testing.assert_allclose(CAM.project(level, pts)[0], CAM.project(tilted, pts)[0])
    fixed = DownwardCamera(gimballed=False)
    assert not np.allclose(fixed.project(level, pts)[0], fixed.project(tilted, pts)[0])


def test_likelihood_integrates_to_one_over_the_image() -> None:
    """Summing g(z | x) over a fine pixel grid around the image of x gives 1."""
    pose = _pose(90.0, yaw=0.7)
    x = np.array([[20.0, -15.0]])
    centre, _ = CAM.project(pose, x)
    step = 0.25
    r = centre[0, 0] + np.arange(-20.0, 20.0, step)
    c = centre[0, 1] + np.arange(-20.0, 20.0, step)
    grid = np.stack(np.meshgrid(r, c, indexing="ij"), axis=-1).reshape(-1, 2)
    lik = CAM.likelihood(pose, grid, x)
    assert lik.shape == (grid.shape[0], 1)
    assert lik.sum() * step * step == pytest.approx(1.0, abs=1e-3)
    assert np.argmax(lik[:, 0]) == np.argmin(np.sum((grid - centre) ** 2, axis=1))


def test_clutter_is_uniform_over_the_image() -> None:
    """c(z) = λ_c / (W H) inside the image and 0 outside, so it integrates to λ_c."""
    cam = DownwardCamera(clutter_rate=3.0)
    z = np.array([[10.0, 10.0], [479.0, 639.0], [-1.0, 5.0], [5.0, 700.0]])
    c = cam.clutter_intensity(_pose(50.0), z)
    np.testing.assert_allclose(c, [3.0 / (640 * 480)] * 2 + [0.0, 0.0])
    assert c[0] * cam.image_area_px2 == pytest.approx(3.0)


def test_measure_is_seeded_and_labels_origins() -> None:
    """Simulated images repeat for a seed, lie in the image and find the visible targets."""
    cam = DownwardCamera(pd_max=1.0, pd0=1.0, clutter_rate=2.0)
    pose = _pose(60.0)
    targets = np.array([[10.0, -20.0], [15.0, -25.0], [900.0, 900.0]])
    z1, o1 = cam.measure(pose, targets, np.random.default_rng(5))
    z2, o2 = cam.measure(pose, targets, np.random.default_rng(5))
    np.testing.assert_array_equal(z1, z2)
    np.testing.assert_array_equal(o1, o2)
    assert np.all(cam.in_image(z1))
    assert sorted(o1[o1 >= 0].tolist()) == [0, 1]
    back = cam.to_position(pose, z1[o1 == 0])
    assert np.linalg.norm(back[0] - targets[0]) < 1.0


@pytest.mark.parametrize(("field", "value"), [
    ("width_px", 0), ("height_px", 2.5), ("hfov_rad", 0.0), ("hfov_rad", math.pi),
    ("target_length_m", -1.0), ("pd0", 1.5), ("pd_max", -0.1), ("slope_per_px", 0.0),
    ("n_px0", -1.0), ("sigma_px", 0.0), ("clutter_rate", -1.0), ("gimballed", 1),
    ("hfov_rad", math.nan),
])
def test_bad_constructor_input(field: str, value: object) -> None:
    """Every bad constructor argument raises InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError) as err:
        DownwardCamera(**{field: value})  # type: ignore[arg-type]
    assert err.value.field == field


def test_pd_max_below_pd0_is_refused() -> None:
    """pd_max < pd0 is refused."""
    with pytest.raises(InvalidInputError, match="pd_max"):
        DownwardCamera(pd0=0.5, pd_max=0.4)


@pytest.mark.parametrize("pose", [[0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 10.0], [0, 0, 10, 0, 0, 0, 0],
                                  [0.0, math.nan, 10.0, 0.0]])
def test_bad_pose(pose: list[float]) -> None:
    """A pose on or below the ground, too short, too long or not finite is refused."""
    with pytest.raises(InvalidInputError, match="pose"):
        CAM.detection_probability(np.array(pose, dtype=float), np.zeros((1, 2)))
