import os

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")


@pytest.fixture
def one_line_error():
    """``one_line_error(result, message="")``: a command refused its input in one line, as ``percept.cli.common.fail``
    prints it.

    ``result`` is a click ``CliRunner`` result (exit_code, output) or a finished ``subprocess.run`` with text output
    (returncode, stdout, stderr). It passes when the exit code is 2, no traceback is printed and no exception but
    SystemExit is raised, the output's last line starts with ``error: `` and contains ``message``, and no other line
    says ``error:`` (lines before it, such as a progress bar, may be there).
    """
    def check(result, message: str = "") -> None:
        if hasattr(result, "exit_code"):
            code, text = result.exit_code, result.output
            assert result.exception is None or isinstance(result.exception, SystemExit), text
        else:
            code, text = result.returncode, (result.stdout or "") + (result.stderr or "")
        lines = text.strip().splitlines()
        assert code == 2, text
        assert "Traceback" not in text, text
        assert lines and lines[-1].startswith("error: ") and message in lines[-1], text
        assert sum("error:" in line for line in lines) == 1, text
    return check
