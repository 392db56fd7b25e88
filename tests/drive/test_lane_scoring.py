"""The lanes task's scoring: the lane estimate's offset error, and how a lane change's crossing is judged."""

from types import SimpleNamespace

import pytest

from percept.drive.scoring import LaneScorer, ScoreContext, StepTruth
from percept.sensors import EgoPath, LaneEstimate
from percept.sims.ground_truth import LaneTruth

W = 3.75
"""The true lane's width [m]."""


def _rmse(frames) -> float:
    """The offset RMSE of frames given as (estimated offset, true offset, the side of a change under way or None)."""
    s = LaneScorer(ScoreContext(True, 0, 0, 1.8))
    for est, true, side in frames:
        truth = SimpleNamespace(lane=LaneTruth(true, 0.0, 0.0, W, ("0", "1", 1)))
        path = EgoPath(LaneEstimate(est, 0.0, 0.0, W, 1.0), 25.0)
        s.update(path, None, StepTruth(truth, [], None, 0.0, 0.0, side))
    return s.result()["offset_rmse_m"]


def test_a_change_is_judged_against_the_lane_the_estimate_describes():
    # the car's centre crosses to the left: the estimate has moved to the new lane (it reads -1.80 m from that lane's
    # centre) a frame before the truth does (+1.90 m from the old one's, -1.85 m from the new one's): 0.05 m off
    crossing = [(0.0, 0.0, 1)] * 9 + [(-1.80, 1.90, 1)]
    assert _rmse(crossing) == pytest.approx(0.05 / 10 ** 0.5)


def test_outside_a_change_a_lane_mistaken_for_the_next_counts_in_full():
    assert _rmse([(0.0, 0.0, None)] * 9 + [(-1.80, 1.90, None)]) == pytest.approx(3.70 / 10 ** 0.5)
