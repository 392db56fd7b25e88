"""The vision slot on rendered highway frames, against the simulator's truth (the lane from truth, so that only the
neighbours are under test)."""

import numpy as np
import pytest

from percept.neighbours import NeighbourSlot
from percept.sensors import EgoPath
from percept.sims.world import SimWorld, WorldConfig


@pytest.mark.slow
def test_vehicles_ahead_are_found_ranged_and_put_in_their_lanes(path_from_truth):
    w = SimWorld(WorldConfig("highway", 1, autopilot=True))
    slot = NeighbourSlot(w.cfg.rig, None, w.dt)
    found, gap_err, lanes = [], [], []
    for step in range(150):
        w.step()
        frame, gt = w.observe()
        lt = gt.lane
        nb, _ = slot.step(frame, {EgoPath: path_from_truth(gt)})
        if step < 15:  # tracks are confirmed after a few frames
            continue
        for o in gt.objects:
            x, y = o.position_m[:2]
            lane = round(y / lt.width_m)
            gap = x - 5.0
            if 3 < gap < 60 and abs(lane) <= 1 and o.visible >= 0.5:
                m = [n for n in nb.tracks if abs(n.x_m - x) < 4 and abs(n.lane * lt.width_m + n.lateral_m - y) < 1.8]
                found.append(bool(m))
                if m:
                    lanes.append(m[0].lane == lane)
                    if gap < 40:
                        gap_err.append(abs(m[0].gap_m - gap) / gap)
    assert len(found) > 100
    assert np.mean(found) >= 0.9
    assert np.mean(lanes) == 1.0
    assert np.median(gap_err) <= 0.02
