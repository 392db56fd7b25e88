"""Training the sim people model on rendered frames (``percept train-detector``)."""

from .people import TrainPlan, frames_to_sample, train_people_model, truth_path
from .samples import for_each_frame

__all__ = ["TrainPlan", "for_each_frame", "frames_to_sample", "train_people_model", "truth_path"]
