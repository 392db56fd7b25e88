"""The renderer's compiled kernels, each checked in a fresh Python process: a renderer, once built, compiles
nothing in a world's frames; the pedestrians' figures built by compiled code are the interpreted ones to the byte;
Ctrl-C during a kernel is a KeyboardInterrupt."""

import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.slow


WARM_CHECK = """
from percept.compiled import dispatchers
from percept.sims import SimWorld, WorldConfig, condition_passes, conditions, normals
from percept.sims.render import cull, ground, paint, pedestrian, pixels, small_patches, spans
modules = (pixels, small_patches, cull, spans, pedestrian, ground, paint, condition_passes, normals)
kernels = dispatchers(*modules)
# the world's renderer and its night effects warm their kernels up when they are built, and so do the other
# conditions' effects
world = SimWorld(WorldConfig("crossing", seed=1, condition="night", autopilot=True))
others = [conditions.ConditionEffects(world.cfg.rig, c) for c in ("rain", "glare", "noise")]
before = [len(k.signatures) for k in kernels]
for _ in range(6):
    world.step()
    frame, _ = world.observe()
    for fx in others:
        fx.apply(frame.left, 1, world.frame_index, 0)
print(len(kernels), min(before), [len(k.signatures) for k in kernels] == before)
"""


def test_after_the_warm_up_rendering_a_world_compiles_nothing():
    # in a fresh process: this one may have compiled kernels for other tests already
    out = subprocess.run([sys.executable, "-c", WARM_CHECK], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    count, least, unchanged = out.stdout.split()
    # every kernel compiled (or loaded) by the warm-up; a frame compiling one for new argument types would pay
    # seconds inside a timed step
    assert int(count) >= 18 and int(least) >= 1 and unchanged == "True"


FIGURES = """
import hashlib, math
import numpy as np
from percept.sensors import Pose2D
from percept.sims.render import ObjectKind, ObjectState
from percept.sims.render.pedestrian import pedestrian_packed
rng = np.random.default_rng(11)
m = hashlib.sha256()
for i in range(300):
    x, y = rng.uniform(-40, 40, 2)
    obj = ObjectState(i + 1, ObjectKind.PEDESTRIAN, Pose2D(x, y, rng.uniform(-math.pi, math.pi)), 0.5, 0.5,
                      rng.uniform(1.0, 2.1), style=int(rng.integers(0, 2**40)), speed_mps=float(rng.choice([0, 1.4])),
                      gait_phase=rng.uniform(0, 12))
    m.update(pedestrian_packed(obj, (rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(0.5, 2.0))).tobytes())
# seen from straight above its base: the horizontal direction to the viewer is degenerate
m.update(pedestrian_packed(ObjectState(1, ObjectKind.PEDESTRIAN, Pose2D(1.0, 2.0, 0.3), 0.5, 0.5, 1.7),
                           (1.0, 2.0, 1.0)).tobytes())
print(m.hexdigest())
"""


def test_the_compiled_figures_are_the_interpreted_ones():
    # the pedestrians' figures are built by compiled code; with numba's compiler off the same functions run as
    # Python, with Python's own arithmetic, math.hypot, min and max: the patches must be the same bytes
    digests = []
    for jit_off in ("0", "1"):
        env = {**os.environ, "NUMBA_DISABLE_JIT": jit_off}
        out = subprocess.run([sys.executable, "-c", FIGURES], capture_output=True, text=True, timeout=300, env=env)
        assert out.returncode == 0, out.stderr[-2000:]
        digests.append(out.stdout.strip())
    assert len(digests[0]) == 64 and digests[0] == digests[1]


CTRL_C = """
import os, signal, threading, time
import numpy as np
# Python's own handler, also when the test runs where SIGINT is ignored (a background job: nohup cmd &)
signal.signal(signal.SIGINT, signal.default_int_handler)
from percept.sims.render.cull import inverse_rows
n = 5000
o = np.random.default_rng(0).normal(size=(n, 3))
e1, e2, ok = o.copy(), o + 1, np.ones(n, bool)
inverse_rows(o, e1, e2, ok, 100.0, 100.0, 80.0, 60.0)
seen = []
for trial in range(12):
    threading.Timer(0.01 + 0.003 * trial, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    t0 = time.time()
    try:
        while time.time() - t0 < 5:
            inverse_rows(o, e1, e2, ok, 100.0, 100.0, 80.0, 60.0)
        seen.append("none")
    except BaseException as e:
        seen.append(type(e).__name__)
print(" ".join(seen))
"""


def test_ctrl_c_during_a_kernel_is_a_keyboard_interrupt():
    # numba boxes a kernel's arrays without checking for a pending signal; unwrapped, most of these would be
    # SystemError, which the commands' Ctrl-C handling (keep what is finished, exit 130) does not recognise
    out = subprocess.run([sys.executable, "-c", CTRL_C], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.split() == ["KeyboardInterrupt"] * 12
