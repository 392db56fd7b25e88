"""The rear stereo rig, drawn by the forward renderer.

The renderer's ground layer, road paint, scenery view cone and culling all select what lies ahead of the rig along
the vehicle's +x axis. A rig looking back (mount yaw pi, ``mount_x`` behind the centre) sees exactly what a rig
looking forward sees from the ego turned round on the spot: turning the vehicle frame by pi about z maps (x, y) to
(-x, -y), so the mount moves to ``-mount_x`` with yaw 0 and each camera keeps its side (the rear rig's left camera,
at y = -b/2, sits at y' = +b/2 of the turned frame). The same world is drawn: the same road, seed, textures and
scenery, the other vehicles' headlights (their +x faces) towards a rig that looks back at them.
"""

from __future__ import annotations

import math

import numpy as np

from percept.sensors import Pose2D, StereoRig, wrap_angle

from ..road_geometry import RoadGeometry
from .ground import Palette
from .renderer import StereoImages, StereoRenderer
from .scene import Scene


def forward_twin(rig: StereoRig) -> StereoRig:
    """The forward-looking rig (yaw 0, mount at ``-mount_x``) that sees what ``rig`` (yaw pi) sees, from the ego
    turned round (``turned``); ValueError for a rig that does not look straight back."""
    if not abs(wrap_angle(rig.yaw_rad - math.pi)) < 1e-9:
        raise ValueError(f"a rear rig looks straight back (yaw_rad pi), got yaw_rad {rig.yaw_rad}")
    return StereoRig(rig.camera, rig.baseline_m, rig.mount_height_m, rig.pitch_rad, -rig.mount_x_m)


def turned(scene: Scene) -> Scene:
    """``scene`` with the ego turned round on the spot: the same place, heading + pi (wrapped to (-pi, pi])."""
    e = scene.ego
    return Scene(Pose2D(e.x_m, e.y_m, float(wrap_angle(e.yaw_rad + math.pi))), scene.objects)


class RearRenderer:
    """Renders a rear rig's (yaw pi) pair, left depth, ids and boxes with a ``StereoRenderer`` of its forward twin
    from the turned ego; the images are those of the rear rig's left and right cameras. Same arguments as
    ``StereoRenderer``."""

    def __init__(self, rig: StereoRig, road: RoadGeometry, seed: int = 0, palette: Palette = Palette(),
                 scenery: bool = True, signs_xy: np.ndarray | None = None):
        self.rig = rig
        self.view = StereoRenderer(forward_twin(rig), road, seed, palette, scenery, signs_xy)

    def render(self, scene: Scene, emission: bool = True, depth: bool = True) -> StereoImages:
        """The rear pair of ``scene`` (the ego's true pose): ``StereoRenderer.render`` of the turned scene."""
        return self.view.render(turned(scene), emission, depth)
