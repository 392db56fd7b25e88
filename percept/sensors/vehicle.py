"""Constants that several packages must agree on, each defined once: the ego's size, the command limits and the
landmark signs' geometry. ``tests/sensors/test_vehicle.py`` checks them against highway-env's own classes.

Vehicle frame: ISO 8855 (x forward, y left, z up), origin on the ground below the vehicle centre.
"""

from __future__ import annotations

EGO_LENGTH_M = 5.0
"""Body length [m] (highway-env ``Vehicle.LENGTH``)."""
EGO_WIDTH_M = 2.0
"""Body width [m] (highway-env ``Vehicle.WIDTH``)."""
WHEELBASE_M = 5.0
"""highway-env's kinematic bicycle integrates heading with the body length as its wheelbase [m]."""
CAMERA_MOUNT_X_M = 0.8
"""The stereo rig sits this far ahead of the vehicle centre [m] (``StereoRig.mount_x_m``'s default)."""
ACCEL_RANGE_MPS2 = (-8.0, 4.0)
"""What the simulated car can do: braking down to -8 m/s² (highway-env's default stops at -5), up to +4 m/s²."""
MAX_BRAKE_MPS2 = -ACCEL_RANGE_MPS2[0]
"""The strongest deceleration a law may command [m/s², positive number]."""
STEER_RANGE_RAD = (-0.5, 0.5)
"""Front-wheel angle limits [rad]."""

SIGN_PANEL_SIZE_M = 0.9
"""Side of a landmark sign's square panel [m]; its face carries the ArUco marker."""
SIGN_PANEL_BOTTOM_M = 1.6
"""Height of the panel's lower edge above the road [m]."""
SIGN_PANEL_CENTRE_M = round(SIGN_PANEL_BOTTOM_M + SIGN_PANEL_SIZE_M / 2, 9)
"""Height of the panel centre above the road [m]: where the landmark map puts a sign."""


def bumper_gap_m(range_m: float, camera_mount_x_m: float = CAMERA_MOUNT_X_M) -> float:
    """Free distance from the ego's front bumper to something ``range_m`` ahead of the camera [m], at least 0."""
    # the bumper is half a body length ahead of the centre, the camera mount_x ahead of it
    return max(range_m - (EGO_LENGTH_M / 2 - camera_mount_x_m), 0.0)
