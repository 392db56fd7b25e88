"""The command line as typed, through the console script (``python -m percept``): a line typer cannot parse is one
`error:` line naming the help, with exit code 2; --help lists on/off flags without a value type."""

import subprocess
import sys

import pytest
from typer.testing import CliRunner

from percept.cli import app

runner = CliRunner()


def percept(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "percept", *args], capture_output=True, text=True, timeout=60,
                          cwd=cwd)


@pytest.mark.parametrize("args, message", [
    (["drive", "--record", "."], "Invalid value for '--record'"),
    (["drive", "--lanes", "magic"], "Invalid value for '--lanes'"),
    (["render", "--frames", "x", "--out", "o"], "Invalid value for '--frames'"),
    (["eval", "--scenario", "highway"], "Missing option '--out'"),
    (["lanes"], "Missing argument"),
    (["detect"], "Missing argument"),
    (["drive", "--bogus"], "No such option: --bogus"),
])
@pytest.mark.slow
def test_usage_errors_are_one_line(tmp_path, args, message, one_line_error):
    """typer printed these as a usage line, a hint and a framed box (five lines or more)."""
    p = percept(*args, cwd=tmp_path)
    one_line_error(p, message)
    assert p.stderr.splitlines() == [p.stderr.strip()], p.stderr
    assert f"(see `python -m percept {args[0]} --help`)" in p.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_help_still_works_through_the_console_script():
    p = percept("drive", "--help")
    assert p.returncode == 0 and "--no-record" in p.stdout and p.stderr == ""
    p = percept()  # no command: the help, as typer prints it
    assert p.returncode == 2 and "drive" in p.stdout + p.stderr and "error:" not in p.stderr


@pytest.mark.parametrize("command, flags", [
    ("drive", ["--no-record"]), ("render", ["--scenery", "--force"]), ("eval", ["--redo"]),
    ("calibrate", ["--stereo"]), ("view", ["--web"]), ("lanes", []), ("detect", []),
])
def test_flags_show_no_value_type_in_help(command, flags):
    r = runner.invoke(app, [command, "--help"], env={"COLUMNS": "200"})
    assert r.exit_code == 0
    lines = {ln.split()[1]: ln for ln in r.output.splitlines() if ln.strip().startswith(("│ --", "│    --"))}
    for flag in flags:
        assert "<bool>" not in lines[flag], lines[flag]
    if command in ("calibrate", "view", "lanes", "detect"):  # registered with percept's Command class
        assert "<bool>" not in lines["--help"], lines["--help"]


def test_help_paragraphs_are_reflowed_and_lists_kept():
    """A docstring's line breaks inside a paragraph are joined (typer's rich help kept them as ragged lines);
    paragraphs and list items stay."""
    from percept.cli.common import reflow

    assert reflow("One line\n    wrapped here.\n\n    Next\n    para:\n    - item one\n      goes on\n    - two") == (
        "One line wrapped here.\n\nNext para:\n- item one goes on\n- two")
    assert reflow(None) is None and reflow("") == ""
    r = runner.invoke(app, ["eval", "--help"], env={"COLUMNS": "240"})
    assert r.exit_code == 0
    assert ("summary.csv (every metric per scenario and condition: runs, mean, p95, worst), summary.md (safety "
            "counts, headline metrics, runs to look at with the command that reproduces each)") in r.output
