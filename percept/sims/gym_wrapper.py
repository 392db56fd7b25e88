"""StereoObservation: percept's stereo camera and IMU as the observation of any highway-env environment.

Usage::

    import gymnasium as gym
    import highway_env  # noqa: F401  (registers highway-v0, racetrack-v0, roundabout-v0, ...)
    from percept.sims.gym_wrapper import StereoObservation

    env = StereoObservation(gym.make("racetrack-v0"), seed=0)
    obs, info = env.reset(seed=0)
    obs["left"].shape, obs["right"].shape, obs["imu"]   # (480, 640, 3) uint8 BGR twice; (6,) float32
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

The images are BGR (OpenCV's order, as in percept's ``Frame``) from the rig's left and right cameras on
the controlled vehicle (``env.unwrapped.vehicle``). ``imu`` is accelerometer x, y, z [m/s^2] then gyro
x, y, z [rad/s] in the vehicle frame (x forward, y left, z up), with seeded noise and bias drift
(percept.sims.imu), clipped to +-16 g and +-2000 deg/s. The environment's own observation is still
computed by highway-env, and discarded. ``env.last_images`` keeps the renderer's output of the last
observation (left depth, object ids and boxes) for users who want image ground truth.

With ``rear=True`` the observation also holds ``rear_left`` and ``rear_right``: the rear stereo rig's images
(``percept.sensors.rear_rig`` of the rig: the same cameras at the rear bumper, looking back), and
``env.last_rear_images`` that rig's renderer output (its left depth, ids and boxes).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from percept.sensors import StereoRig, rear_rig

from .imu import ImuModel
from .render import RearRenderer, StereoRenderer, forward_twin
from .road_geometry import build_road_geometry
from .snapshot import ObjectIds, scene_from_road


ACCEL_RANGE_MPS2 = 16 * 9.81
GYRO_RANGE_RPS = np.radians(2000.0)
"""Full scale of a typical automotive MEMS IMU (+-16 g, +-2000 deg/s); readings are clipped to it."""


class StereoObservation(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    """Replaces a highway-env observation with {"left", "right": (H, W, 3) uint8 BGR, "imu": (6,) float32} (and
    "rear_left", "rear_right" with ``rear``).

    rig: the stereo rig (camera intrinsics, baseline, mount); seed: texture, scenery and IMU-noise seed;
    scenery: roadside clutter on/off; rear: the rear rig's pair too (True: ``rear_rig(rig)``, or a rig looking
    straight back). The road geometry and renderers are rebuilt on a reset only when the road network differs from
    the last one; object ids are kept for one episode.
    """

    def __init__(self, env: gym.Env, rig: StereoRig | None = None, seed: int = 0, scenery: bool = True,
                 rear: bool | StereoRig = False):
        gym.utils.RecordConstructorArgs.__init__(self, rig=rig, seed=seed, scenery=scenery, rear=rear)
        super().__init__(env)
        if seed < 0:
            raise ValueError(f"seed must be >= 0, got {seed}")
        self.rig = rig if rig is not None else StereoRig()
        if not isinstance(rear, (bool, StereoRig)):
            raise ValueError(f"rear must be True, False or a StereoRig, got {rear!r}")
        self.rear_rig = rear_rig(self.rig) if rear is True else rear or None
        if self.rear_rig is not None:
            forward_twin(self.rear_rig)  # ValueError unless it looks straight back
        self.seed = int(seed)
        self.scenery = bool(scenery)
        self._imu_range = np.array([ACCEL_RANGE_MPS2] * 3 + [GYRO_RANGE_RPS] * 3, np.float32)
        H, W = self.rig.camera.height, self.rig.camera.width
        image = spaces.Box(0, 255, (H, W, 3), np.uint8)
        self.observation_space = spaces.Dict({
            "left": image, "right": image,
            "imu": spaces.Box(-self._imu_range, self._imu_range, (6,), np.float32),
            **({} if self.rear_rig is None else {"rear_left": image, "rear_right": image}),
        })
        self.renderer: StereoRenderer | None = None
        self.rear_renderer: RearRenderer | None = None
        self.imu: ImuModel | None = None
        self.ids = ObjectIds()
        self.episode = 0
        self._reset_seed: int | None = None
        self._network_key: tuple | None = None
        self.last_images = None
        self.last_rear_images = None
        self._first = True

    @property
    def dt(self) -> float:
        """Time between two observations [s]: one policy step."""
        return 1.0 / float(self.env.unwrapped.config["policy_frequency"])

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        obs, info = self.env.reset(seed=seed, options=options)
        # reset(seed=s) makes the episode reproducible (IMU noise included); later resets continue from it
        self._reset_seed, self.episode = (seed, 0) if seed is not None else (self._reset_seed, self.episode + 1)
        entropy = [self.seed, self.episode, 0 if self._reset_seed is None else int(self._reset_seed) + 1]
        self.imu = ImuModel(int(np.random.SeedSequence(entropy).generate_state(1)[0]))
        network = self.env.unwrapped.road.network
        key = _network_key(network)
        if key != self._network_key:  # highway-env rebuilds an identical network on most resets
            road = build_road_geometry(network)
            self.renderer = StereoRenderer(self.rig, road, seed=self.seed, scenery=self.scenery)
            self.rear_renderer = None if self.rear_rig is None else RearRenderer(self.rear_rig, road, seed=self.seed,
                                                                                  scenery=self.scenery)
            self._network_key = key
        self.ids = ObjectIds()
        self._first = True
        return self.observation(obs), info

    def observation(self, observation) -> dict:
        if self.renderer is None:
            raise RuntimeError("call reset() before step()")
        base = self.env.unwrapped
        ego = base.vehicle
        scene = scene_from_road(base.road, ego, self.ids)
        images = self.renderer.render(scene)
        self.last_images = images
        # the first sample of an episode has no previous state: dt = 0 gives zero rates
        dt = 0.0 if self._first else self.dt
        self._first = False
        truth = self.imu.true_sample(scene.ego.yaw_rad, float(ego.speed), dt)
        meas, _wheel = self.imu.measure(truth, float(ego.speed), self.dt)
        imu = np.clip(np.concatenate([meas.accel_mps2, meas.gyro_rps]), -self._imu_range, self._imu_range)
        obs = {"left": images.left, "right": images.right, "imu": imu.astype(np.float32)}
        if self.rear_renderer is not None:
            self.last_rear_images = back = self.rear_renderer.render(scene)
            obs.update(rear_left=back.left, rear_right=back.right)
        return obs


def _network_key(network) -> tuple:
    """A cheap fingerprint of a RoadNetwork's geometry: each lane's class, ends, width and line types."""
    key = []
    for a, tos in network.graph.items():
        for b, lanes in tos.items():
            for lane in lanes:
                ends = np.round(np.concatenate([lane.position(0.0, 0.0), lane.position(lane.length, 0.0)]), 3)
                key.append((a, b, type(lane).__name__, tuple(ends), round(float(lane.length), 3),
                            round(float(lane.width_at(0.0)), 3), tuple(lane.line_types)))
    return tuple(key)
