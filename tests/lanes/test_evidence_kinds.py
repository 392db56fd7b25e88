"""Marking evidence by kind: raised pavement markers, concrete seams and tar lines, shadow edges, yellow paint on
pale concrete; synthetic ground painted through the rig's homography (positions known), then real frames."""

from pathlib import Path

import cv2
import numpy as np
import pytest

from percept.lanes import MarkingExtractor, fit_lane
from percept.lanes.realworld import FootageLanes, RealLaneConfig
from percept.sensors import StereoRig

from .test_real_footage import on_marking_fraction

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data"
TUSIMPLE = DATA / "tusimple-samples"
UDACITY = DATA / "udacity-lanes" / "test_images"
FOOTAGE = RealLaneConfig().lane.evidence  # the evidence settings percept uses on recorded footage


class Ground:
    """A camera image of a flat road: ground polygons (vehicle frame, metres) painted through the homography."""

    def __init__(self, road_bgr=(90, 90, 90)):
        self.rig = StereoRig()
        self.H = self.rig.ground_homography()
        self.image = np.empty((480, 640, 3), np.uint8)
        self.image[:] = road_bgr

    def paint(self, xy_m: np.ndarray, bgr) -> None:
        p = np.column_stack([xy_m, np.ones(len(xy_m))]) @ self.H.T
        cv2.fillPoly(self.image, [np.round(p[:, :2] / p[:, 2:] * 16).astype(np.int32)], bgr, cv2.LINE_AA, shift=4)

    def stripe(self, y0: float, y1: float, bgr, x0: float = 6.0, x1: float = 45.0) -> None:
        self.paint(np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float), bgr)

    def dot(self, x: float, y: float, bgr, radius_m: float = 0.05) -> None:
        a = np.linspace(0, 2 * np.pi, 16, endpoint=False)
        self.paint(np.column_stack([x + radius_m * np.cos(a), y + radius_m * np.sin(a)]), bgr)

    def evidence(self):
        return MarkingExtractor(self.rig, FOOTAGE).extract(self.image)


def near(ev, y_m: float, tol_m: float = 0.1) -> int:
    return int((np.abs(ev.points_m[:, 1] - y_m) < tol_m).sum())


def test_a_row_of_raised_markers_is_a_boundary():
    g = Ground()
    for x in np.arange(6.0, 45.0, 1.2):  # Botts' dots: 10 cm discs 1.2 m apart
        g.dot(x, 1.85, (235, 235, 235))
    for x in np.arange(6.0, 45.0, 12.0):  # dashes 3 m long on the right
        g.stripe(-1.925, -1.775, (235, 235, 235), x, x + 3.0)
    ev = g.evidence()
    assert near(ev, 1.85) >= 20
    fit = fit_lane(ev, None)
    assert fit.inliers_left >= 20 and fit.inliers_right >= 20
    assert fit.estimate.width_m == pytest.approx(3.7, abs=0.1) and fit.estimate.offset_m == pytest.approx(0, abs=0.05)


@pytest.mark.parametrize("width_m", [0.03, 0.10], ids=["seam", "tar line"])
def test_seams_and_tar_lines_leave_no_evidence(width_m):
    g = Ground((150, 150, 150))  # pale concrete
    g.stripe(-0.9 - width_m / 2, -0.9 + width_m / 2, (45, 45, 45))
    g.stripe(0.6 - width_m / 2, 0.6 + width_m / 2, (70, 70, 70))
    g.stripe(1.775, 1.925, (240, 240, 240))  # the one marking
    ev = g.evidence()
    assert near(ev, -0.9, 0.25) == 0 and near(ev, 0.6, 0.25) == 0
    assert near(ev, 1.85) > 50


def test_a_shadow_edge_is_not_a_marking_and_the_markings_in_shade_remain():
    g = Ground((120, 120, 120))
    g.stripe(-4.0, -0.5, (55, 55, 55))  # shade over the right of the road: its edge runs along the road
    g.stripe(1.775, 1.925, (235, 235, 235))
    g.stripe(-1.925, -1.775, (110, 110, 110))  # the right marking, in shade
    ev = g.evidence()
    assert near(ev, -0.5, 0.25) == 0
    assert near(ev, 1.85) > 50 and near(ev, -1.85) > 50


