"""``percept bench``: each stage's cost on one thread against its named peer in the same run, and the whole
stack's cost in the closed loop."""

from .stages import StageCost, bench_render, bench_task, median_ms, slot_ms

__all__ = ["StageCost", "bench_render", "bench_task", "median_ms", "slot_ms"]
