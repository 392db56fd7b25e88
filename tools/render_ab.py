"""The renderer of another checkout against this one, in one process: the same frames, and their CPU time.

Two timing runs one after the other compare the machine's speed at two moments as much as the code. Here the other
checkout's ``percept/sims`` is loaded beside this one (as the package ``othersims``), both renderers are built for
the same world, and each frame is rendered by one and then by the other, so that a drift falls on both. Every tenth
frame's images, depth, ids and boxes must be identical (the renderer's optimisations keep the pictures bit for bit;
exit 1 when they do not).

usage: python tools/render_ab.py OTHER_CHECKOUT [SCENARIO ...]   (default: highway crossing loop curves)
       e.g. git worktree add /tmp/base HEAD~3 && python tools/render_ab.py /tmp/base
Prints per scenario the CPU ms per stereo pair (60 frames, seed 0; the best of REPS passes, default 5, of each
pass's sum) of the other checkout and of this one, and the ratio of their totals.
"""
import dataclasses
import importlib
import os
import sys
import time
import types
from pathlib import Path

import cv2
import numpy as np

from percept.sims import SimWorld, WorldConfig
from percept.sims.snapshot import scene_from_road

cv2.setNumThreads(1)
FRAMES = 60


def other_render(checkout: Path):
    """The other checkout's ``sims.render`` package, loaded as ``othersims.render``."""
    sims = checkout / "percept" / "sims"
    if not (sims / "render" / "renderer.py").is_file():
        sys.exit(f"{checkout} is not a percept checkout (no percept/sims/render/renderer.py)")
    # numba caches a kernel beside its source under its module's name: cached as ``othersims``, the other
    # checkout's kernels would not load when it runs as ``percept`` ("No module named 'othersims'"), so its
    # kernels are compiled here without the disk cache
    from numba.core.dispatcher import Dispatcher

    enable = Dispatcher.enable_caching
    Dispatcher.enable_caching = lambda d: None if d.py_func.__module__.startswith("othersims") else enable(d)
    pkg = types.ModuleType("othersims")
    pkg.__path__ = [str(sims)]
    sys.modules["othersims"] = pkg
    return importlib.import_module("othersims.render")


def convert(other, scene):
    """``scene`` in the other checkout's own classes (its renderer tells kinds apart by identity)."""
    def fields(o):
        return {f.name: other.ObjectKind[o.kind.name] if f.name == "kind" else getattr(o, f.name)
                for f in dataclasses.fields(o)}
    return other.Scene(scene.ego, tuple(other.ObjectState(**fields(o)) for o in scene.objects))


def main() -> None:
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    other = other_render(Path(sys.argv[1]))
    reps = int(os.environ.get("REPS", "5"))

    for scen in sys.argv[2:] or ["highway", "crossing", "loop", "curves"]:
        world = SimWorld(WorldConfig(scen, seed=0, autopilot=True))
        cfg = world.cfg
        theirs = other.StereoRenderer(cfg.rig, world.road_geometry, seed=cfg.seed, scenery=cfg.scenery,
                                      signs_xy=world.landmark_map().positions_m[:, :2])
        ours = world.renderer
        scenes = []
        for _ in range(FRAMES):
            world.step()
            scenes.append(scene_from_road(world.env.road, world.ego, world.ids))
        pairs = [(s, convert(other, s)) for s in scenes]
        for s, t in pairs[::10]:
            a, b = ours.render(s), theirs.render(t)
            same = all(np.array_equal(x, y) for x, y in ((a.left, b.left), (a.right, b.right), (a.depth_m, b.depth_m),
                                                           (a.ids, b.ids))) and a.boxes_px == b.boxes_px
            if not same:
                sys.exit(f"{scen}: the two renderers draw different pictures")
        t_theirs, t_ours = np.zeros(reps), np.zeros(reps)
        for rep in range(reps):
            for s, t in pairs:
                t0 = time.process_time()
                theirs.render(t)
                t1 = time.process_time()
                ours.render(s)
                t_theirs[rep] += t1 - t0
                t_ours[rep] += time.process_time() - t1
        print(f"{scen}: other {t_theirs.min() / FRAMES * 1e3:.2f} ms, this {t_ours.min() / FRAMES * 1e3:.2f} ms a "
              f"stereo pair, {t_theirs.sum() / t_ours.sum():.2f}x", flush=True)
        world.env.close()


if __name__ == "__main__":
    main()
