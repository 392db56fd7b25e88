"""Both rigs on rendered `overtake` frames: cars behind are found by the rear rig, and the car that comes up from
behind and paces the ego in the blind band stays tracked while neither rig sees it (the lane from truth, so that only
the neighbours are under test)."""

import numpy as np
import pytest

from percept.drive.neighbours_scoring import match_tracks
from percept.drive.neighbours_truth import truth_neighbours
from percept.neighbours import NeighbourSlot
from percept.sensors import EgoPath, StereoRig, Zone, rear_rig
from percept.sims.world import SimWorld, WorldConfig


@pytest.mark.slow
def test_cars_behind_and_beside_are_tracked(path_from_truth):
    w = SimWorld(WorldConfig("overtake", 1, autopilot=True, rear_rig=rear_rig(StereoRig())))
    slot = NeighbourSlot(w.cfg.rig, w.cfg.rear_rig, w.dt)
    behind, beside, seen = [], [], set()
    for step in range(330):
        w.step()
        frame, gt = w.observe()
        nb, _ = slot.step(frame, {EgoPath: path_from_truth(gt)})
        truth = truth_neighbours(gt).tracks
        seen.update(n.track_id for n in truth if n.camera is not None)
        found = {j for _, j in match_tracks(nb.tracks, truth, gt.lane.width_m)}
        for j, n in enumerate(truth):
            if n.zone is Zone.BEHIND and n.camera == "rear" and n.gap_m <= 60 and step >= 15:
                behind.append(j in found)
            if n.zone is Zone.BESIDE and n.lane != 0 and n.track_id in seen:
                beside.append(j in found)
    assert len(behind) > 100 and np.mean(behind) >= 0.9
    # the pacing car: beside for seconds, never reported absent
    assert len(beside) > 45 and all(beside)
