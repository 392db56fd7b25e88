"""TuSimple's lane format: per image, each lane's x at fixed rows (``h_samples``), -2 where the lane is absent.

The benchmark's prediction file has one JSON object per line: {"raw_file": ..., "lanes": [[x, ...], ...],
"h_samples": [...], "run_time": ms}; its 1280x720 frames are sampled at rows 160, 170, ..., 710, and a point is
right when it lies within 20 px of the labelled lane at that row (TuSimple lane detection challenge, 2017;
https://github.com/TuSimple/tusimple-benchmark). percept reports the ego lane's two boundaries, left then right.
"""

from __future__ import annotations

import numpy as np

TUSIMPLE_HEIGHT_PX = 720
TUSIMPLE_ROWS_PX = tuple(range(160, 720, 10))
ABSENT = -2


def h_samples(height_px: int) -> list[int]:
    """TuSimple's rows for an image ``height_px`` tall: its own for 720 rows, scaled for other heights."""
    if height_px == TUSIMPLE_HEIGHT_PX:
        return list(TUSIMPLE_ROWS_PX)
    return [int(round(v * height_px / TUSIMPLE_HEIGHT_PX)) for v in TUSIMPLE_ROWS_PX]


def tusimple_record(result, raw_file: str, height_px: int, width_px: int, run_time_ms: float) -> dict:
    """One image's line of a TuSimple prediction file from a ``LaneResult``: both ego boundaries (left, right) at
    ``h_samples``, ABSENT outside each boundary's drawn range or the image."""
    rows = h_samples(height_px)
    lanes = []
    for name, u in result.u_at_rows(np.asarray(rows, float)).items():
        ok = np.isfinite(u) & (u >= 0) & (u <= width_px - 1)
        lanes.append([int(round(x)) if k else ABSENT for x, k in zip(u, ok)])
    return {"raw_file": raw_file, "lanes": lanes, "h_samples": rows, "run_time": round(float(run_time_ms), 1)}
