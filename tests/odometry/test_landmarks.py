"""Landmark sightings on rendered frames: the mapped sign found, measured by stereo within its stated error."""

import numpy as np

from percept.odometry import LandmarkFinder, SightingConfig
from percept.odometry.landmarks import MIN_PERIMETER_RATE
from percept.sensors import LandmarkMap, Pose2D


def test_signs_are_found_and_measured_within_their_stated_error(loop_run):
    world, shots = loop_run
    lm = world.landmark_map()
    finder = LandmarkFinder(world.cfg.rig, lm)
    seen = []
    for frame, gt in shots[110:]:
        for s in finder.sight(frame.left, frame.right, gt.ego, np.diag([0.04, 0.04, 1e-4])):
            true = gt.ego.to_vehicle_xy(lm.position(s.marker_id)[None, :2])[0]
            e = s.position_v_m[:2] - true
            # normalised error squared against chi2 (2 dof) at 99.73 %
            seen.append((s.marker_id, s.range_m, float(e @ np.linalg.solve(s.covariance_xy, e)), np.abs(e)))
    assert len(seen) >= 5
    assert {m for m, *_ in seen} == {3}
    assert all(10.0 < r < 32.0 for _, r, *_ in seen)
    assert all(nees < 11.83 for *_, nees, _ in seen)
    assert max(e[1] for *_, e in seen) < 0.5  # lateral [m]


def test_nothing_is_searched_without_a_sign_in_range(loop_run):
    world, shots = loop_run
    rig = world.cfg.rig
    frame, gt = shots[140]
    empty = LandmarkFinder(rig, LandmarkMap((), np.zeros((0, 3))))
    assert empty.expected(gt.ego, np.eye(3) * 0.01) == [] and empty.sight(frame.left, frame.right, gt.ego,
                                                                          np.eye(3)) == []
    # looking the wrong way: every mapped sign is behind
    finder = LandmarkFinder(rig, world.landmark_map())
    back = Pose2D(gt.ego.x_m, gt.ego.y_m, gt.ego.yaw_rad + np.pi)
    assert finder.expected(back, np.eye(3) * 0.01) == []
    # a black frame where a sign is expected: no sighting, no error
    black = np.zeros_like(frame.left)
    assert finder.expected(gt.ego, np.eye(3) * 0.01) and finder.sight(black, black, gt.ego, np.eye(3) * 0.01) == []


def test_skipping_small_candidates_finds_the_same_corners(loop_run):
    """Candidates under a quarter of the marker's expected perimeter are not checked (most of ArUco's cost): the
    same signs are found at the same corners as with OpenCV's default floor, over a wide pose uncertainty too."""
    world, shots = loop_run
    lm = world.landmark_map()
    quick = LandmarkFinder(world.cfg.rig, lm)
    full = LandmarkFinder(world.cfg.rig, lm, SightingConfig(min_perimeter_share=0.0))
    found, rates = 0, []
    for frame, gt in shots[110::2]:
        for cov in (np.diag([0.04, 0.04, 1e-4]), np.diag([4.0, 4.0, 4e-3])):
            a, b = quick.sight(frame.left, frame.right, gt.ego, cov), full.sight(frame.left, frame.right, gt.ego, cov)
            assert [s.marker_id for s in a] == [s.marker_id for s in b]
            assert all(np.array_equal(s.corners_px, t.corners_px) for s, t in zip(a, b))
            found += len(a)
            rates += [rate for *_, rate in quick.expected(gt.ego, cov)]
    assert found >= 6
    # the floor is OpenCV's default at the least, and well above it where the sign is expected big in its window
    assert min(rates) >= MIN_PERIMETER_RATE and max(rates) > 3 * MIN_PERIMETER_RATE
