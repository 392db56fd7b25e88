"""The two cues beside stereo: time to contact from image expansion (synthetic scaling) and range from ground contact
(a rendered car at known ranges)."""

import cv2
import numpy as np
import pytest
from highway_env.road.road import RoadNetwork

from percept.longitudinal import ContactRange, ExpansionTracker, FlowConfig
from percept.sensors import Pose2D, StereoRig
from percept.sims.render import ObjectKind, ObjectState, Scene, StereoRenderer
from percept.sims.road_geometry import build_road_geometry


def textured(size=(240, 320), seed=0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    img = cv2.GaussianBlur(rng.uniform(0, 255, size).astype(np.float32), (0, 0), 1.5)
    return cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8)


def scaled(img: np.ndarray, s: float, centre=(160.0, 120.0)) -> np.ndarray:
    # x' = c + s (x - c): what an object at range Z0 looks like at Z1 = Z0 / s
    M = np.array([[s, 0, centre[0] * (1 - s)], [0, s, centre[1] * (1 - s)]])
    return cv2.warpAffine(img, M, img.shape[::-1], flags=cv2.INTER_CUBIC, borderMode=cv2.BORDER_REFLECT)


@pytest.mark.parametrize("s", [0.98, 1.0, 1.03])
def test_expansion_recovers_the_scale_change_and_its_time_to_contact(s):
    base = textured()
    tracker = ExpansionTracker(FlowConfig(frames_back=1))
    box = (130, 95, 190, 145)
    assert tracker.measure(base, box, 0.0) is None  # one frame: nothing to compare with
    e = tracker.measure(scaled(base, s), box, 0.2)
    assert e is not None and e.features >= 10
    assert e.scale == pytest.approx(s, abs=0.002)
    # dZ/dt = -Z (s - 1) / dt; tau = dt / (s - 1) while it expands
    assert e.range_rate_mps(30.0) == pytest.approx(-30.0 * (s - 1) / 0.2, abs=0.35)
    if s > 1:
        assert e.ttc_s == pytest.approx(0.2 / (s - 1), rel=0.1)
    else:
        assert e.ttc_s is None


def test_expansion_needs_texture_and_a_box_that_fits():
    tracker = ExpansionTracker()
    flat = np.full((240, 320), 90, np.uint8)
    tracker.measure(flat, (100, 100, 160, 150), 0.0)
    assert tracker.measure(flat, (100, 100, 160, 150), 0.1) is None
    tracker.reset()
    tracker.measure(textured(), (100, 100, 104, 103), 0.0)
    assert tracker.measure(textured(), (100, 100, 104, 103), 0.1) is None


@pytest.fixture(scope="module")
def renderer():
    rig = StereoRig()
    return rig, StereoRenderer(rig, build_road_geometry(RoadNetwork.straight_road_network(4, length=400)), seed=3,
                               scenery=False)


@pytest.mark.parametrize("range_m", [12.0, 25.0, 40.0])
def test_ground_contact_range_of_a_rendered_car(renderer, range_m):
    rig, r = renderer
    ego = Pose2D(100.0, -4.0, 0.0)
    # the car's rear face range_m ahead of the left camera
    x = ego.x_m + rig.mount_x_m + range_m + 4.8 / 2
    car = ObjectState(1, ObjectKind.VEHICLE, Pose2D(x, ego.y_m, 0.0), 4.8, 1.9, 1.5, style=3)
    out = r.render(Scene(ego, (car,)))
    gray = cv2.cvtColor(out.left, cv2.COLOR_BGR2GRAY)
    # a guess 10 % off (a coarse stereo range) still finds the edge
    c = ContactRange(rig).measure(gray, out.boxes_px[1], range_m * 1.1)
    assert c is not None
    # within the edge's one-pixel quantisation (dZ = Z^2 / (f H) per row) and 2 %
    assert abs(c.range_m - range_m) < max(range_m ** 2 / (rig.camera.fy * rig.mount_height_m), 0.02 * range_m)
    assert c.sigma_m == pytest.approx(range_m ** 2 / (rig.camera.fy * rig.mount_height_m) * 0.29, rel=0.15)


def test_ground_contact_needs_an_edge(renderer):
    rig, _ = renderer
    flat = np.full((rig.camera.height, rig.camera.width), 100, np.uint8)
    assert ContactRange(rig).measure(flat, (300, 230, 340, 260), 30.0) is None


def _numpy_pair_ratios(a: np.ndarray, b: np.ndarray, min_pair_px: float) -> np.ndarray:
    """The pairs' ratios as the expansion took them before they were compiled."""
    a, b = a.astype(np.float64), b.astype(np.float64)
    i, j = np.triu_indices(len(a), 1)
    d0 = np.linalg.norm(a[i] - a[j], axis=1)
    far = d0 >= min_pair_px
    return np.linalg.norm(b[i] - b[j], axis=1)[far] / d0[far]


def test_pair_ratios_equal_numpys_bit_for_bit():
    from percept.longitudinal.flow import pair_ratios

    rng = np.random.default_rng(5)
    for n in (0, 1, 2, 7, 40, 80):
        for spread in (3.0, 60.0, 400.0):
            a = (rng.random((n, 2)) * spread).astype(np.float32)
            b = (a * rng.uniform(0.9, 1.1) + rng.normal(0, 0.3, (n, 2))).astype(np.float32)
            if n > 3:
                a[3] = a[1]  # a repeated point: a pair at distance 0 is left out
            got, want = pair_ratios(a, b, 6.0), _numpy_pair_ratios(a, b, 6.0)
            assert got.dtype == want.dtype and got.tobytes() == want.tobytes(), (n, spread)
    with pytest.raises(ValueError, match="different numbers of points"):
        pair_ratios(np.zeros((3, 2), np.float32), np.zeros((2, 2), np.float32), 6.0)
