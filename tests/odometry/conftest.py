import pytest

from percept.sims import SimWorld, WorldConfig

LOOP_FRAMES = 150


@pytest.fixture(scope="package")
def loop_run():
    """The first 10 s of `loop` seed 0 (highway-env's autopilot drives): (world, [(frame, truth), ...]). A landmark
    sign is in view around frames 130-145."""
    world = SimWorld(WorldConfig("loop", 0, autopilot=True))
    shots = []
    for _ in range(LOOP_FRAMES):
        shots.append(world.observe())
        world.step()
    return world, shots
