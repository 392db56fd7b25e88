"""Cost a frame of pedestrian slot variants on the same frames, alternated in one process (one thread), as
``percept bench`` times a slot (``bench.stages.slot_ms``: the mean over consecutive frames from a reset): read the
ratios between variants; a busy machine moves every figure together.

    python tools/pedestrian_slot_ab.py [--frames 60] [--passes 3] [--by-level] VARIANT [VARIANT ...]

A variant is MODEL or MODEL:FAR_SWEEP_FRAMES (MODEL: sim, inria or a .npz file; the far field's levels searched
every FAR_SWEEP_FRAMES frames, by default as often as the slot's default). The frames are the first of `crossing`
seed 0 on highway-env's autopilot, with the true ego path. ``--by-level`` also times every scan of the search
(sweeps and the regions about tracks) and prints, per scale, the scans, the windows and the milliseconds a frame.
"""

from __future__ import annotations

import argparse
import time
from collections import Counter

import cv2
import numpy as np

from percept.bench.stages import slot_ms
from percept.detection import LinearModel, PedestrianSlot
from percept.detection.constrained import PERSON_PX, ConstrainedSearch
from percept.drive.loop import slot_context
from percept.drive.privileged import TruthFeed
from percept.drive.tasks import TASKS
from percept.sensors import EgoPath
from percept.sims import SimWorld, WorldConfig


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("variants", nargs="+", help="MODEL or MODEL:FAR_SWEEP_FRAMES")
    ap.add_argument("--frames", type=int, default=60)
    ap.add_argument("--passes", type=int, default=3)
    ap.add_argument("--by-level", action="store_true", help="also each scale's scans, windows and ms a frame")
    args = ap.parse_args()
    cv2.setNumThreads(1)
    variants = []
    for v in args.variants:
        name, _, far = v.partition(":")
        variants.append((v, LinearModel.named(name), {"far_sweep_frames": int(far)} if far else {}))
    world = SimWorld(WorldConfig("crossing", seed=0, autopilot=True))
    feed = TruthFeed()
    ctx = slot_context(world, feed)
    # the true ego path, from the privileged slot of the task that provides it: the pedestrian slot reads it
    path_slot = next(t for t in TASKS if t.provides is EgoPath).privileged(ctx)
    shots = []
    for _ in range(args.frames):
        frame, feed.truth = world.observe()
        shots.append((frame, {EgoPath: path_slot.step(frame, {})[0]}))
        world.step()
    ms = {v: [] for v, _, _ in variants}
    for _ in range(args.passes):
        for v, model, far in variants:
            ms[v].append(slot_ms(PedestrianSlot(world.cfg.rig, world.dt, model, **far), shots))
    base = float(np.median(ms[variants[0][0]]))
    for v, _, _ in variants:
        m = float(np.median(ms[v]))
        print(f"{v}: {m:.2f} ms a frame (passes {', '.join(f'{x:.2f}' for x in ms[v])}), {m / base:.2f}x the first")
    if args.by_level:
        for v, model, far in variants:
            by_level(v, PedestrianSlot(world.cfg.rig, world.dt, model, **far), shots, args.passes)


def by_level(name: str, slot: PedestrianSlot, shots: list, passes: int) -> None:
    """Each scale's scans, windows and ms a frame over ``passes`` passes of ``shots`` (after slot_ms's warm-up)."""
    ms, scans, windows = Counter(), Counter(), Counter()
    scan = ConstrainedSearch._scan

    def timed(self, image, level, region):
        t0 = time.perf_counter()
        out = scan(self, image, level, region)
        ms[level] += (time.perf_counter() - t0) * 1e3
        scans[level] += 1
        windows[level] += out[3]
        return out

    slot_ms(slot, shots, passes=1)
    ConstrainedSearch._scan = timed
    try:
        slot_ms(slot, shots, passes=passes)
    finally:
        ConstrainedSearch._scan = scan
    n = len(shots) * (passes + 1)  # slot_ms steps a warm-up pass and then the timed ones
    print(f"{name}, per scale (person px: scans a frame, windows a scan, ms a scan, ms a frame):")
    for k, p in enumerate(slot.periods):
        if scans[k]:
            print(f"  {PERSON_PX * slot.search.scales[k]:5.0f} px (every {p} frames): {scans[k] / n:.2f}, "
                  f"{windows[k] / scans[k]:.0f}, {ms[k] / scans[k]:.3f}, {ms[k] / n:.3f}")
    print(f"  every scan: {sum(ms.values()) / n:.3f} ms a frame")


if __name__ == "__main__":
    main()
