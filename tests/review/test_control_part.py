"""The control part on hand-made law records: the acceleration terms beside the command, each drawn within what a
law may command."""

from types import SimpleNamespace

from percept.control import EmergencyBrakingDebug
from percept.review import ColumnBuffer, PartContext
from percept.review.parts.control import PART
from percept.sensors import StereoRig
from percept.sensors.vehicle import MAX_BRAKE_MPS2


class Scalars(ColumnBuffer):
    """The scalars a part sends through the buffer, the last of each path."""

    def __init__(self):
        super().__init__("sim_time")
        self.last: dict[str, float] = {}

    def add(self, path, archetype, **components):
        super().add(path, archetype, **components)
        self.last[path] = float(components["scalars"][0]) if "scalars" in components else None


class Logged:
    def log(self, path, entity, **kwargs):
        pass


def test_an_emergency_term_beyond_the_brake_limit_is_drawn_at_the_limit():
    buffer = Scalars()
    ctx = PartContext("control", StereoRig(), buffer, image=False)
    braking = EmergencyBrakingDebug({"follow": -2.0, "emergency": -1000.0}, "brake_limit", None, -MAX_BRAKE_MPS2)
    step = SimpleNamespace(accel_mps2=-MAX_BRAKE_MPS2, steering_rad=0.0, estimates={})
    truth = SimpleNamespace(truth=SimpleNamespace(speed_mps=20.0))
    PART(Logged(), ctx, step, {"emergency_braking": braking}, truth)
    assert buffer.last["control/accel_mps2/emergency"] == -MAX_BRAKE_MPS2
    assert buffer.last["control/accel_mps2/command"] == -MAX_BRAKE_MPS2
