"""The simulated world: highway-env scenarios, the stereo renderer, IMU, conditions and ground truth."""

from .conditions import CONDITION_SUMMARY, Condition
from .ground_truth import GroundTruth, LaneTruth, ObjectTruth
from .scenarios import SCENARIOS, Scenario
from .world import SimWorld, WorldConfig, check_condition, check_scenario

__all__ = ["CONDITION_SUMMARY", "Condition", "GroundTruth", "LaneTruth", "ObjectTruth", "SCENARIOS", "Scenario",
           "SimWorld", "WorldConfig", "check_condition", "check_scenario"]
