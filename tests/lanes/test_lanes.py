"""Lanes: analytic fit on synthetic evidence, evidence on a synthetic image, tracking in the simulator."""

import numpy as np
import pytest

from percept.lanes import (FitConfig, LaneDetector, LaneEstimate, LaneTracker, MarkingEvidence, MarkingExtractor,
                           fit_lane)
from percept.sensors import StereoRig


def synthetic_evidence(truth: LaneEstimate, rng, outliers: int = 0, dashed: bool = True) -> MarkingEvidence:
    x = np.arange(6.0, 50.0, 0.25)
    pts = []
    for side in (1, -1):
        keep = ((x % 12.0) < 3.0) if (dashed and side == 1) else np.ones_like(x, bool)
        xs = x[keep]
        pts.append(np.column_stack([xs, truth.boundary_y(xs, side) + rng.normal(0, 0.03, len(xs))]))
    if outliers:
        pts.append(np.column_stack([rng.uniform(6, 50, outliers), rng.uniform(-8, 8, outliers)]))
    p = np.concatenate(pts)
    return MarkingEvidence(p, np.full(len(p), 40.0), np.zeros((len(p), 2)))


@pytest.mark.parametrize("offset, heading, curvature", [(0.0, 0.0, 0.0), (0.4, -0.02, 0.004), (-0.6, 0.03, -0.006)])
def test_fit_recovers_a_known_lane(offset, heading, curvature):
    truth = LaneEstimate(offset, heading, curvature, 3.6, 1.0)
    rng = np.random.default_rng(0)
    fit = fit_lane(synthetic_evidence(truth, rng, outliers=60), prior=None)
    assert fit is not None
    e = fit.estimate
    assert e.offset_m == pytest.approx(offset, abs=0.03)
    assert e.heading_rad == pytest.approx(heading, abs=0.003)
    assert e.curvature_1pm == pytest.approx(curvature, abs=3e-4)
    assert e.width_m == pytest.approx(3.6, abs=0.05)
    assert fit.inliers_left > 20 and fit.inliers_right > 20


def test_fit_recovers_the_curvature_rate_of_a_clothoid():
    truth = LaneEstimate(0.3, 0.01, 0.002, 3.7, 1.0, curvature_rate_1pm2=1.2e-4)
    fit = fit_lane(synthetic_evidence(truth, np.random.default_rng(2), outliers=40), prior=None)
    assert fit is not None and fit.cov.shape == (5, 5)
    e = fit.estimate
    assert e.curvature_rate_1pm2 == pytest.approx(1.2e-4, abs=3e-5)
    assert e.curvature_1pm == pytest.approx(0.002, abs=3e-4)
    assert e.heading_rad == pytest.approx(0.01, abs=0.003)


def test_tracker_follows_curvature_along_a_spiral():
    """A car on the centre of a clothoid (curvature rising 6e-5 per metre): the Kalman filter's curvature rate
    state keeps the curvature within 1.5e-4 1/m of the truth, where a lag of 0.3 s would cost 4.5e-4."""
    tracker, rng = LaneTracker(), np.random.default_rng(3)
    v, dt, rate = 25.0, 1 / 15, 6e-5
    err = []
    for i in range(90):
        k = rate * v * dt * i
        truth = LaneEstimate(0.0, 0.0, k, 3.7, 1.0, curvature_rate_1pm2=rate)
        if tracker.initialised:
            # the car turns with the road under it: yaw rate = v k
            tracker.predict(v, v * k, dt)
        fit = fit_lane(synthetic_evidence(truth, rng), tracker.estimate if tracker.initialised else None)
        tracker.update(fit)
        if i >= 30:
            err.append(tracker.estimate.curvature_1pm - k)
    assert np.sqrt(np.mean(np.square(err))) < 1.5e-4
    assert tracker.estimate.curvature_rate_1pm2 == pytest.approx(rate, abs=2e-5)


