"""The review parts: one module per driving task, named in the slot table as "percept.review.parts.<module>:PART",
and the control part every recording has. See ``percept.review.context`` for the part interface."""

from .control import PART as control

__all__ = ["control"]
