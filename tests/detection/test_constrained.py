"""The ground-constrained search on a rendered crossing: it scores only windows where a person standing on the road
can be, finds a person 30 m ahead (33 px tall, below what a full pyramid from scale 1 can see) and skips most of the
full pyramid's windows over the same scales."""

from dataclasses import replace

import numpy as np
import pytest

from percept.detection import LinearModel, window_of
from percept.detection.constrained import PERSON_PX, ConstrainedSearch, SearchConfig
from percept.sensors import EgoPath, ObjectKind, StereoRig, iou
from percept.sims import SimWorld, WorldConfig


@pytest.fixture(scope="module")
def crossing_frame():
    w = SimWorld(WorldConfig("crossing", 100))
    for _ in range(140):
        w.step(0.0, 0.0)
    frame, gt = w.observe()
    return w.cfg.rig, frame, gt


def test_the_constrained_search_finds_a_far_person_and_skips_most_windows(crossing_frame):
    rig, frame, gt = crossing_frame
    people = [o for o in gt.objects if o.kind is ObjectKind.PEDESTRIAN and o.visible >= 0.5 and o.box_px
              and 24 <= o.box_px[3] - o.box_px[1] <= 40]
    assert people, "the frame should hold a far pedestrian"
    search = ConstrainedSearch(rig, LinearModel.inria())
    dets, stats = search.search(frame.left, EgoPath.straight(frame.wheel_speed_mps))
    for p in people:
        assert max(iou(window_of(p.box_px), d.box_px) for d in dets) >= 0.5
    assert stats.removed >= 0.9 and stats.windows < stats.full_windows
    # scales from the smallest person searched (24 px) to the tallest near one
    assert search.scales[0] == pytest.approx(24 / PERSON_PX)


def test_no_scale_admits_a_person_outside_the_searched_depths():
    search = ConstrainedSearch(StereoRig(), LinearModel.inria(), SearchConfig(min_range_m=10.0, max_range_m=20.0))
    path = EgoPath.straight(10.0)
    # a 2.1 m person at 5 m would be 233 px tall: no window that large is ever scored
    big = [s for k, s in enumerate(search.scales) if search.region(k, path) is not None and s * PERSON_PX > 150]
    assert not big and np.all(np.diff(search.scales) > 0)


def test_a_cascade_keeps_what_its_second_stage_confirms(crossing_frame):
    """The search with a second stage that confirms every window finds what the first model alone finds; one that
    confirms none finds nothing (the second stage is applied to the search's detections, windows and lone ones)."""
    rig, frame, _ = crossing_frame
    path = EgoPath.straight(frame.wheel_speed_mps)
    first = LinearModel.inria()
    alone, _ = ConstrainedSearch(rig, first).search(frame.left, path)
    assert alone
    for threshold, expected in ((-1e6, alone), (1e6, [])):
        cascade = replace(first, second=first, second_threshold=threshold)
        dets, _ = ConstrainedSearch(rig, cascade).search(frame.left, path)
        assert dets == expected


def test_a_region_is_clipped_to_the_same_whole_pixels_as_numpys_floor_and_ceil():
    """``clip`` (math.floor / math.ceil after clipping) gives the pixels of int(max(np.floor(u0), 0)), ...,
    int(min(np.ceil(u1), width)), for corners inside, outside, on whole pixels and at infinity."""
    rig = StereoRig()
    search = ConstrainedSearch(rig, LinearModel.inria())
    cam = rig.camera
    rng = np.random.default_rng(3)
    corners = list(rng.uniform(-200, 900, (400, 4))) + [np.array([-np.inf, 3.0, np.inf, np.inf]),
                                                        np.array([0.0, -0.0, 640.0, 480.0]),
                                                        np.array([-1.0, 2.0, 603.0, 467.0])]
    kept = 0
    for u0, v0, u1, v1 in corners:
        box = (np.float64(u0), float(v0), np.float64(u1), float(v1))
        want = (int(max(np.floor(box[0]), 0)), int(max(np.floor(box[1]), 0)), int(min(np.ceil(box[2]), cam.width)),
                int(min(np.ceil(box[3]), cam.height)))
        got = search.clip(box, 0.5)
        small = want[2] - want[0] < 32 or want[3] - want[1] < 64
        assert got == (None if small else want)
        assert got is None or all(type(c) is int for c in got)
        kept += got is not None
    assert 50 < kept < len(corners)
