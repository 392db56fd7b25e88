"""HOG blocks computed once per image and scored for every window equal OpenCV's per-window descriptors; the
pyramid search finds what OpenCV's detectMultiScale finds (real video); models load, save and fail clearly; a
cascade's second stage scores windows as its own model does and keeps the detections one of whose windows it
passes."""

from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest

from percept.detection import DESCRIPTOR_LEN, LinearModel, block_grid, detect_multiscale, hog_descriptor
from percept.detection.pyramid import (Detection, _best_of_overlapping, group, lone_windows, pyramid_scales,
                                      second_stage_kept)
from percept.sensors import iou

VTEST = Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "opencv-samples" / "pedestrians" / "vtest.avi"


def textured(h=200, w=160, seed=0):
    rng = np.random.default_rng(seed)
    return cv2.GaussianBlur(rng.uniform(0, 255, (h, w, 3)).astype(np.uint8), (0, 0), 1.5)


def float32_sum_tolerance(model: LinearModel, blocks: np.ndarray) -> np.ndarray:
    """How far two float32 sums of a window's 3780 products w_i d_i may lie apart, per window: sqrt(n) float32
    epsilons of sum_i |w_i d_i|, the typical rounding of an n-term float32 sum in any order (Higham 2002, ch. 4);
    the order (BLAS kernel, SIMD width) differs by CPU."""
    magnitude = LinearModel(np.abs(model.weights), 0.0, "magnitude").score_map(np.abs(blocks))
    return np.sqrt(DESCRIPTOR_LEN) * np.finfo(np.float32).eps * magnitude


def test_every_window_scores_as_its_own_descriptor_would():
    img = textured()
    model = LinearModel.inria()
    blocks = block_grid(img)
    scores, tolerance = model.score_map(blocks), float32_sum_tolerance(model, blocks)
    # windows at 8-pixel steps: (160 - 64) / 8 + 1 across, (200 - 128) / 8 + 1 down
    assert scores.shape == (13, 10)
    locs = [(0, 0), (8, 16), (96, 72), (48, 40)]
    desc = hog_descriptor().compute(img, (8, 8), (0, 0), locs).reshape(len(locs), DESCRIPTOR_LEN)
    for (u, v), d in zip(locs, desc):
        want = float(d @ model.weights) + model.bias
        assert scores[u // 8, v // 8] == pytest.approx(want, abs=tolerance[u // 8, v // 8])


def test_the_window_scores_equal_the_sum_over_each_windows_blocks():
    """score_map's per-row products and compiled sums equal, to float32 rounding, b + sum_ij w_ij . B(x + i, y + j)
    computed in float64 window by window, for one window, strips a few windows tall and whole frames, and for
    blocks that are not contiguous."""
    rng = np.random.default_rng(4)
    model = LinearModel.inria()
    w = model.weights.astype(np.float64).reshape(7, 15, 36)
    for nbx, nby in ((7, 15), (8, 16), (139, 24), (40, 57)):
        blocks = rng.random((nbx, nby, 36), dtype=np.float32) * 0.2
        nx, ny = nbx - 6, nby - 14
        expected = np.array([[model.bias + np.einsum("ijk,ijk->", w, blocks[x:x + 7, y:y + 15].astype(np.float64))
                              for y in range(ny)] for x in range(nx)])
        got = model.score_map(blocks)
        assert got.dtype == np.float32 and got.shape == (nx, ny)
        assert (np.abs(got - expected) <= float32_sum_tolerance(model, blocks)).all()
        strided = np.zeros((nbx, nby, 72), np.float32)
        strided[:, :, ::2] = blocks
        # the same function on the same values (score_map copies strided blocks to contiguous ones): the same bits
        assert np.array_equal(model.score_map(strided[:, :, ::2]), got)


def test_pyramid_scales_stop_where_a_window_no_longer_fits():
    s = pyramid_scales(640, 480, 1.05)
    assert s[0] == 1.0 and s[1] == pytest.approx(1.05)
    assert round(480 / s[-1]) >= 128 and round(480 / (s[-1] * 1.05)) < 128
    with pytest.raises(ValueError, match="scale step must be > 1"):
        pyramid_scales(640, 480, 1.0)


def test_an_image_smaller_than_the_window_is_refused():
    with pytest.raises(ValueError, match="smaller than the 64x128 detection window"):
        detect_multiscale(np.zeros((100, 200, 3), np.uint8), LinearModel.inria())


def test_a_model_saves_and_loads_and_bad_files_say_so(tmp_path):
    m = LinearModel(np.linspace(-1, 1, DESCRIPTOR_LEN).astype(np.float32), -0.5, "test")
    m.save(tmp_path / "m.npz", trained_on="nothing")
    back = LinearModel.load(tmp_path / "m.npz")
    assert np.array_equal(back.weights, m.weights) and back.bias == -0.5  # saved and loaded as they are
    with pytest.raises(ValueError, match="does not exist"):
        LinearModel.load(tmp_path / "missing.npz")
    (tmp_path / "bad.npz").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="is not a percept HOG model"):
        LinearModel.load(tmp_path / "bad.npz")
    np.savez(tmp_path / "short.npz", weights=np.zeros(10), bias=0.0)
    with pytest.raises(ValueError, match="expected 3780 finite weights"):
        LinearModel.load(tmp_path / "short.npz")


