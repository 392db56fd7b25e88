"""Helpers shared by the output tests: what a folder holds, byte for byte, and the writers' leftovers."""

from pathlib import Path

import pytest


@pytest.fixture
def snapshot():
    """``snapshot(folder)``: every file under ``folder`` (hidden temporaries included) -> its bytes."""
    return lambda folder: {p.relative_to(folder): p.read_bytes() for p in sorted(Path(folder).rglob("*"))
                           if p.is_file()}


@pytest.fixture
def temporaries():
    """``temporaries(folder)``: the atomic writers' temporaries left under ``folder``."""
    return lambda folder: [p for p in Path(folder).rglob(".*") if ".tmp" in p.name]
