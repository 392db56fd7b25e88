"""`percept render`: stereo PNGs, depth and ground truth of a scenario."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import options as opt
from .common import console, fail, on_interrupt, progress_bar


def render(
    frames: Annotated[int, typer.Option("--frames", help="Number of consecutive frames (15 per simulated second), "
                                                         "1 to 1,000,000.")],
    out: Annotated[Path, typer.Option("--out", file_okay=False, help="Output folder; created if missing.")],
    scenario: opt.Scenario = "highway",
    seed: opt.Seed = 0,
    condition: opt.Condition = "clear",
    scenery: Annotated[bool, opt.flag(help="Roadside clutter (rails, poles, trees, buildings).")] = True,
    rear: opt.Rear = None,
    force: Annotated[bool, opt.flag("--force", help="Replace an earlier render in --out (its files are removed "
                                                        "first; other files still refuse the folder).")] = False,
):
    """Render stereo PNGs, depth and ground truth of a scenario; the ego is driven by highway-env's IDM autopilot.

    Writes for frame i: DIR/{i:06d}_left.png, _right.png (and _rear_left.png, _rear_right.png with the rear rig;
    absent when the frame was dropped), _depth.npy (float32 metres, inf for sky), _gt.json; plus DIR/camera.json
    (DIR/rear_camera.json with the rear rig) and, with landmark signs, DIR/landmarks.json.
    Each frame's files are complete or absent, also when the render is stopped; a folder that already holds files
    is refused unless --force.
    """
    from percept.sims import SimWorld, WorldConfig, with_rear
    from percept.sims.export import prepare_out_dir, render_run, written

    opt.check_number("--frames", frames, 1, 10**6)
    opt.check_number("--seed", seed, 0, opt.MAX_SEED)
    try:
        cfg = with_rear(WorldConfig(scenario=scenario, seed=seed, condition=condition, autopilot=True,
                                    scenery=scenery), rear)
        prepare_out_dir(out, force)
    except ValueError as e:
        fail(str(e))
    kept = lambda: f"{written(out)} complete frames kept in {out}; --force starts over in the same folder"  # noqa: E731
    on_interrupt(kept)
    world = SimWorld(cfg)
    with progress_bar() as bar:
        task = bar.add_task(f"rendering {scenario}/{cfg.condition.value}/seed {seed}", total=frames)
        try:
            render_run(world, frames, out, progress=lambda: bar.advance(task))
        except ValueError as e:
            fail(str(e))
        except OSError as e:
            fail(f"cannot write into {out}: {e.strerror or e}; {kept()}")
    console.print(f"wrote {frames} frames to {out}")
