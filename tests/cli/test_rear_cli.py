"""--rear/--no-rear on `percept render`, `drive` and `eval` through typer's CliRunner."""

import json
import math

import cv2
import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.drive import DriveConfig
from percept.evaluate.plan import EvalPlan
from percept.sensors import StereoRig, rear_rig
from percept.sims import WorldConfig

runner = CliRunner()


@pytest.mark.parametrize("command", ["render", "drive", "eval"])
def test_every_command_that_makes_a_world_offers_the_rear_rig(command):
    r = runner.invoke(app, [command, "--help"], terminal_width=200)
    assert r.exit_code == 0 and "--rear" in r.output and "--no-rear" in r.output


def test_render_with_the_rear_rig_writes_its_pair_its_camera_and_its_boxes(tmp_path):
    r = runner.invoke(app, ["render", "--frames", "2", "--out", str(tmp_path), "--no-scenery", "--rear"])
    assert r.exit_code == 0, r.output
    rear = StereoRig.load(tmp_path / "rear_camera.json")
    assert rear == rear_rig(StereoRig.load(tmp_path / "camera.json")) and rear.yaw_rad == math.pi
    for i in range(2):
        left, right = (cv2.imread(str(tmp_path / f"{i:06d}_rear_{s}.png")) for s in ("left", "right"))
        assert left.shape == right.shape == (rear.camera.height, rear.camera.width, 3)
        gt = json.loads((tmp_path / f"{i:06d}_gt.json").read_text())
        behind = [o for o in gt["objects"] if "rear_box_px" in o]
        assert behind and all(o["position_m"][0] < 0 and 0 < o["rear_visible"] <= 1 for o in behind)
    # --force replaces it with a render without the rear rig (the highway default): no rear file is left
    r = runner.invoke(app, ["render", "--frames", "1", "--out", str(tmp_path), "--no-scenery", "--force"])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["000000_depth.npy", "000000_gt.json", "000000_left.png",
                                                          "000000_right.png", "camera.json"]


def test_drive_says_whether_the_car_had_the_rear_rig(tmp_path):
    for args, rear in (([], False), (["--rear"], True), (["--no-rear"], False)):
        out = tmp_path / "run.json"
        r = runner.invoke(app, ["drive", "--privileged", "--no-record", "--duration", "0.2", "--json", str(out),
                                *args])
        assert r.exit_code == 0, r.output
        assert json.loads(out.read_text())["rear"] is rear


def test_the_configurations_resolve_the_option_per_scenario():
    assert DriveConfig(WorldConfig("highway")).rear is False
    cfg = DriveConfig(WorldConfig("highway"), rear=True)
    assert cfg.rear is True and cfg.world.rear_rig == rear_rig(cfg.world.rig)
    assert DriveConfig(WorldConfig("highway", rear_rig=rear_rig(StereoRig())), rear=False).world.rear_rig is None
    plan = EvalPlan(("highway", "crossing"), ("clear",), (0, 1), rear=True)
    assert all(plan.config(job).world.rear_rig is not None for job in plan.jobs)
    with pytest.raises(ValueError, match="rear must be True, False or None"):
        DriveConfig(rear="on")


def test_eval_keeps_the_option_in_its_settings_and_refuses_to_mix_runs(tmp_path, one_line_error):
    base = ["eval", "--scenario", "lead-brake", "--seeds", "0", "--privileged", "--duration", "0.2", "--out",
            str(tmp_path)]
    r = runner.invoke(app, [*base, "--rear"])
    assert r.exit_code == 0, r.output
    run = json.loads((tmp_path / "runs" / "lead-brake-clear-0.json").read_text())
    assert run["rear"] is True and run["settings"]["rear"] is True
    r = runner.invoke(app, [*base, "--no-rear"])
    one_line_error(r, "made with other settings")
    assert "rear True (now False)" in r.output
