"""The simulated world: highway-env scenarios, the stereo renderer, IMU, conditions and ground truth."""

from .conditions import CONDITION_SUMMARY, Condition
from .ground_truth import GroundTruth, LaneTruth, ObjectTruth
from .gym_wrapper import StereoObservation
from .scenarios import SCENARIOS, Scenario
from .world import SimWorld, WorldConfig, check_condition, check_scenario, with_rear

__all__ = ["CONDITION_SUMMARY", "Condition", "GroundTruth", "LaneTruth", "ObjectTruth", "SCENARIOS", "Scenario",
           "SimWorld", "StereoObservation", "WorldConfig", "check_condition", "check_scenario", "with_rear"]
