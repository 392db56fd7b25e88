"""When a neighbour track counts as laterally still in its lane, which a cut-in warning needs first (a settled
neighbour): its filter starts at rest, so a new track's lateral speed is at first the prior's."""

from percept.neighbours import NeighbourTracker, TrackerConfig

from .test_tracker import DT, W, det


def test_a_track_born_moving_sideways_is_not_still():
    tr = NeighbourTracker(DT)
    # first found 40 m ahead in the lane beside, already moving towards the ego lane at 1.5 m/s
    for k in range(20):
        tr.step({"front": [det(40.0, W + 1.0 - 1.5 * k * DT)]}, W)
        (t,) = tr.tracks
        assert not t.still and t.settled == 0


def test_a_still_car_is_still_once_confirmed_and_calm_and_settled_after_that():
    cfg = TrackerConfig()
    tr = NeighbourTracker(DT, cfg)
    still_at = None
    for k in range(30):
        tr.step({"front": [det(40.0, W)]}, W)
        (t,) = tr.tracks
        still_at = k + 1 if t.still and still_at is None else still_at
    # detections confirm_hits .. confirm_hits + still_frames - 1 are the calm ones
    assert still_at == cfg.confirm_hits + cfg.still_frames - 1
    assert t.settled == 30 - still_at + 1