def test_yellow_paint_on_pale_concrete_stands_out():
    g = Ground((170, 178, 180))  # BGR: pale concrete
    g.stripe(1.775, 1.925, (60, 185, 205))  # yellow: little brighter than the concrete in R and G
    ev = g.evidence()
    assert near(ev, 1.85) > 50
    # the yellowness term, not brightness, carries it: max(R, G) alone sees ~25 grey levels
    assert np.median(ev.strength[np.abs(ev.points_m[:, 1] - 1.85) < 0.1]) > 100


@pytest.fixture(scope="module")
def tusimple_0():
    if not TUSIMPLE.is_dir():
        pytest.skip(f"{TUSIMPLE} is absent (real data in ../shared/data)")
    images = [cv2.imread(str(p)) for p in sorted(TUSIMPLE.glob("*.jpg"))]
    lanes = FootageLanes()
    lanes.calibrate(images)  # one camera: its height from the four frames
    return images[0], lanes.still(images[0])


@pytest.mark.slow
def test_raised_markers_on_a_real_freeway_carry_the_left_boundary(tusimple_0):
    _, r = tusimple_0
    # 0.jpg marks its left boundary with clusters of Botts' dots; one cluster spans (456, 404) to (404, 446) px
    uv, side = r.debug.evidence.uv_px, r.debug.fit.side
    on_dots = (uv[:, 0] > 400) & (uv[:, 0] < 460) & (uv[:, 1] > 400) & (uv[:, 1] < 450)
    assert on_dots.sum() >= 8 and (side[on_dots] == 1).all()
    rows = np.array([404.0, 425.0, 446.0])
    assert np.abs(r.u_at_rows(rows)["left"] - np.interp(rows, [404, 446], [456, 404])).max() < 15


@pytest.mark.slow
def test_a_pale_strip_beside_a_seam_does_not_take_the_boundary_but_lowers_the_confidence(tusimple_0):
    image, r = tusimple_0
    # the right boundary is the solid white line; a strip of paler concrete along a seam ~1 m inside it looks like
    # paint too: the line's stronger evidence wins, and the rival lane shows in the confidence
    right = r.boundaries_px["right"]
    assert on_marking_fraction(image, right) > 0.6
    assert 0.2 < r.debug.fit.ambiguity < 0.5 and r.estimate.confidence < 0.8


def test_tree_shadows_on_real_asphalt_give_no_boundary_evidence():
    if not UDACITY.is_dir():
        pytest.skip(f"{UDACITY} is absent (real data in ../shared/data)")
    image = cv2.imread(str(UDACITY / "test4.jpg"))  # dappled shade across the ego lane
    r = FootageLanes(RealLaneConfig(mount_height_m=1.2)).still(image)
    rows = np.arange(450.0, 680.0, 10.0)
    u = r.u_at_rows(rows)
    uv, side = r.debug.evidence.uv_px, r.debug.fit.side
    inside = np.zeros(len(uv), bool)
    for v, ul, ur in zip(rows, u["left"], u["right"]):
        inside |= (np.abs(uv[:, 1] - v) <= 5) & (uv[:, 0] > ul + 40) & (uv[:, 0] < ur - 40)
    # what the shade's edges leave between the markings is a few stray points, none taken for a boundary
    assert inside.sum() < 0.05 * len(uv) and (side[inside] == 0).all()
    for pts in r.boundaries_px.values():
        assert on_marking_fraction(image, pts) > 0.3


def test_a_barrier_and_the_cars_beside_the_lane_give_no_boundary_evidence():
    if not UDACITY.is_dir():
        pytest.skip(f"{UDACITY} is absent (real data in ../shared/data)")
    image = cv2.imread(str(UDACITY / "test5.jpg"))  # a concrete barrier with a rail on the left, two cars ahead right
    r = FootageLanes(RealLaneConfig(mount_height_m=1.2)).still(image)
    uv, side = r.debug.evidence.uv_px, r.debug.fit.side
    left_u = r.u_at_rows(uv[:, 1])["left"]
    barrier = np.isfinite(left_u) & (uv[:, 0] < left_u - 60)
    cars = [(uv[:, 0] > u0) & (uv[:, 0] < u1) & (uv[:, 1] > v0) & (uv[:, 1] < v1)
            for u0, u1, v0, v1 in ((808, 933, 408, 492), (1083, 1280, 400, 508))]
    # their edges pass the stripe test (evidence is there) but neither boundary takes any of it
    for region in [barrier] + cars:
        assert region.sum() >= 10 and (side[region] == 0).all()
    for pts in r.boundaries_px.values():
        assert on_marking_fraction(image, pts) > 0.3
