"""`drive` and `eval` outputs that would destroy an input or the batch's own files, and record options that cannot
both hold: refused in one line before any run; footage commands that do not read their own overlays."""

import json
import shutil
from pathlib import Path

import cv2
import numpy as np

import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.detection.hog import SIM_MODEL_PATH

runner = CliRunner()


@pytest.fixture
def model(tmp_path):
    """A copy of the packaged people model."""
    path = tmp_path / "people.npz"
    shutil.copy(SIM_MODEL_PATH, path)
    return path


@pytest.mark.parametrize("command, output", [(["drive", "--no-record"], "--json"), (["drive"], "--record"),
                                             (["eval", "--scenario", "highway", "--seeds", "0"], "--json")])
def test_an_output_on_the_people_model_is_refused_and_the_model_kept(tmp_path, model, command, output,
                                                                     one_line_error):
    before = model.read_bytes()
    args = [*command, "--duration", "1", "--detector", str(model), output, str(model)]
    if command[0] == "eval":
        args += ["--out", str(tmp_path / "e")]
    result = runner.invoke(app, args)
    one_line_error(result, ".npz" if output == "--record" else "is also an input")
    assert model.read_bytes() == before


@pytest.mark.parametrize("inside", ["summary.md", "runs/highway-clear-0.json", "plots/x.png"])
def test_eval_json_inside_its_out_folder_is_refused(tmp_path, inside, one_line_error):
    out = tmp_path / "e"
    result = runner.invoke(app, ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "1", "--out", str(out),
                                 "--json", str(out / inside)])
    one_line_error(result, "is where eval writes its own results")
    assert not (out / "runs" / "highway-clear-0.json").exists()


def test_record_and_no_record_together_are_refused(tmp_path, one_line_error):
    one_line_error(runner.invoke(app, ["drive", "--duration", "1", "--no-record", "--record", str(tmp_path / "r.rrd")]),
                   "contradict")


@pytest.mark.parametrize("name", ["summary.md", "summary.json", "summary.csv"])
def test_a_summary_eval_did_not_write_is_not_replaced(tmp_path, name, one_line_error):
    out = tmp_path / "e"
    out.mkdir()
    (out / name).write_text("my own notes")
    result = runner.invoke(app, ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "1", "--out", str(out)])
    one_line_error(result, "was not written by percept eval")
    assert (out / name).read_text() == "my own notes"


def test_a_file_where_eval_writes_its_plots_is_refused_before_any_run(tmp_path, one_line_error):
    out = tmp_path / "e"
    out.mkdir()
    (out / "plots").write_text("mine")
    result = runner.invoke(app, ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "1", "--out", str(out)])
    one_line_error(result, "where eval writes its plots")
    assert not (out / "summary.json").exists() and (out / "plots").read_text() == "mine"


@pytest.mark.parametrize("command", ["lanes", "detect"])
def test_a_footage_folder_holding_its_own_overlays_is_read_without_them(tmp_path, command, one_line_error):
    folder = tmp_path / "shots"
    folder.mkdir()
    rng = np.random.default_rng(0)
    cv2.imwrite(str(folder / "a.png"), rng.integers(0, 255, (240, 320, 3), dtype=np.uint8))
    for k in range(2):  # the second run finds the first one's overlay beside the image
        js = tmp_path / f"run{k}.json"
        r = runner.invoke(app, [command, str(folder), "--out", str(folder), "--json", str(js)])
        assert r.exit_code == 0, r.output
        assert [Path(x["file"]).name for x in json.loads(js.read_text())["results"]] == ["a.png"]
    assert sorted(p.name for p in folder.iterdir()) == sorted(["a.png", f"a.{command}.png"])
    one_line_error(runner.invoke(app, [command, str(tmp_path / "only"), "--out", str(tmp_path / "only")]), "")
    (tmp_path / "only").mkdir()
    shutil.copy(folder / f"a.{command}.png", tmp_path / "only")
    one_line_error(runner.invoke(app, [command, str(tmp_path / "only"), "--out", str(tmp_path / "only")]),
                   f"holds only percept's own {command} overlays")


def test_the_summaries_eval_writes_are_known_as_its_own_and_replaced_next_time(tmp_path):
    from percept.evaluate import SUMMARY_STARTS, written_by_eval

    out = tmp_path / "e"
    args = ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "0.2", "--privileged", "--out", str(out)]
    assert runner.invoke(app, args).exit_code == 0
    assert all(written_by_eval(out / name) for name in SUMMARY_STARTS)
    r = runner.invoke(app, [*args, "--redo"])
    assert r.exit_code == 0, r.output
