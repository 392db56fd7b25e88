"""The contact search's compiled edge against numpy's formulas: the same row and step, bit for bit."""

import numpy as np

from percept.longitudinal.contact import _tyre_edge


def _numpy_edge(strip, u0, u1, k):
    cols = np.concatenate([strip[:, u0:u0 + k], strip[:, u1 - k:u1]], axis=1).astype(np.float32)
    step = np.diff(cols.mean(axis=1))
    i = int(np.argmax(step))
    return i, step[i]


def test_tyre_edge_equals_numpys():
    rng = np.random.default_rng(6)
    for _ in range(2000):
        rows, w = int(rng.integers(3, 40)), int(rng.integers(8, 200))
        strip = rng.integers(0, 256, (rows, w)).astype(np.uint8)
        if rng.random() < 0.3:
            strip //= 64  # few grey levels: ties between steps
        u0 = int(rng.integers(0, w - 4))
        u1 = int(rng.integers(u0 + 4, w + 1))
        k = max(int(round((u1 - u0) * rng.uniform(0.05, 0.45))), 1)
        want_i, want = _numpy_edge(strip, u0, u1, k)
        (a0, a1, _), (b0, b1, _) = slice(u0, u0 + k).indices(w), slice(u1 - k, u1).indices(w)
        i, step = _tyre_edge(strip, a0, a1, b0, b1)
        assert i == want_i and np.float32(step).tobytes() == want.tobytes()
