"""The rear rig in a drive: its slots get the rear rig and the rear pair of each frame."""

from dataclasses import dataclass

from percept.drive import TASKS, DriveConfig, Task, run_drive
from percept.sims import WorldConfig


@dataclass(frozen=True)
class RearSeen:
    """The test task's record: whether its slot had the rear rig and this frame's rear pair."""

    rig: bool
    pair: bool


class RearSlot:
    def __init__(self, ctx):
        self.rig = ctx.rear_rig

    def reset(self) -> None:
        pass

    def step(self, frame, upstream):
        ok = frame.has_rear and frame.rear_left.shape == frame.left.shape
        return RearSeen(self.rig is not None and self.rig.looks_back, ok), None


class RearScorer:
    def __init__(self, ctx):
        self.seen = []

    def update(self, estimate, debug, step):
        self.seen.append(estimate)

    def result(self):
        return {"rig": all(s.rig for s in self.seen), "pair": all(s.pair for s in self.seen),
                "frames": len(self.seen)}


REAR_TASK = Task("rearview", RearSeen, RearSlot, RearScorer, vision=RearSlot, help="looks back")


def test_a_vision_slot_gets_the_rear_rig_and_every_frames_rear_pair():
    tasks = TASKS + (REAR_TASK,)
    cfg = DriveConfig(WorldConfig("highway", 0, scenery=False), 0.4, {"rearview": "vision"}, tasks=tasks,
                      default="privileged", rear=True)
    r = run_drive(cfg)
    assert r["rearview"] == {"rig": True, "pair": True, "frames": 6} and r["rear"] is True
    off = run_drive(DriveConfig(cfg.world, 0.2, {"rearview": "vision"}, tasks=tasks, default="privileged",
                                rear=False))
    assert off["rearview"] == {"rig": False, "pair": False, "frames": 3} and off["rear"] is False
