import cv2
import numpy as np
import pytest

from percept.sensors import Frame, ImuSample, to_gray


def _frame(left, right) -> Frame:
    return Frame(3, 0.1, left, right, ImuSample(np.zeros(3), np.zeros(3)), 10.0)


def test_a_frame_converts_each_image_to_grey_once_and_shares_it_read_only():
    rng = np.random.default_rng(0)
    left, right = (rng.integers(0, 256, (48, 64, 3), dtype=np.uint8) for _ in range(2))
    f = _frame(left, right)
    assert np.array_equal(f.left_gray, cv2.cvtColor(left, cv2.COLOR_BGR2GRAY))
    assert np.array_equal(f.right_gray, cv2.cvtColor(right, cv2.COLOR_BGR2GRAY))
    # the same array for every slot that asks, and none may write into what the others read
    assert f.left_gray is f.left_gray and f.right_gray is f.right_gray
    with pytest.raises(ValueError, match="read-only"):
        f.left_gray[0, 0] = 1
    # the frame's own images stay as they were
    assert left.flags.writeable and right.flags.writeable


def test_a_grey_frame_is_shared_as_it_is_and_a_dropped_one_has_no_grey():
    grey = np.full((8, 8), 7, np.uint8)
    f = _frame(grey, grey)
    assert np.shares_memory(f.left_gray, grey) and not f.left_gray.flags.writeable and grey.flags.writeable
    dropped = _frame(None, None)
    assert dropped.left_gray is None and dropped.right_gray is None


def test_to_gray_takes_grey_or_bgr_and_says_what_else_it_got():
    assert to_gray(np.full((2, 2), 300.0)).tolist() == [[255, 255], [255, 255]]
    with pytest.raises(ValueError, match=r"expected an \(H, W\) or \(H, W, 3\) image, got shape \(2, 2, 4\)"):
        to_gray(np.zeros((2, 2, 4), np.uint8))


def test_the_right_image_is_lent_in_grey_once_converted_and_in_colour_before():
    rng = np.random.default_rng(1)
    left, right = (rng.integers(0, 256, (8, 12, 3), dtype=np.uint8) for _ in range(2))
    f = _frame(left, right)
    # nobody converted it yet: the colour image, not a conversion made for one reader each frame
    assert f.right_gray_or_bgr() is right
    grey = f.right_gray
    assert f.right_gray_or_bgr() is grey
    assert _frame(None, None).right_gray_or_bgr() is None
