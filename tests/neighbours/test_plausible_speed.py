"""A track faster over the ground than any car (``NeighbourConfig.max_ground_speed_mps``) is not reported: behind the
ego, three car-wide faces matched by chance along the lane beside, strung into one track, read 35 m/s closing."""

import pytest

from percept.neighbours import NeighbourConfig, NeighbourSlot
from percept.sensors import EgoPath, StereoRig

from .test_tracker import DT, _FakeFinder, det

EGO_MPS = 22.0
FRAME = type("F", (), {"dropped": False, "has_rear": True, "left_gray": None, "right_gray": None,
                       "rear_left_gray": None, "rear_right_gray": None})()


def _behind(dets: list, cfg: NeighbourConfig = NeighbourConfig()) -> list:
    """The slot's reports behind the ego on each frame of rear detections ``dets`` (None: nothing found)."""
    slot = NeighbourSlot(StereoRig(), None, DT, cfg)
    slot.front, slot.rear = _FakeFinder([None] * len(dets)), _FakeFinder(dets)
    out = []
    for _ in dets:
        nb, _ = slot.step(FRAME, {EgoPath: EgoPath.straight(EGO_MPS)})
        out.append([n for n in nb.tracks if n.x_m < 0])
    return out


def test_things_strung_into_a_track_faster_than_any_car_are_not_reported():
    posts = [det(-40.8, 5.2), det(-42.0, 5.1), det(-37.0, 4.3)] + [None] * 4
    assert not any(_behind(posts))
    # without the bound it is a car closing at over 30 m/s
    fast = _behind(posts, NeighbourConfig(max_ground_speed_mps=1e9))
    assert fast[2] and fast[2][0].rel_speed_mps > 30.0


def test_a_car_closing_fast_but_within_a_cars_speed_is_reported():
    car = [det(-60.0 + 12.0 * k * DT, 4.0) for k in range(45)]
    reports = _behind(car)
    assert all(reports[k] for k in range(3, 45))
    assert reports[-1][0].rel_speed_mps == pytest.approx(12.0, abs=0.5)
