"""Per-frame rows of numbers kept compactly for scoring at the end of a run.

``Rows`` keeps the values as float64 in the standard library's ``array`` (8 bytes each, amortised growth) and
hands them to numpy at the end: a list of Python lists costs about 150 bytes a row of three floats, and a numpy
view kept per frame holds its whole base array, which over a long drive grows the process steadily.
"""

from __future__ import annotations

import sys
from array import array

import numpy as np


class Rows:
    """Rows of ``width`` float64 values, appended one per frame; ``values()`` is the (N, width) array."""

    def __init__(self, width: int):
        self.width = width
        self._data = array("d")

    def append(self, row) -> None:
        if len(row) != self.width:
            raise ValueError(f"a row of {len(row)} values where {self.width} are kept")
        self._data.extend(row)

    @property
    def nbytes(self) -> int:
        """Bytes the rows hold in memory, spare room included."""
        return sys.getsizeof(self._data)

    def __len__(self) -> int:
        return len(self._data) // self.width

    def values(self) -> np.ndarray:
        """The rows so far, (N, width) float64 (a copy: a view would stop the array from growing)."""
        return np.array(self._data, dtype=np.float64).reshape(-1, self.width)
