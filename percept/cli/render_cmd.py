"""`percept render`: stereo PNGs, depth and ground truth of a scenario."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from . import options as opt
from .common import console, fail, progress_bar


def render(
    frames: Annotated[int, typer.Option("--frames", help="Number of consecutive frames (15 per simulated second), "
                                                         "1 to 1,000,000.")],
    out: Annotated[Path, typer.Option("--out", file_okay=False, help="Output folder; created if missing.")],
    scenario: opt.Scenario = "highway",
    seed: opt.Seed = 0,
    condition: opt.Condition = "clear",
    scenery: Annotated[bool, typer.Option(help="Roadside clutter (rails, poles, trees, buildings).")] = True,
):
    """Render stereo PNGs, depth and ground truth of a scenario; the ego is driven by highway-env's IDM autopilot.

    Writes for frame i: DIR/{i:06d}_left.png, _right.png (absent when the frame was dropped), _depth.npy
    (float32 metres, inf for sky), _gt.json; plus DIR/camera.json and, with landmark signs, DIR/landmarks.json.
    """
    from percept.sims import SimWorld, WorldConfig
    from percept.sims.export import prepare_out_dir, render_run

    opt.check_number("--frames", frames, 1, 10**6)
    opt.check_number("--seed", seed, 0, opt.MAX_SEED)
    try:
        cfg = WorldConfig(scenario=scenario, seed=seed, condition=condition, autopilot=True, scenery=scenery)
        prepare_out_dir(out)
    except ValueError as e:
        fail(str(e))
    world = SimWorld(cfg)
    with progress_bar() as bar:
        task = bar.add_task(f"rendering {scenario}/{cfg.condition.value}/seed {seed}", total=frames)
        try:
            render_run(world, frames, out, progress=lambda: bar.advance(task))
        except (ValueError, OSError) as e:
            fail(str(e))
    console.print(f"wrote {frames} frames to {out}")
