"""StereoObservation: the stereo camera and IMU as the observation of stock highway-env environments."""

import math
import warnings

import cv2
import gymnasium as gym
import highway_env  # noqa: F401  (registers the environments)
import numpy as np
import pytest

from percept.sensors import PinholeCamera, StereoRig, rear_rig
from percept.sims.coords import hw_pose, hw_to_world_xy
from percept.sims.gym_wrapper import StereoObservation

pytestmark = pytest.mark.filterwarnings("ignore:.*share an object")  # highway-env reuses its info dict

SMALL = StereoRig(PinholeCamera.from_hfov(160, 120, math.radians(60.0)))
CONFIGS = {"highway-v0": {"vehicles_count": 3}, "racetrack-v0": {"other_vehicles": 1}}
ACTIONS = {"highway-v0": 1, "racetrack-v0": np.array([0.0], np.float32)}  # IDLE / steer straight


def make(name: str, rig: StereoRig = SMALL, seed: int = 0, config: dict | None = None) -> StereoObservation:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # "racetrack-v0 is out of date"
        env = gym.make(name, config=config if config is not None else CONFIGS[name])
    return StereoObservation(env, rig=rig, seed=seed, scenery=False)


def run(name: str, steps: int = 3, seed: int = 0) -> tuple[StereoObservation, list[dict], list[np.ndarray]]:
    env = make(name, seed=seed)
    obs, _ = env.reset(seed=seed)
    out, pos = [obs], [env.unwrapped.vehicle.position.copy()]
    for _ in range(steps):
        obs, *_ = env.step(ACTIONS[name])
        out.append(obs)
        pos.append(env.unwrapped.vehicle.position.copy())
    return env, out, pos


@pytest.fixture(scope="module", params=list(CONFIGS))
def episode(request):
    return request.param, *run(request.param)


def test_default_observation_space():
    env = make("highway-v0", rig=StereoRig())
    space = env.observation_space
    assert isinstance(space, gym.spaces.Dict) and set(space.spaces) == {"left", "right", "imu"}
    for side in ("left", "right"):
        assert space[side].shape == (480, 640, 3) and space[side].dtype == np.uint8
        assert space[side].low.min() == 0 and space[side].high.max() == 255
    assert space["imu"].shape == (6,) and space["imu"].dtype == np.float32


def test_observations_are_in_the_space(episode):
    name, env, obs, _ = episode
    H, W = SMALL.camera.height, SMALL.camera.width
    for o in obs:
        assert env.observation_space.contains(o), name
        assert o["left"].shape == o["right"].shape == (H, W, 3) and o["left"].dtype == np.uint8
        assert o["imu"].dtype == np.float32 and np.all(np.isfinite(o["imu"]))
    assert env.dt == pytest.approx(1.0 / env.unwrapped.config["policy_frequency"])


def test_images_are_textured_and_a_stereo_pair(episode):
    name, _, obs, _ = episode
    for o in obs:
        grey = cv2.cvtColor(o["left"], cv2.COLOR_BGR2GRAY)
        assert grey.std() > 20, name  # sky, road and grass, not a blank frame
        assert not np.array_equal(o["left"], o["right"])
        # the road is under the car: the bottom rows are mostly unsaturated grey (asphalt)
        hsv = cv2.cvtColor(o["left"][-10:, 40:-40], cv2.COLOR_BGR2HSV)
        assert np.median(hsv[..., 1]) < 40, name


def test_observation_changes_as_the_car_moves(episode):
    name, _, obs, pos = episode
    assert np.linalg.norm(pos[-1] - pos[0]) > 5.0
    diff = np.abs(obs[-1]["left"].astype(np.int16) - obs[0]["left"]).mean()
    assert diff > 2.0, name
    assert np.abs(obs[-1]["imu"] - obs[0]["imu"]).max() > 0


def test_same_seed_gives_identical_observations(episode):
    name, _, obs, _ = episode
    _, again, _ = run(name)
    for a, b in zip(obs, again):
        for k in ("left", "right", "imu"):
            assert np.array_equal(a[k], b[k]), (name, k)


