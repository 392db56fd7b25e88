"""`percept scenarios` and `percept render` through typer's CliRunner."""

import json
import re

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app

runner = CliRunner()


def test_scenarios_lists_every_scenario_and_condition(tmp_path):
    out = tmp_path / "s.json"
    r = runner.invoke(app, ["scenarios", "--json", str(out)])
    assert r.exit_code == 0, r.output
    for name in ("highway", "curves", "lead-brake", "cut-in", "cut-in-close", "crossing", "loop", "dense", "overtake",
                 "merge", "night", "dropout"):
        assert name in r.output
    d = json.loads(out.read_text())
    assert set(d["scenarios"]) == {"highway", "curves", "lead-brake", "cut-in", "cut-in-close", "crossing", "loop",
                                   "dense", "overtake", "merge"}
    assert {k for k, v in d["scenarios"].items() if v["lane_changes"]} == {"dense", "overtake", "merge"}
    assert {k for k, v in d["scenarios"].items() if v["rear"]} == {"dense", "overtake", "merge", "cut-in-close"}
    assert set(d["conditions"]) == {"clear", "night", "rain", "glare", "noise", "dropout"}


def test_render_writes_the_contract(tmp_path):
    r = runner.invoke(app, ["render", "--scenario", "highway", "--frames", "2", "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    cam = json.loads((tmp_path / "camera.json").read_text())
    for k in ("fx", "fy", "cx", "cy", "width", "height", "baseline_m", "mount_height_m", "pitch_rad"):
        assert k in cam
    for i in range(2):
        left = cv2.imread(str(tmp_path / f"{i:06d}_left.png"))
        right = cv2.imread(str(tmp_path / f"{i:06d}_right.png"))
        assert left.shape == right.shape == (cam["height"], cam["width"], 3)
        depth = np.load(tmp_path / f"{i:06d}_depth.npy")
        assert depth.dtype == np.float32 and depth.shape == left.shape[:2]
        assert np.isinf(depth[0]).all() and np.isfinite(depth[-1]).all()  # sky on top, road at the bottom
        gt = json.loads((tmp_path / f"{i:06d}_gt.json").read_text())
        assert set(gt["ego"]) >= {"x", "y", "yaw", "speed"}
        assert set(gt["lane"]) >= {"offset_m", "heading_rad", "curvature_1pm", "width_m"}
        kinds = {o["kind"] for o in gt["objects"]}
        assert "vehicle" in kinds
        for o in gt["objects"]:
            assert set(o) >= {"kind", "id", "box_px", "visible", "distance_m", "position_m"}
            assert 0.0 <= o["visible"] <= 1.0
            if o["box_px"] is not None:
                u0, v0, u1, v1 = o["box_px"]
                assert 0 <= u0 < u1 <= cam["width"] and 0 <= v0 < v1 <= cam["height"]


def test_render_loop_writes_the_landmark_map(tmp_path):
    r = runner.invoke(app, ["render", "--scenario", "loop", "--frames", "1", "--out", str(tmp_path), "--no-scenery"])
    assert r.exit_code == 0, r.output
    lm = json.loads((tmp_path / "landmarks.json").read_text())
    assert len(lm) >= 40 and all(len(v) == 3 for v in lm.values())


@pytest.mark.parametrize("args, message", [
    (["--scenario", "motorway", "--frames", "2"], "unknown scenario 'motorway'; choose one of: highway"),
    (["--scenario", "highway", "--condition", "fog", "--frames", "2"], "unknown condition 'fog'; choose one of: clear"),
    (["--scenario", "highway", "--frames", "0"], "--frames must be a finite number between 1"),
    (["--scenario", "highway", "--frames", "2", "--seed", "-1"], "--seed must be a finite number"),
])
def test_render_bad_input_is_one_line_exit_2(tmp_path, args, message, one_line_error):
    one_line_error(runner.invoke(app, ["render", *args, "--out", str(tmp_path / "o")]), message)
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())


def test_render_unwritable_folder(tmp_path, one_line_error):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    r = runner.invoke(app, ["render", "--frames", "1", "--out", str(blocker / "sub")])
    one_line_error(r)
    assert "cannot write" in r.output or "not a folder" in r.output
