"""Points on the ground bucketed in square cells, so that a frame looks only at those near the car: the scenery
of a long road is thousands of patches, of which a frame's view cone holds a few hundred."""

from __future__ import annotations

import math

import numpy as np


class GroundGrid:
    """World points ``xy`` (N, 2) [m] in square cells of ``cell_m`` [m]. ``within(x0, y0, x1, y1)``: the indices,
    ascending, of every point in the cells that meet the box [x0, x1] x [y0, y1] [m] (all the points inside it, and
    some beside it)."""

    def __init__(self, xy: np.ndarray, cell_m: float):
        if not cell_m > 0:
            raise ValueError(f"cell_m must be > 0, got {cell_m}")
        xy = np.asarray(xy, float).reshape(-1, 2)
        self.cell_m = float(cell_m)
        cells = np.floor(xy / self.cell_m).astype(np.int64)
        # one key per cell, the points sorted by it (stable: ascending indices within a cell)
        self._lo = cells.min(axis=0) if len(xy) else np.zeros(2, np.int64)
        self._shape = (cells.max(axis=0) - self._lo + 1) if len(xy) else np.zeros(2, np.int64)
        key = (cells[:, 0] - self._lo[0]) * self._shape[1] + (cells[:, 1] - self._lo[1])
        self._order = np.argsort(key, kind="stable")
        self._starts = np.searchsorted(key[self._order], np.arange(int(np.prod(self._shape)) + 1))

    def within(self, x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
        if not all(math.isfinite(c) for c in (x0, y0, x1, y1)):
            return np.arange(len(self._order))
        nx, ny = (int(n) for n in self._shape)
        if not len(self._order):
            return self._order
        i0 = max(math.floor(x0 / self.cell_m) - int(self._lo[0]), 0)
        i1 = min(math.floor(x1 / self.cell_m) - int(self._lo[0]), nx - 1)
        j0 = max(math.floor(y0 / self.cell_m) - int(self._lo[1]), 0)
        j1 = min(math.floor(y1 / self.cell_m) - int(self._lo[1]), ny - 1)
        if i0 > i1 or j0 > j1:
            return self._order[:0]
        # the cells of one column i are contiguous keys i ny + j0 .. i ny + j1
        parts = [self._order[self._starts[i * ny + j0]:self._starts[i * ny + j1 + 1]] for i in range(i0, i1 + 1)]
        return np.sort(np.concatenate(parts))
