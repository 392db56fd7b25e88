"""The person-path conflict rule shared by the privileged and vision pedestrian slots."""

import pytest

from percept.sensors.conflict import PERSON_CORRIDOR_HALF_M, person_conflict


@pytest.mark.parametrize("y, vy, now, entering", [
    (0.5, 0.0, True, False),     # standing in the lane
    (6.0, 0.0, False, False),    # standing on the verge
    (6.0, 0.1, False, False),    # shuffling on the verge: slower than a walk
    (4.0, -1.4, False, True),    # walking towards the lane, within a lane of it
    (-4.0, 1.4, False, True),    # the same from the right
    (4.0, 1.4, False, False),    # walking away: has left the corridor
    (7.0, -1.4, False, True),    # two lanes away, but inside the corridor when the ego arrives (20 m at 5 m/s)
    (14.0, -1.4, False, False),  # too far to get there in time
])
def test_who_conflicts_with_the_path(y, vy, now, entering):
    c = person_conflict(20.0, y, vy, centre_y_m=0.0, lane_width_m=3.5, ego_speed_mps=5.0)
    assert (c.now, c.entering) == (now, entering)
    assert c.any == (now or entering)


def test_the_corridor_follows_the_path_centre():
    # the path bends 3 m to the left at 20 m: a person standing there is in it
    assert person_conflict(20.0, 3.0, 0.0, centre_y_m=3.0, lane_width_m=3.5, ego_speed_mps=10.0).now
    assert not person_conflict(20.0, 3.0 + PERSON_CORRIDOR_HALF_M + 0.01, 0.0, 3.0, 3.5, 10.0).now