def test_far_evidence_weighs_what_the_image_holds():
    """A grid row's weight: image rows it re-samples (flat ground: dv/dx = f h / x^2) times the lateral precision
    (f s / x)^2, each capped at 1."""
    rig = StereoRig()
    ex = MarkingExtractor(rig)
    w = ex.row_weight
    assert w[0] == pytest.approx(1.0) and np.all(np.diff(w) <= 1e-9)
    cam, cfg = rig.camera, ex.cfg
    for x in (20.0, 30.0, 45.0):
        rows = cam.fy * rig.mount_height_m / x ** 2 * cfg.dx_m
        expect = min(1, rows) * min(1, (cam.fx * cfg.full_weight_span_m / x) ** 2)
        assert w[np.argmin(np.abs(ex.x - x))] == pytest.approx(expect, rel=0.1)


def test_a_far_streak_does_not_bend_the_lane():
    """Rain streaks near the horizon become long slanted stripes in the bird's-eye view (one image row spans
    metres there): weighted by what the image holds, 60 such points at 38-50 m leave the near lane alone."""
    truth = LaneEstimate(0.0, 0.0, 0.0, 4.0, 1.0)
    rng = np.random.default_rng(4)
    ev = synthetic_evidence(truth, rng)
    near = ev.points_m[:, 0] < 25
    xs = np.linspace(38, 50, 60)
    streak = np.column_stack([xs, 2.0 + 0.06 * (xs - 38)])
    pts = np.concatenate([ev.points_m[near], streak])
    weight = np.array([MarkingExtractor(StereoRig()).row_weight[int(round((x - 6.0) / 0.25))] for x in pts[:, 0]])
    fits = {}
    for name, wt in (("weighted", weight), ("unweighted", None)):
        fits[name] = fit_lane(MarkingEvidence(pts, np.full(len(pts), 40.0), np.zeros((len(pts), 2)), wt), None)
    assert abs(fits["weighted"].estimate.heading_rad) < 0.006 and abs(fits["weighted"].estimate.offset_m) < 0.05
    # the same points counted alike pull the heading several times further off
    assert abs(fits["unweighted"].estimate.heading_rad) > 3 * abs(fits["weighted"].estimate.heading_rad)


def test_fit_with_one_side_only_uses_the_width_prior():
    truth = LaneEstimate(0.2, 0.0, 0.0, 3.7, 1.0)
    ev = synthetic_evidence(truth, np.random.default_rng(1))
    left_only = ev.points_m[:, 1] > 0
    ev1 = MarkingEvidence(ev.points_m[left_only], ev.strength[left_only], ev.uv_px[left_only])
    fit = fit_lane(ev1, prior=truth)
    assert fit is not None and fit.inliers_right == 0
    assert fit.estimate.offset_m == pytest.approx(0.2, abs=0.1)
    assert fit.estimate.confidence < 1.0


def test_too_little_evidence_gives_no_fit():
    ev = MarkingEvidence(np.zeros((3, 2)), np.ones(3), np.zeros((3, 2)))
    assert fit_lane(ev, None, FitConfig()) is None


def test_extractor_finds_painted_stripes_and_ignores_wide_bright_areas():
    rig = StereoRig()
    ex = MarkingExtractor(rig)
    img = np.full((480, 640, 3), 90, np.uint8)
    H = rig.ground_homography()
    def paint(y0, y1, x0=6.0, x1=40.0, val=230):
        quad = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float)
        p = np.column_stack([quad, np.ones(4)]) @ H.T
        import cv2
        cv2.fillPoly(img, [np.round(p[:, :2] / p[:, 2:]).astype(np.int32)], (val, val, val))
    paint(1.8, 1.95)  # a 15 cm marking 1.9 m to the left
    paint(-3.0, -5.0)  # a 2 m wide bright slab (a white car's side), not a marking
    ev = ex.extract(img)
    assert len(ev.points_m) > 50
    y = ev.points_m[:, 1]
    assert np.mean(np.abs(y - 1.875) < 0.15) > 0.9


def test_detector_rejects_a_wrong_image_size():
    det = LaneDetector(StereoRig())
    with pytest.raises(ValueError, match="the rig expects 640x480"):
        det.process(np.zeros((100, 100, 3), np.uint8))


