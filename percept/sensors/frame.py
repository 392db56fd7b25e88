"""What the car's sensors deliver at one instant."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import cv2
import numpy as np

FRAME_RATE_HZ = 15
"""Frames a second the cameras deliver, and the simulator's steps a second (highway-env's own frequency) [Hz]."""


def to_gray(image: np.ndarray) -> np.ndarray:
    """(H, W, 3) BGR or (H, W) grey uint8 -> (H, W) grey uint8 (OpenCV's BGR weights; other grey types clipped)."""
    img = np.asarray(image)
    if img.ndim == 3 and img.shape[2] == 3:
        return cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    if img.ndim == 2:
        return img if img.dtype == np.uint8 else np.clip(img, 0, 255).astype(np.uint8)
    raise ValueError(f"expected an (H, W) or (H, W, 3) image, got shape {img.shape}")


def _read_only_gray(image: np.ndarray | None) -> np.ndarray | None:
    if image is None:
        return None
    out = to_gray(image)
    if out is image:
        out = out.view()
    out.flags.writeable = False
    return out


@dataclass(frozen=True)
class ImuSample:
    """One IMU reading in the vehicle frame (x forward, y left, z up).

    accel_mps2: (3,) specific force [m/s^2] (gravity removed: a car at rest on level ground reads ~0);
    gyro_rps: (3,) angular rate [rad/s]; yaw rate is ``gyro_rps[2]``.
    """

    accel_mps2: np.ndarray
    gyro_rps: np.ndarray

    @property
    def yaw_rate_rps(self) -> float:
        return float(self.gyro_rps[2])

    def is_finite(self) -> bool:
        return bool(np.all(np.isfinite(self.accel_mps2)) and np.all(np.isfinite(self.gyro_rps)))


@dataclass(frozen=True)
class Frame:
    """A stereo frame with inertial and wheel data.

    left, right: (H, W, 3) uint8 BGR images, or None when the frame was dropped;
    timestamp_s: time since the run started [s]; index: frame counter;
    imu: IMU sample; wheel_speed_mps: speed from the wheel encoders [m/s];
    rear_left, rear_right: (H, W, 3) uint8 BGR images of the rear-facing rig, or None (no rear rig, or dropped).
    ``left_gray`` / ``right_gray`` (and ``rear_left_gray`` / ``rear_right_gray``): the images in grey, converted on
    first use and then shared by every slot that reads them (read-only; None when dropped).
    """

    index: int
    timestamp_s: float
    left: np.ndarray | None
    right: np.ndarray | None
    imu: ImuSample
    wheel_speed_mps: float
    rear_left: np.ndarray | None = None
    rear_right: np.ndarray | None = None

    @property
    def dropped(self) -> bool:
        return self.left is None or self.right is None

    @property
    def has_rear(self) -> bool:
        """Whether the rear rig's pair is in this frame."""
        return self.rear_left is not None and self.rear_right is not None

    @cached_property
    def left_gray(self) -> np.ndarray | None:
        """(H, W) uint8, read-only: ``left`` in grey, converted once."""
        return _read_only_gray(self.left)

    @cached_property
    def right_gray(self) -> np.ndarray | None:
        """(H, W) uint8, read-only: ``right`` in grey, converted once."""
        return _read_only_gray(self.right)

    def right_gray_or_bgr(self) -> np.ndarray | None:
        """``right_gray`` if a slot has converted it already, else ``right`` as it is: for a reader that needs the
        grey image only now and then (a keyframe, a sign's window) and converts what it reads, so that it shares the
        conversion when there is one but does not pay for a whole image each frame when there is not."""
        return self.__dict__.get("right_gray", self.right)

    @cached_property
    def rear_left_gray(self) -> np.ndarray | None:
        """(H, W) uint8, read-only: ``rear_left`` in grey, converted once."""
        return _read_only_gray(self.rear_left)

    @cached_property
    def rear_right_gray(self) -> np.ndarray | None:
        """(H, W) uint8, read-only: ``rear_right`` in grey, converted once."""
        return _read_only_gray(self.rear_right)
