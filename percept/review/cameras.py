"""A rig's left camera in the recording: its mount and pinhole (static), its image stored at the recording options'
rate, scale and JPEG quality, and the true boxes of the objects on it. The forward rig's camera is
``world/ego/camera/left``; the rear rig's, when the car has one, ``world/ego/camera/rear_left``. Each is an entity
of its own under the ego, so a 2D view shows it with what the parts draw on it."""

from __future__ import annotations

import math

import cv2
import numpy as np
import rerun as rr

from percept.sensors import ObjectKind, Side, StereoRig

from .context import RecordOptions
from .series import ColumnBuffer

KIND_CLASSES = {ObjectKind.VEHICLE: (1, (70, 130, 230)), ObjectKind.PEDESTRIAN: (2, (240, 80, 60)),
                ObjectKind.LANDMARK: (3, (250, 220, 60))}
"""Class id and RGB of each object kind (the annotation context at ``world``)."""


class CameraStore:
    """One rig's left camera: ``path`` its entity, ``rig`` the rig, ``options`` what is stored, ``box_attr`` the
    ObjectTruth field holding an object's box in this camera (``box_px`` forward, ``rear_box_px`` rear)."""

    def __init__(self, path: str, rig: StereoRig, options: RecordOptions, box_attr: str = "box_px"):
        self.path, self.rig, self.options, self.box_attr = path, rig, options, box_attr
        self._bucket: int | None = None

    def log_static(self, rec: rr.RecordingStream) -> None:
        """The camera's mount and its pinhole at the stored image's scale."""
        rig, s = self.rig, self.options.image_scale
        # camera mount: vehicle_from_camera rotation is the transpose of cam_from_vehicle
        rec.log(self.path, rr.Transform3D(translation=rig.camera_position(Side.LEFT),
                                          mat3x3=rig.rotation_cam_from_vehicle().T), static=True)
        cam = rig.camera
        rec.log(self.path, rr.Pinhole(focal_length=[cam.fx * s, cam.fy * s], principal_point=[cam.cx * s, cam.cy * s],
                                      resolution=[round(cam.width * s), round(cam.height * s)],
                                      camera_xyz=rr.ViewCoordinates.RDF, image_plane_distance=2.0), static=True)

    def store(self, rec: rr.RecordingStream, timestamp_s: float, image: np.ndarray | None) -> bool:
        """Store ``image`` (BGR, or None: nothing) if ``timestamp_s`` [s] starts a new 1 / camera_hz interval;
        whether it was stored."""
        bucket = math.floor(timestamp_s * self.options.camera_hz + 1e-6)
        if image is None or bucket == self._bucket:
            return False
        img, s = image, self.options.image_scale
        if s != 1:
            h, w = img.shape[:2]
            img = cv2.resize(img, (round(w * s), round(h * s)), interpolation=cv2.INTER_AREA)
        ok, jpg = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, int(self.options.jpeg_quality)])
        if not ok:
            return False
        rec.log(self.path, rr.EncodedImage(contents=jpg.tobytes(), media_type="image/jpeg"))
        self._bucket = bucket
        return True

    def log_boxes(self, rec: rr.RecordingStream, buffer: ColumnBuffer, objects) -> None:
        """The true boxes of ``objects`` (ObjectTruth) this camera sees, on its stored image (none: cleared)."""
        seen = [(getattr(o, self.box_attr), o.kind) for o in objects if getattr(o, self.box_attr) is not None]
        if seen:
            rec.log(f"{self.path}/objects", rr.Boxes2D(
                array=np.asarray([box for box, _ in seen], dtype=float) * self.options.image_scale,
                array_format=rr.Box2DFormat.XYXY, class_ids=[KIND_CLASSES[kind][0] for _, kind in seen],
                show_labels=False))
        else:
            buffer.clear(f"{self.path}/objects")
