"""Scenarios built on highway-env's road, lane and vehicle classes."""

from .catalog import SCENARIOS, Scenario
from .clothoid import ClothoidLane
from .placing import lane_at
from .roads import loop_road, merge_road, straight_road, winding_road

__all__ = ["SCENARIOS", "ClothoidLane", "Scenario", "lane_at", "loop_road", "merge_road", "straight_road",
           "winding_road"]
