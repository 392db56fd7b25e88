"""Stereo rig: two identical rectified pinhole cameras on a car.

The rig is centred on the vehicle's x axis, ``mount_x_m`` ahead of the vehicle centre and
``mount_height_m`` above the road; both cameras look along the mount's yaw ``yaw_rad`` (0: forward, pi: back),
pitched down by ``pitch_rad``, the left camera ``baseline/2`` to the left of the mount as the cameras see it
(vehicle frame, y left: a forward rig's left camera at y = +baseline/2, a rear rig's at y = -baseline/2).
Reference: Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., sec. 8.1 (homography of a plane).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path

import numpy as np

from .camera import PinholeCamera
from .poses import Transform


class Side(str, Enum):
    LEFT = "left"
    RIGHT = "right"


def _read_only(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


def _default_camera() -> PinholeCamera:
    return PinholeCamera.from_hfov(640, 480, math.radians(60.0))


@dataclass(frozen=True)
class StereoRig:
    """Where the two cameras sit on the car and what they see (see the module docstring)."""

    camera: PinholeCamera = field(default_factory=_default_camera)  # intrinsics shared by both cameras
    baseline_m: float = 0.54  # distance between the optical centres [m]
    mount_height_m: float = 1.4  # the optical centres' height above the road [m]
    pitch_rad: float = 0.0  # positive looks down [rad]
    mount_x_m: float = 0.8  # how far ahead of the vehicle centre the cameras sit [m] (negative: behind it)
    yaw_rad: float = 0.0  # where the cameras look, from the vehicle's x axis (+ left) [rad]: 0 forward, pi back

    def __post_init__(self) -> None:
        if not self.baseline_m > 0:
            raise ValueError(f"baseline_m must be positive, got {self.baseline_m}")
        if not self.mount_height_m > 0:
            raise ValueError(f"mount_height_m must be positive, got {self.mount_height_m}")
        if not math.isfinite(self.yaw_rad):
            raise ValueError(f"yaw_rad must be finite, got {self.yaw_rad}")
        if not abs(self.pitch_rad) < 0.5:
            raise ValueError(f"pitch_rad {self.pitch_rad} is outside (-0.5, 0.5)")
        # the frame changes and ground homographies of both cameras, computed once (read-only: callers share them)
        cache = {}
        R = _read_only(self.rotation_cam_from_vehicle())
        for side in Side:
            T = Transform(R, _read_only(-R @ self.camera_position(side)))
            # (u, v, 1) ~ K [r1 r2 t] (x, y, 1) for points with z_v = 0
            H = self.camera.K @ np.column_stack([T.R[:, 0], T.R[:, 1], T.t])
            cache[side] = (T, _read_only(H), _read_only(np.linalg.inv(H)), T.inverse())
        object.__setattr__(self, "_frames", cache)

    def camera_position(self, side: Side = Side.LEFT) -> np.ndarray:
        """Optical centre in the vehicle frame (3,) [m]."""
        half = self.baseline_m / 2 if Side(side) is Side.LEFT else -self.baseline_m / 2
        # the cameras' left, (-sin yaw, cos yaw), times half the baseline from the mount
        return np.array([self.mount_x_m - half * math.sin(self.yaw_rad), half * math.cos(self.yaw_rad),
                         self.mount_height_m])

    def rotation_cam_from_vehicle(self) -> np.ndarray:
        """3x3 rotation taking vehicle-frame directions (x fwd, y left, z up) to camera (x right, y down, z fwd)."""
        # axes swap at zero pitch: x_c = -y_v, y_c = -z_v, z_c = x_v
        r0 = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
        c, s = math.cos(self.pitch_rad), math.sin(self.pitch_rad)
        # pitch down by theta = rotation about the camera x axis
        rx = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
        if not self.yaw_rad:
            return rx @ r0
        # a mount turned by yaw sees vehicle directions turned by -yaw: R = Rx(pitch) R0 Rz(-yaw)
        cy, sy = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        rz = np.array([[cy, sy, 0.0], [-sy, cy, 0.0], [0.0, 0.0, 1.0]])
        return rx @ r0 @ rz

    def cam_from_vehicle(self, side: Side = Side.LEFT) -> Transform:
        """Vehicle frame -> camera frame of ``side``: p_c = R (p_v - c) (read-only arrays)."""
        return self._frames[Side(side)][0]

    def vehicle_from_cam(self, side: Side = Side.LEFT) -> Transform:
        """Camera frame of ``side`` -> vehicle frame: p_v = R^T p_c + c."""
        return self._frames[Side(side)][3]

    @property
    def looks_back(self) -> bool:
        """Whether the cameras look more backwards than forwards (a rear rig)."""
        return math.cos(self.yaw_rad) < 0

    def ground_homography(self, side: Side = Side.LEFT) -> np.ndarray:
        """3x3 H taking ground points (x_v, y_v, 1) of the vehicle frame (z = 0) to pixels (u, v, 1) (read-only)."""
        return self._frames[Side(side)][1]

    def image_to_ground(self, uv: np.ndarray, side: Side = Side.LEFT) -> np.ndarray:
        """Pixels (N, 2) -> vehicle-frame ground points (N, 2) [m]; rows above the horizon give garbage."""
        Hinv = self._frames[Side(side)][2]
        p = np.column_stack([np.asarray(uv, dtype=np.float64), np.ones(len(uv))]) @ Hinv.T
        return p[:, :2] / p[:, 2:3]

    def project_vehicle_points(self, points_v: np.ndarray, side: Side = Side.LEFT) -> tuple[np.ndarray, np.ndarray]:
        """Vehicle-frame points (N, 3) -> pixels (N, 2) and camera depth z (N,) [m]."""
        pc = self.cam_from_vehicle(side).apply(np.asarray(points_v, dtype=np.float64).reshape(-1, 3))
        return self.camera.project(pc), pc[:, 2]

    @property
    def horizon_row(self) -> float:
        """Image row of the horizon (points at infinity on the ground plane) [px]."""
        # a direction (1, 0, 0) in the vehicle frame -> camera (0, -sin p, cos p)
        return self.camera.cy - self.camera.fy * math.tan(self.pitch_rad)

    def disparity_px(self, depth_m: np.ndarray | float) -> np.ndarray | float:
        """Disparity of a point at camera depth z: d = f b / z [px]."""
        return self.camera.fx * self.baseline_m / np.asarray(depth_m)

    def to_dict(self) -> dict:
        d = self.camera.to_dict()
        d.update(baseline_m=self.baseline_m, mount_height_m=self.mount_height_m, pitch_rad=self.pitch_rad,
                 mount_x_m=self.mount_x_m)
        if self.yaw_rad:
            d["yaw_rad"] = self.yaw_rad
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "StereoRig":
        cam = PinholeCamera(float(d["fx"]), float(d["fy"]), float(d["cx"]), float(d["cy"]), int(d["width"]),
                            int(d["height"]))
        return cls(cam, float(d["baseline_m"]), float(d["mount_height_m"]), float(d.get("pitch_rad", 0.0)),
                   float(d.get("mount_x_m", 0.8)), float(d.get("yaw_rad", 0.0)))

    def save(self, path: Path) -> None:
        """camera.json, written atomically (temporary file, then rename)."""
        from percept.outputs import write_json_atomic

        write_json_atomic(Path(path), self.to_dict())

    @classmethod
    def load(cls, path: Path) -> "StereoRig":
        try:
            return cls.from_dict(json.loads(Path(path).read_text()))
        except FileNotFoundError:
            raise ValueError(f"camera file {path} does not exist") from None
        except (KeyError, json.JSONDecodeError, TypeError) as e:
            raise ValueError(f"camera file {path} is not a percept camera.json ({e})") from None


REAR_MOUNT_X_M = -2.5
"""Where the rear rig sits: at the rear bumper of a 5 m car, its centre 2.5 m behind the vehicle centre [m]."""


def rear_rig(front: StereoRig) -> StereoRig:
    """The rear-facing rig paired with ``front``: the same cameras and baseline, at the rear bumper, 1.0 m up (where
    a reversing camera sits), looking back (yaw pi)."""
    return StereoRig(front.camera, front.baseline_m, 1.0, front.pitch_rad, REAR_MOUNT_X_M, math.pi)
