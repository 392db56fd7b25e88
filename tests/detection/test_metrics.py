"""IoU, greedy matching with ignore regions, and detection rates on hand-made frames."""

import numpy as np
import pytest

from percept.detection import FrameMatch, eligible, iou, iou_matrix, match_detections, score_frames

PERSON = (100.0, 50.0, 120.0, 100.0)  # 20 x 50 px


def test_iou_of_known_boxes():
    assert iou((0, 0, 10, 10), (0, 0, 10, 10)) == pytest.approx(1.0)
    # half of each overlaps: 50 / (100 + 100 - 50)
    assert iou((0, 0, 10, 10), (5, 0, 15, 10)) == pytest.approx(1 / 3)
    # one inside the other, half its area: 50 / 100
    assert iou((0, 0, 10, 10), (0, 0, 10, 5)) == pytest.approx(0.5)
    # quarter corner overlap: 25 / (100 + 100 - 25)
    assert iou((0, 0, 10, 10), (5, 5, 15, 15)) == pytest.approx(25 / 175)
    assert iou((0, 0, 10, 10), (20, 20, 30, 30)) == 0.0
    assert iou((0, 0, 10, 10), (10, 0, 20, 10)) == 0.0  # touching edges
    assert iou((5, 5, 5, 5), (5, 5, 5, 5)) == 0.0  # zero area


def test_iou_matrix_matches_pairwise_iou():
    a = np.array([[0, 0, 10, 10], [5, 5, 15, 15]], dtype=float)
    b = np.array([[0, 0, 10, 10], [5, 0, 15, 10], [40, 40, 50, 60]], dtype=float)
    m = iou_matrix(a, b)
    assert m.shape == (2, 3)
    for i in range(2):
        for j in range(3):
            assert m[i, j] == pytest.approx(iou(a[i], b[j]))
    assert iou_matrix(np.zeros((0, 4)), b).shape == (0, 3)
    assert iou_matrix(a, []).shape == (2, 0)


def test_bad_boxes_raise():
    with pytest.raises(ValueError, match="u1 < u0"):
        iou((10, 0, 0, 10), (0, 0, 10, 10))
    with pytest.raises(ValueError, match=r"shape \(K, 4\)"):
        iou_matrix(np.ones((2, 3)), np.ones((1, 4)))
    with pytest.raises(ValueError, match="finite"):
        iou((0, 0, np.nan, 10), (0, 0, 10, 10))


def test_eligible_follows_design_rule():
    assert eligible((0, 0, 10, 24), visible=0.5)
    assert not eligible((0, 0, 10, 23.9), visible=1.0)
    assert not eligible((0, 0, 10, 100), visible=0.49)
    assert eligible((0, 0, 10, 20), visible=0.3, min_height_px=20, min_visible=0.3)
    with pytest.raises(ValueError, match="visible"):
        eligible((0, 0, 10, 30), visible=1.5)


def test_two_detections_on_one_person_higher_score_wins():
    shifted = (104.0, 50.0, 124.0, 100.0)  # IoU 16*50 / (2000 - 800) = 2/3
    dets = np.array([PERSON, shifted])
    m = match_detections(dets, [0.6, 0.9], np.array([PERSON]), [True])
    # greedy by score: the shifted (0.9) box takes the person although the exact one overlaps more
    assert (m.tp, m.fp, m.fn, m.ignored) == (1, 1, 0, 0)
    assert m.pairs == ((1, 0),)


def test_below_iou_threshold_is_a_false_positive_and_a_miss():
    far_shift = (112.0, 50.0, 132.0, 100.0)  # IoU 8 / 32 = 0.25
    m = match_detections(np.array([far_shift]), [1.0], np.array([PERSON]), [True])
    assert (m.tp, m.fp, m.fn) == (0, 1, 1)
    assert match_detections(np.array([far_shift]), [1.0], np.array([PERSON]), [True], iou_min=0.25).tp == 1


def test_ignore_box_absorbs_detections_and_is_never_a_miss():
    small = (300.0, 60.0, 308.0, 76.0)  # 16 px tall: not eligible
    gt = np.array([PERSON, small])
    dets = np.array([small, (300.0, 60.0, 308.0, 75.0)])
    m = match_detections(dets, [0.9, 0.8], gt, [True, False])
    assert (m.tp, m.fp, m.fn, m.ignored) == (0, 0, 1, 2)
    assert match_detections(np.zeros((0, 4)), [], np.array([small]), [False]) == FrameMatch(0, 0, 0)


def test_best_match_decides_between_eligible_and_ignore():
    near = (100.0, 50.0, 120.0, 90.0)  # ignore box inside the person
    gt = np.array([PERSON, near])
    on_ignore = match_detections(np.array([near]), [1.0], gt, [True, False])
    assert (on_ignore.tp, on_ignore.fp, on_ignore.fn, on_ignore.ignored) == (0, 0, 1, 1)
    on_person = match_detections(np.array([PERSON]), [1.0], gt, [True, False])
    assert (on_person.tp, on_person.fp, on_person.fn, on_person.ignored) == (1, 0, 0, 0)
    # a tie goes to the eligible box
    tie = match_detections(np.array([PERSON]), [1.0], np.array([PERSON, PERSON]), [False, True])
    assert tie.pairs == ((0, 1),)


def test_an_eligible_box_is_matched_at_most_once_then_the_ignore_box_takes_over():
    gt = np.array([PERSON, PERSON])
    m = match_detections(np.array([PERSON, PERSON, PERSON]), [0.3, 0.2, 0.1], gt, [True, False])
    assert (m.tp, m.fp, m.fn, m.ignored) == (1, 0, 0, 2)


def test_mismatched_scores_and_flags_raise():
    with pytest.raises(ValueError, match="scores"):
        match_detections(np.array([PERSON]), [0.5, 0.4], np.array([PERSON]), [True])
    with pytest.raises(ValueError, match="eligibility"):
        match_detections(np.array([PERSON]), [0.5], np.array([PERSON]), [True, False])
    with pytest.raises(ValueError, match="finite"):
        match_detections(np.array([PERSON]), [np.nan], np.array([PERSON]), [True])


def test_rates_over_a_hand_made_sequence():
    other = (200.0, 50.0, 220.0, 100.0)
    frames = [
        match_detections(np.array([PERSON, (400, 0, 420, 50)]), [0.9, 0.5], np.array([PERSON]), [True]),
        match_detections(np.zeros((0, 4)), [], np.array([PERSON]), [True]),
        match_detections(np.array([other]), [0.7], np.array([PERSON, other]), [True, True]),
    ]
    assert [(f.tp, f.fp, f.fn) for f in frames] == [(1, 1, 0), (0, 0, 1), (1, 0, 1)]
    s = score_frames(frames)
    assert s["recall"] == pytest.approx(2 / 4)
    assert s["precision"] == pytest.approx(2 / 3)
    assert s["fppi"] == pytest.approx(1 / 3)
    assert (s["tp"], s["fp"], s["fn"], s["frames"]) == (2, 1, 2, 3)


def test_rates_without_denominator_are_none():
    assert score_frames([]) == {"recall": None, "precision": None, "fppi": None,
                                "tp": 0, "fp": 0, "fn": 0, "frames": 0}
    empty = score_frames([FrameMatch(0, 0, 0), FrameMatch(0, 0, 0, ignored=1)])
    assert (empty["recall"], empty["precision"], empty["fppi"]) == (None, None, 0.0)