def test_racetrack_passes_gymnasium_env_checker():
    from gymnasium.utils.env_checker import check_env

    env = make("racetrack-v0", config={"other_vehicles": 0})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(env, skip_render_check=True)


def _paint_grey(env: StereoObservation, lane_index, s_ego: float, s: float, lateral_hw: float) -> float:
    """Put the ego at s_ego on a lane, render, and read the left image's grey level at a lane point."""
    base = env.unwrapped
    lane = base.road.network.get_lane(lane_index)
    ego = base.vehicle
    ego.position, ego.heading = lane.position(s_ego, 0.0), lane.heading_at(s_ego)
    grey = cv2.cvtColor(env.observation(None)["left"], cv2.COLOR_BGR2GRAY).astype(float)
    p = hw_pose(ego).to_vehicle_xy(hw_to_world_xy(lane.position(s, lateral_hw)))
    (u, v), = env.rig.project_vehicle_points(np.array([[p[0], p[1], 0.0]]))[0]
    u, v = int(round(u)), int(round(v))
    assert 1 <= u < grey.shape[1] - 1 and 1 <= v < grey.shape[0] - 1, "the probe point is outside the image"
    return grey[v - 1:v + 2, u - 1:u + 2].mean()


@pytest.fixture(scope="module")
def racetrack_full():
    env = make("racetrack-v0", rig=StereoRig(), config={"other_vehicles": 0})
    env.reset(seed=0)
    return env


def test_racetrack_paints_its_own_line_types(racetrack_full):
    # lane ("a", "b", 0): a solid left edge (highway-env's LineType.CONTINUOUS) and a striped right line
    edge = _paint_grey(racetrack_full, ("a", "b", 0), 2.0, 12.0, -2.5)
    road = _paint_grey(racetrack_full, ("a", "b", 0), 2.0, 12.0, 0.0)
    assert edge > road + 60
    # on a CircularLane (radius 25 m, turning left) the solid outer edge is painted too
    arc = ("b", "c", 1)
    assert _paint_grey(racetrack_full, arc, 1.0, 9.0, 2.5) > _paint_grey(racetrack_full, arc, 1.0, 9.0, 0.0) + 60


def test_racetrack_shared_dashed_line_is_painted(racetrack_full):
    # the dash from s = 12 m to 15 m of the line between lanes ("a", "b", 0) and ("a", "b", 1)
    dash = _paint_grey(racetrack_full, ("a", "b", 0), 2.0, 13.5, 2.5)
    road = _paint_grey(racetrack_full, ("a", "b", 0), 2.0, 13.5, 0.0)
    assert dash > road + 60


def test_bad_use_raises():
    with pytest.raises(ValueError, match="seed must be >= 0"):
        make("highway-v0", seed=-1)
    with pytest.raises(RuntimeError, match="reset"):
        make("highway-v0").observation(None)


def test_the_rear_rig_is_offered_on_request():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        env = StereoObservation(gym.make("highway-v0", config=CONFIGS["highway-v0"]), rig=SMALL, scenery=False,
                                rear=True)
    assert env.rear_rig == rear_rig(SMALL)
    assert set(env.observation_space.spaces) == {"left", "right", "imu", "rear_left", "rear_right"}
    obs, _ = env.reset(seed=0)
    obs, *_ = env.step(ACTIONS["highway-v0"])
    assert env.observation_space.contains(obs)
    assert not np.array_equal(obs["rear_left"], obs["left"]) and not np.array_equal(obs["rear_left"],
                                                                                     obs["rear_right"])
    assert env.last_rear_images.left is obs["rear_left"]
    with pytest.raises(ValueError, match="rear must be True, False or a StereoRig"):
        StereoObservation(gym.make("highway-v0"), rear="yes")
    with pytest.raises(ValueError, match="looks straight back"):
        StereoObservation(gym.make("highway-v0"), rear=SMALL)
