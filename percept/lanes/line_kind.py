"""Broken or solid: what a lane boundary's paint says about the lane beyond it.

A broken line separates two lanes of the same direction; a solid one is the road's edge (or a line not to be
crossed). On a broken line the paint stops and starts again along the near range (US interstates: 3 m dashes, 9 m
gaps, MUTCD 3A.06); on a solid one it runs on without a gap until something hides it, and a car that hides it
truncates it rather than cutting a gap in it. So the test is the longest gap between painted stretches inside the
range where the line was seen at all, not the share of the range painted.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LineKindConfig:
    """Where along the lane, and how finely, a boundary's paint is looked at."""

    x_near_m: float = 6.0  # nearest range looked at [m]
    x_far_m: float = 35.0  # farthest (beyond it the rendered dashes fade into their period's mean) [m]
    bin_m: float = 0.5  # along-lane bins a painted point marks [m]
    min_gap_m: float = 4.0  # an interior gap this long makes the line broken [m]
    min_span_m: float = 10.0  # a line with no such gap is solid once seen over this length [m]


def line_kind(x_m: np.ndarray, cfg: LineKindConfig = LineKindConfig()) -> bool | None:
    """Whether the boundary whose painted points lie at ranges ``x_m`` (N,) [m] is broken (True), solid (False) or
    not known (None: seen over less than ``min_span_m`` without a gap)."""
    x = np.asarray(x_m, float)
    x = x[(x >= cfg.x_near_m) & (x <= cfg.x_far_m)]
    if len(x) == 0:
        return None
    painted = np.unique(np.floor((x - cfg.x_near_m) / cfg.bin_m).astype(int))
    # an interior gap: the empty bins between two painted ones, times the bin length
    gaps = (np.diff(painted) - 1) * cfg.bin_m
    if len(gaps) and gaps.max() >= cfg.min_gap_m:
        return True
    return False if (painted[-1] - painted[0] + 1) * cfg.bin_m >= cfg.min_span_m else None
