"""Cost a frame of pedestrian slot variants on the same frames, alternated in one process (one thread), as
``percept bench`` times a slot (``drive.bench.slot_ms``: the mean over consecutive frames from a reset): read the
ratios between variants; a busy machine moves every figure together.

    python tools/pedestrian_slot_ab.py [--frames 60] [--passes 3] VARIANT [VARIANT ...]

A variant is MODEL or MODEL:FAR_SWEEP_FRAMES (MODEL: sim, inria or a .npz file; the far field's levels searched
every FAR_SWEEP_FRAMES frames, 6 by default as the slot's other levels). The frames are the first of `crossing`
seed 0 on highway-env's autopilot, with the true ego path.
"""

from __future__ import annotations

import argparse

import cv2
import numpy as np

from percept.detection import LinearModel, PedestrianSlot
from percept.drive.bench import slot_ms
from percept.drive.privileged import TruthFeed
from percept.drive.tasks import TASKS, SlotContext
from percept.sims import SimWorld, WorldConfig
from percept.sims.coords import hw_pose


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("variants", nargs="+", help="MODEL or MODEL:FAR_SWEEP_FRAMES")
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--passes", type=int, default=3)
    args = ap.parse_args()
    cv2.setNumThreads(1)
    variants = []
    for v in args.variants:
        name, _, far = v.partition(":")
        variants.append((v, LinearModel.named(name), int(far or 6)))
    world = SimWorld(WorldConfig("crossing", seed=0, autopilot=True))
    feed = TruthFeed()
    lm = world.landmark_map()
    ctx = SlotContext(world.cfg.rig, world.dt, lm if len(lm) else None, feed, start_pose=hw_pose(world.ego))
    lateral = {t.name: t for t in TASKS}["lateral"].privileged(ctx)
    shots = []
    for _ in range(args.frames):
        frame, feed.truth = world.observe()
        shots.append((frame, {"lateral": lateral.step(frame, {})[0]}))
        world.step()
    ms = {v: [] for v, _, _ in variants}
    for _ in range(args.passes):
        for v, model, far in variants:
            ms[v].append(slot_ms(PedestrianSlot(world.cfg.rig, world.dt, model, far_sweep_frames=far), shots))
    base = float(np.median(ms[variants[0][0]]))
    for v, _, _ in variants:
        m = float(np.median(ms[v]))
        print(f"{v}: {m:.2f} ms a frame (passes {', '.join(f'{x:.2f}' for x in ms[v])}), {m / base:.2f}x the first")


if __name__ == "__main__":
    main()