@pytest.mark.skipif(not VTEST.is_file(), reason=f"{VTEST} is absent (real data in ../shared/data)")
@pytest.mark.slow
def test_the_pyramid_finds_what_opencv_detect_multiscale_finds_on_real_video():
    cap = cv2.VideoCapture(str(VTEST))
    hog = cv2.HOGDescriptor()
    hog.setSVMDetector(cv2.HOGDescriptor_getDefaultPeopleDetector())
    model, theirs_n, ours_n, theirs_hit, ours_hit = LinearModel.inria(), 0, 0, 0, 0
    for k in range(31):
        ok, frame = cap.read()
        if k % 10:
            continue
        ours = [d.box_px for d in detect_multiscale(frame, model)]
        rects, _ = hog.detectMultiScale(frame)
        theirs = [(x, y, x + w, y + h) for x, y, w, h in np.asarray(rects).reshape(-1, 4)]
        theirs_n, ours_n = theirs_n + len(theirs), ours_n + len(ours)
        theirs_hit += sum(any(iou(t, o) >= 0.5 for o in ours) for t in theirs)
        ours_hit += sum(any(iou(o, t) >= 0.5 for t in theirs) for o in ours)
    assert theirs_n >= 8
    assert theirs_hit >= 0.9 * theirs_n and ours_hit >= 0.9 * ours_n


def test_lone_windows_are_those_opencv_never_groups_with_another():
    rng = np.random.default_rng(3)
    xy = rng.integers(0, 120, (40, 2))
    wh = rng.choice([32, 36, 40, 64], 40)[:, None] * np.array([1, 2])
    boxes = np.column_stack([xy, wh]).astype(np.int32)
    lone = {d.box_px for d in lone_windows(boxes, np.arange(40, dtype=np.float32))}
    for i, b in enumerate(boxes.tolist()):
        # a pair groups (a cluster of 2 passes threshold 1) exactly when OpenCV finds the two windows similar
        paired = any(len(cv2.groupRectangles([b, o], 1, 0.2)[0]) for j, o in enumerate(boxes.tolist()) if j != i)
        assert ((b[0], b[1], b[0] + b[2], b[1] + b[3]) in lone) == (not paired)
    assert 0 < len(lone) < 40
    grouped = group(boxes, np.ones(40, np.float32), 1)
    assert all(d.windows >= 2 for d in grouped)


def test_the_second_stage_scores_each_window_as_its_own_model_would():
    """A cascade's second-stage score of a window equals the second model's ``score_map`` there."""
    blocks = block_grid(textured(seed=5), 4)
    first, second = LinearModel.inria(), LinearModel(np.linspace(-1, 1, DESCRIPTOR_LEN).astype(np.float32), 0.3, "b")
    cascade = replace(first, second=second, second_threshold=-0.5)
    assert first.second_scores(blocks, np.array([0]), np.array([0])) is None
    full = second.score_map(blocks)
    x, y = np.nonzero(np.ones_like(full, bool))
    got = cascade.second_scores(blocks, x, y)
    # a matrix-vector product per window against score_map's per-row products: float32 sums in another order
    assert got.dtype == np.float32 and (np.abs(got - full[x, y]) <= float32_sum_tolerance(second, blocks)[x, y]).all()
    # no window: an empty float32 array, as the product of no descriptors gives
    none = np.zeros(0, np.intp)
    empty = cascade.second_scores(blocks, none, none)
    assert empty.dtype == np.float32 and empty.shape == (0,)


def test_a_cascade_saves_and_loads_and_a_bad_second_stage_is_refused(tmp_path):
    a = LinearModel(np.linspace(-1, 1, DESCRIPTOR_LEN).astype(np.float32), -0.5, "a")
    b = LinearModel(np.linspace(1, -1, DESCRIPTOR_LEN).astype(np.float32), 0.25, "b")
    replace(a, second=b, second_threshold=-0.75).save(tmp_path / "c.npz")
    back = LinearModel.load(tmp_path / "c.npz")
    assert np.array_equal(back.weights, a.weights) and back.bias == -0.5
    assert np.array_equal(back.second.weights, b.weights) and back.second.bias == 0.25
    assert back.second_threshold == -0.75 and back.second.second is None
    assert LinearModel.load(tmp_path / "c.npz").second is not None and LinearModel.inria().second is None
    with pytest.raises(ValueError, match="a second stage must be a single linear model"):
        replace(a, second=replace(a, second=b))
    with pytest.raises(ValueError, match="with a finite threshold"):
        replace(a, second=b, second_threshold=float("nan"))


