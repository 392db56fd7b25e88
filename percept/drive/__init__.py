"""Composition: the agent, the closed loop, scoring, batch evaluation and benchmarks."""

from .bench import StageCost, bench_render, median_ms

__all__ = ["StageCost", "bench_render", "median_ms"]