def test_black_frame_and_dropped_frame_degrade_gracefully():
    det = LaneDetector(StereoRig())
    est, dbg = det.process(np.zeros((480, 640, 3), np.uint8), 20.0, 0.0)
    assert not est.valid and dbg.fit is None
    est, dbg = det.process(None, float("nan"), float("nan"))
    assert dbg.evidence is None and not est.valid


def test_slot_holds_the_last_plausible_wheel_speed_and_yaw_rate():
    from percept.lanes import LaneSlot
    from percept.sensors import Frame, ImuSample

    slot = LaneSlot(StereoRig(), 1 / 15)
    black = np.zeros((480, 640, 3), np.uint8)
    speeds, yaw_rates = [], []
    for i, (v, w) in enumerate([(20.0, 0.1), (float("nan"), float("nan")), (1e6, 40.0), (None, 0.0), (21.0, 0.0)]):
        path, _ = slot.step(Frame(i, i / 15, black, black, ImuSample(np.zeros(3), np.array([0, 0, w])), v), {})
        speeds.append(path.speed_mps)
        yaw_rates.append(slot.motion.last.yaw_rate_rps)
    # the ego path (what longitudinal and pedestrians read) never carries a bad sample, nor does the tracker's
    # prediction
    assert speeds == [20.0, 20.0, 20.0, 20.0, 21.0] and yaw_rates == [0.1, 0.1, 0.1, 0.0, 0.0]


@pytest.mark.slow
def test_tracking_on_the_simulated_highway():
    from percept.drive import TASKS, Agent, SlotContext, Source, TruthFeed
    from percept.sims import SimWorld, WorldConfig

    w = SimWorld(WorldConfig("highway", 1, scenery=False))
    det = LaneDetector(w.cfg.rig)
    feed = TruthFeed()
    agent = Agent(TASKS, {t.name: Source.PRIVILEGED for t in TASKS}, SlotContext(w.cfg.rig, w.dt, None, feed),
                  w.cruise_speed_mps)
    err = []
    for i in range(60):
        f, gt = w.observe()
        feed.truth = gt
        est, _ = det.process(f.left, f.wheel_speed_mps, f.imu.yaw_rate_rps, w.dt)
        if i >= 5:
            assert est.valid and est.confidence > 0.5
            err.append([est.offset_m - gt.lane.offset_m, est.heading_rad - gt.lane.heading_rad])
        # a gentle weave so that offset and heading are not trivially zero
        step = agent.step(f)
        w.step(step.accel_mps2, step.steering_rad + 0.01 * np.sin(i / 8))
    rmse = np.sqrt(np.mean(np.square(err), axis=0))
    assert rmse[0] < 0.05 and rmse[1] < 0.005


def _lines(ys: dict[float, int]) -> MarkingEvidence:
    """Straight markings along the road at lateral positions y [m], each with this many points over 6-40 m."""
    pts = np.concatenate([np.column_stack([np.linspace(6.0, 40.0, n), np.full(n, y)]) for y, n in ys.items()])
    return MarkingEvidence(pts, np.full(len(pts), 40.0), np.zeros((len(pts), 2)))


def test_two_equally_supported_lanes_about_the_car_halve_the_confidence():
    # a seam 0.6 m inside the right marking, as strong as it: two lanes (3.7 m and 3.1 m wide) about the car
    fit = fit_lane(_lines({1.85: 60, -1.85: 60, -1.25: 60}), None)
    assert fit.ambiguity == pytest.approx(0.5) and fit.estimate.confidence == pytest.approx(0.5)
    # the same seam, faint: the lane is clear
    fit = fit_lane(_lines({1.85: 60, -1.85: 60, -1.25: 8}), None)
    assert fit.ambiguity < 0.3 and fit.estimate.confidence > 0.7
    assert fit.estimate.width_m == pytest.approx(3.7, abs=0.05)
    # the neighbouring lanes' markings do not compete: they are not about the car
    fit = fit_lane(_lines({1.85: 60, -1.85: 60, 5.55: 60, -5.55: 60}), None)
    assert fit.ambiguity == 0.0 and fit.estimate.confidence == 1.0