def test_the_second_stage_keeps_a_detection_when_one_of_its_windows_passes():
    """A detection is kept when a window overlapping it (IoU >= 0.5) passes the second stage, whichever; a cluster
    whose windows all fail it is dropped; without a second stage every detection stays."""
    boxes = np.array([[10, 10, 64, 128], [14, 12, 64, 128], [200, 10, 64, 128], [204, 14, 64, 128]], np.int32)
    dets = group(boxes, np.array([1.0, 0.5, 0.8, 0.9], np.float32), 1)
    assert len(dets) == 2
    kept = second_stage_kept(dets, boxes, np.array([-2.0, -0.1, -0.9, -0.6], np.float32), -0.5)
    assert [d.box_px[0] < 100 for d in kept] == [True]
    assert second_stage_kept(dets, boxes, None, -0.5) == dets
    assert second_stage_kept(dets, boxes, np.full(4, -0.5, np.float32), -0.5) == dets


def numpy_ious(box, boxes) -> np.ndarray:
    """The IoU of ``box`` with each of ``boxes`` as ``_best_of_overlapping`` computed them in numpy."""
    gx, gy, gw, gh = box
    ix = np.clip(np.minimum(gx + gw, boxes[:, 0] + boxes[:, 2]) - np.maximum(gx, boxes[:, 0]), 0, None)
    iy = np.clip(np.minimum(gy + gh, boxes[:, 1] + boxes[:, 3]) - np.maximum(gy, boxes[:, 1]), 0, None)
    inter = ix * iy
    return inter / (gw * gh + boxes[:, 2] * boxes[:, 3] - inter)


def numpy_best_of_overlapping(box, boxes, values) -> float:
    """``_best_of_overlapping`` as numpy computed it before its compiled pass."""
    iou = numpy_ious(box, boxes)
    return float(values[iou >= 0.5].max()) if (iou >= 0.5).any() else float(values.max())


def numpy_lone_windows(boxes, scores, eps=0.2) -> list:
    """``lone_windows`` as numpy computed it before its compiled pass."""
    b = boxes.astype(np.float64)
    delta = eps * (np.minimum(b[:, None, 2], b[None, :, 2]) + np.minimum(b[:, None, 3], b[None, :, 3])) / 2
    x1, y1 = b[:, 0] + b[:, 2], b[:, 1] + b[:, 3]
    similar = ((np.abs(b[:, None, 0] - b[None, :, 0]) <= delta) & (np.abs(b[:, None, 1] - b[None, :, 1]) <= delta)
               & (np.abs(x1[:, None] - x1[None, :]) <= delta) & (np.abs(y1[:, None] - y1[None, :]) <= delta))
    lone = np.flatnonzero(similar.sum(axis=1) == 1)
    out = [Detection((float(b[i, 0]), float(b[i, 1]), float(x1[i]), float(y1[i])), float(scores[i])) for i in lone]
    return sorted(out, key=lambda d: -d.score)


def random_windows(rng, n: int) -> np.ndarray:
    """n windows (x, y, w, h) in int32 of a few sizes, crowded enough that some overlap and some group."""
    w = rng.choice([24, 32, 40, 64], n)
    return np.column_stack([rng.integers(0, 200, n), rng.integers(0, 120, n), w, 2 * w]).astype(np.int32)


def test_the_compiled_overlaps_and_lone_windows_equal_numpys():
    """The compiled ``_best_of_overlapping`` (integer boxes as ``group`` passes them, float boxes as
    ``second_stage_kept`` does) and ``lone_windows`` give what the numpy code they replace gave, bit for bit."""
    rng = np.random.default_rng(11)
    overlapped = alone = lone = 0
    for trial in range(300):
        boxes = random_windows(rng, int(rng.integers(1, 30)))
        values = rng.normal(0, 1, len(boxes)).astype(np.float32)
        if trial % 50 == 7:
            values[rng.integers(0, len(values))] = np.nan
        gw = int(rng.choice([24, 32, 48]))
        gx, gy = rng.integers(0, 200, 2).astype(np.int32)
        for box in [(gx, gy, np.int32(gw), np.int32(2 * gw)), (float(gx) + 0.5, float(gy) - 0.25, gw * 1.1, 2.2 * gw)]:
            want = numpy_best_of_overlapping(box, boxes, values)
            got = _best_of_overlapping(box, boxes, values)
            assert np.asarray(got).tobytes() == np.asarray(want).tobytes()
            near = bool((numpy_ious(box, boxes) >= 0.5).any())
            overlapped, alone = overlapped + near, alone + (not near)
        got, want = lone_windows(boxes, values), numpy_lone_windows(boxes, values)
        assert [(d.box_px, np.float64(d.score).tobytes(), d.windows) for d in got] == \
            [(d.box_px, np.float64(d.score).tobytes(), d.windows) for d in want]
        lone += len(got)
    # both cases of the overlap (a window at IoU >= 0.5, none) and lone windows came up
    assert overlapped > 20 and alone > 20 and lone > 100
