"""Scenarios built on highway-env's road, lane and vehicle classes."""

from .catalog import SCENARIOS, Scenario, lane_at
from .clothoid import ClothoidLane
from .roads import loop_road, straight_road, winding_road

__all__ = ["SCENARIOS", "ClothoidLane", "Scenario", "lane_at", "loop_road", "straight_road", "winding_road"]
