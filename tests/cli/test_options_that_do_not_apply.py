"""Options a command would ignore are refused in one line, so that nobody believes they took effect."""

import pytest
from typer.testing import CliRunner

from percept.cli import app

runner = CliRunner()


@pytest.mark.parametrize("extra", [["--lanes", "vision"], ["--detector", "inria"]])
def test_the_mobil_ego_takes_no_slot_options(tmp_path, extra, one_line_error):
    result = runner.invoke(app, ["eval", "--ego", "mobil", "--scenario", "dense", "--seeds", "0", "--duration", "1",
                                 "--out", str(tmp_path / "e"), *extra])
    one_line_error(result, "no slot runs")


def test_bench_scenarios_need_the_whole_stack(one_line_error):
    one_line_error(runner.invoke(app, ["bench", "--frames", "1", "--scenario", "dense"]), "add --stack")


def test_a_second_stage_threshold_needs_a_first_stage(tmp_path, one_line_error):
    one_line_error(runner.invoke(app, ["train-detector", "--second-threshold", "1", "--out", str(tmp_path / "m.npz")]),
                   "give it with --first-stage")
    assert not (tmp_path / "m.npz").exists()
