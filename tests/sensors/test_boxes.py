"""The one-pair IoU equals the IoU matrix's entry bit for bit, and checks its boxes as the matrix does."""

import numpy as np
import pytest

from percept.sensors import iou, iou_matrix


def test_iou_of_one_pair_equals_the_matrix_bit_for_bit():
    rng = np.random.default_rng(5)
    for whole in (True, False):  # the finder's integer boxes, and fractional ones
        for _ in range(3000):
            c = rng.uniform(0, 60, 8) if not whole else rng.integers(0, 60, 8).astype(float)
            a = (min(c[0], c[1]), min(c[2], c[3]), max(c[0], c[1]), max(c[2], c[3]))
            b = (min(c[4], c[5]), min(c[6], c[7]), max(c[4], c[5]), max(c[6], c[7]))
            if whole:
                a, b = tuple(int(x) for x in a), tuple(int(x) for x in b)
            want = iou_matrix(np.array([a], float), np.array([b], float))[0, 0]
            for x, y in ((a, b), (list(a), np.array(b)), (np.array(a, np.float32), b)):
                if isinstance(x, np.ndarray) and x.dtype == np.float32 and not whole:
                    continue  # float32 rounds the coordinates themselves
                assert iou(x, y).hex() == float(want).hex()


def test_iou_checks_its_boxes():
    with pytest.raises(ValueError, match="u1 < u0"):
        iou((0, 10, 10, 0), (0, 0, 10, 10))
    with pytest.raises(ValueError, match="finite"):
        iou((0, 0, 10, 10), [0, 0, np.inf, 10])
    with pytest.raises(ValueError, match=r"shape \(K, 4\)"):
        iou(np.ones(3), (0, 0, 10, 10))
