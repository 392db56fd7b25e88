"""`eval --address`: a Ray cluster that does not answer, or an address the engine does not use, is refused in one
line before any run (Ray itself would retry for minutes)."""

import socket

import pytest
from typer.testing import CliRunner

from percept.cli import app

runner = CliRunner()


def closed_port() -> int:
    """A local port nothing listens on."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("engine, address, message", [
    ("ray", f"127.0.0.1:{closed_port()}", "no Ray cluster answers"),
    ("ray", "nonsense", "must be HOST:PORT"),
    ("local", "127.0.0.1:6379", "give it with --engine ray"),
])
def test_a_bad_ray_address_is_one_line_and_writes_nothing(tmp_path, engine, address, message, one_line_error):
    out = tmp_path / "e"
    result = runner.invoke(app, ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "1", "--out", str(out),
                                 "--engine", engine, "--address", address])
    one_line_error(result, message)
    assert not out.exists()
