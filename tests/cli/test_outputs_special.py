"""Outputs that are no plain file: a symbolic link is written through (it stays a link), a FIFO (as a device such as
/dev/null) is written to directly (no rename can replace it)."""

import json
import os
import threading

from typer.testing import CliRunner

from percept import outputs
from percept.cli import app

runner = CliRunner()


def test_a_link_is_written_through_and_stays_a_link(tmp_path):
    target, link = tmp_path / "target.json", tmp_path / "link.json"
    target.write_text("{}")
    link.symlink_to(target)
    result = runner.invoke(app, ["scenarios", "--json", str(link)])
    assert result.exit_code == 0, result.output
    assert link.is_symlink() and "dense" in json.loads(target.read_text())["scenarios"]


def test_a_link_given_to_atomic_path_stays_a_link(tmp_path):
    target, link = tmp_path / "video.avi", tmp_path / "link.avi"
    target.write_bytes(b"old")
    link.symlink_to(target)
    with outputs.atomic_path(link) as tmp:
        assert tmp.parent == tmp_path and tmp != target
        tmp.write_bytes(b"new")
    assert link.is_symlink() and target.read_bytes() == b"new"


def test_a_fifo_is_written_to_not_replaced(tmp_path):
    fifo = tmp_path / "out.json"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    outputs.write_json_atomic(fifo, {"a": 1})
    reader.join(timeout=10)
    assert fifo.is_fifo() and got and json.loads(got[0]) == {"a": 1}
