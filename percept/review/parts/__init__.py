"""The review parts, one per driving task (what ``percept.drive.tasks`` names as "percept.review.parts:<task>"),
and the control part every recording has. See ``percept.review.context`` for the part interface."""

from .control import PART as control
from .lanes import PART as lanes
from .longitudinal import PART as longitudinal
from .odometry import PART as odometry
from .pedestrians import PART as pedestrians

__all__ = ["control", "lanes", "longitudinal", "odometry", "pedestrians"]
