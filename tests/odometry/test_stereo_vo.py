"""Stereo visual odometry on rendered frames against the simulator's truth, and its degraded modes."""

import math

import numpy as np
import pytest

from percept.odometry import StereoVO, StereoVOConfig
from percept.sensors import StereoRig


def vo_for(rig: StereoRig) -> StereoVO:
    return StereoVO(rig.camera.K, rig.baseline_m, rig.mount_height_m)


def travelled(a, b) -> float:
    return math.hypot(b.ego.x_m - a.ego.x_m, b.ego.y_m - a.ego.y_m)


def test_steps_match_the_true_motion(loop_run):
    world, shots = loop_run
    vo = vo_for(world.cfg.rig)
    est, true = [], []
    for k, (frame, gt) in enumerate(shots[:60]):
        step = vo.process(frame.left, frame.right)
        if k:
            assert step.ok, step.reason
            # the camera's forward motion is the car's (straight road, no pitch)
            est.append(step.T_prev_cur[2, 3])
            true.append(travelled(shots[k - 1][1], gt))
            assert step.inliers >= 12 and 0 < step.quality <= 1
            assert np.all(np.linalg.eigvalsh(step.covariance) > 0)
    est, true = np.array(est), np.array(true)
    assert np.median(np.abs(est - true) / true) < 0.02
    assert abs(est.sum() - true.sum()) / true.sum() < 0.01  # 86 m


def test_a_dropped_frame_is_bridged_by_the_next_step(loop_run):
    world, shots = loop_run
    vo = vo_for(world.cfg.rig)
    for frame, _ in shots[:5]:
        vo.process(frame.left, frame.right)
    dropped = vo.process(None, None)
    assert not dropped.ok and dropped.reason == "dropped frame"
    assert np.array_equal(dropped.T_prev_cur, np.eye(4))
    step = vo.process(shots[6][0].left, shots[6][0].right)
    # measured from the last image (frame 4) to frame 6: two frames of motion
    assert step.ok
    assert step.T_prev_cur[2, 3] == pytest.approx(travelled(shots[4][1], shots[6][1]), rel=0.03)


def test_a_black_frame_fails_softly_and_tracking_restarts(loop_run):
    world, shots = loop_run
    vo = vo_for(world.cfg.rig)
    vo.process(shots[0][0].left, shots[0][0].right)
    black = np.zeros_like(shots[1][0].left)
    step = vo.process(black, black)
    assert not step.ok and "featureless" in step.reason
    vo.process(shots[2][0].left, shots[2][0].right)  # a new keyframe
    step = vo.process(shots[3][0].left, shots[3][0].right)
    assert step.ok and step.T_prev_cur[2, 3] == pytest.approx(travelled(shots[2][1], shots[3][1]), rel=0.05)


def test_bad_input_is_refused_with_a_clear_message():
    rig = StereoRig()
    with pytest.raises(ValueError, match="baseline_m must be positive"):
        StereoVO(rig.camera.K, 0.0)
    with pytest.raises(ValueError, match="finite \\(3, 3\\) intrinsic"):
        StereoVO(np.eye(2), 0.5)
    with pytest.raises(ValueError, match="camera_height_m must be positive"):
        StereoVO(rig.camera.K, 0.5, camera_height_m=-1.0)
    with pytest.raises(ValueError, match="min_inliers"):
        StereoVOConfig(min_inliers=2)
    vo = vo_for(rig)
    with pytest.raises(ValueError, match="differ in size"):
        vo.process(np.zeros((480, 640), np.uint8), np.zeros((240, 320), np.uint8))


def test_a_motion_prior_and_mover_boxes_are_used(loop_run):
    world, shots = loop_run
    rig = world.cfg.rig
    T_cv = rig.cam_from_vehicle().matrix()
    vo = vo_for(rig)
    vo.process(shots[0][0].left, shots[0][0].right)
    forward = 0.0
    for k in range(1, 11):
        a, b = shots[k - 1][1].ego.world_from_vehicle().matrix(), shots[k][1].ego.world_from_vehicle().matrix()
        prior = T_cv @ np.linalg.inv(a) @ b @ np.linalg.inv(T_cv)
        step = vo.process(shots[k][0].left, shots[k][0].right, prior)
        assert step.ok
        forward += step.T_prev_cur[2, 3]
    assert forward == pytest.approx(travelled(shots[0][1], shots[10][1]), rel=0.02)
    # a mover box over the whole image leaves nothing to use
    vo.reset()
    step = vo.process(shots[0][0].left, shots[0][0].right, movers=[(0, 0, 640, 480)])
    assert not step.ok and "only 0 corners" in step.reason


def test_each_keyframe_light_picks_its_window_and_pyramid(loop_run, monkeypatch):
    from percept.odometry import stereo_vo

    world, shots = loop_run
    calls = []
    real_track = stereo_vo.track

    def spy(prev, cur, pts, win_px, levels, guess=None):
        calls.append((win_px, levels, guess is not None))
        return real_track(prev, cur, pts, win_px, levels, guess)

    monkeypatch.setattr(stereo_vo, "track", spy)
    cfg = StereoVOConfig()
    vo = vo_for(world.cfg.rig)

    def dark(img):  # a third of the brightness: a mean grey level of ~45 (the night's ~55)
        return (img.astype(np.float32) / 3).astype(np.uint8)

    def flat(img):  # half the contrast about mid-grey: a spread of ~21 (the rain's 26-27)
        return (128 + (img.astype(np.float32) - 128) / 2).astype(np.uint8)

    # each keyframe's stereo match (cfg.levels, from the road's disparity guess), then the tracking from it with the
    # motion prior (the car's true motion, as the slot gives it from wheel speed and gyro)
    for look, win, levels in ((dark, cfg.dark_win_px, cfg.prior_levels), (flat, cfg.win_px, cfg.prior_levels),
                              (lambda img: img, cfg.lit_win_px, cfg.lit_prior_levels)):
        vo.reset()
        calls.clear()
        steps = []
        for k, (f, _) in enumerate(shots[:4]):
            prior = None
            if k:
                prior = np.eye(4)
                # forward along the camera's z by the distance travelled
                prior[2, 3] = travelled(shots[k - 1][1], shots[k][1])
            steps.append(vo.process(look(f.left), look(f.right), prior))
        # the first frame starts the keyframe; each later one is measured
        assert all(s.ok for s in steps[1:]) and len(calls) >= 4
        # keyframes' stereo matches on cfg.levels, the tracking on the prior's levels, all with the light's window
        assert calls[0] == (win, cfg.levels, True) and (win, levels, True) in calls[1:]
        assert set(calls) <= {(win, cfg.levels, True), (win, levels, True)}
    with pytest.raises(ValueError, match="dark_win_px and lit_win_px >= 5"):
        StereoVOConfig(dark_win_px=3)
    with pytest.raises(ValueError, match="lit_prior_levels >= 0"):
        StereoVOConfig(lit_prior_levels=-1)
