"""A sliver (a face too narrow for a car's, seen whole within ``whole_face_m``) starts no track and helps confirm none:
posts, markings' edges, rain and patches of road matched by chance are such slivers, a car's face is not."""

from dataclasses import replace

from percept.neighbours import NeighbourTracker, TrackerConfig

from .test_tracker import DT, W, det


def _frames(dets: list, frames: int = 15) -> NeighbourTracker:
    """A tracker fed the same rear detections ``frames`` times."""
    tr = NeighbourTracker(DT)
    for _ in range(frames):
        tr.step({"rear": list(dets)}, W)
    return tr


def test_a_sliver_within_the_whole_face_range_starts_no_track():
    assert _frames([replace(det(-40.0, W), width_m=0.4)]).tracks == []


def test_a_car_wide_face_there_does():
    (t,) = _frames([det(-40.0, W)]).tracks
    assert t.confirmed


def test_a_sliver_cut_off_by_the_image_edge_or_far_away_starts_one():
    cut = replace(det(-20.0, W), width_m=0.0, cut_off=True)
    far = replace(det(-TrackerConfig().whole_face_m - 10.0, W), width_m=0.4)
    for d in (cut, far):
        (t,) = _frames([d]).tracks
        assert t.confirmed


def test_a_sliver_still_updates_a_car_s_track():
    tr = _frames([det(-40.0, W)])
    (t,) = tr.tracks
    hits = t.hits
    # the car's face shrinks to a sliver for a frame (a lit part of it lost at night)
    tr.step({"rear": [replace(det(-40.0, W), width_m=0.4)]}, W)
    assert tr.tracks == [t] and t.hits == hits + 1 and t.misses == 0


def test_slivers_do_not_confirm_a_track_a_cut_off_face_started():
    # rain at the rear image's edge beside the ego: one face cut off by the edge, then slivers
    cut = replace(det(-18.0, W), width_m=0.0, cut_off=True)
    sliver = replace(det(-18.0, W), width_m=0.4)
    tr = NeighbourTracker(DT)
    for d in (cut, sliver, sliver, sliver):
        tr.step({"rear": [d]}, W)
    (t,) = tr.tracks
    assert t.hits == 4 and not t.confirmed
