"""Records passed out of the lanes module."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from percept.sensors.records import LaneEstimate


@dataclass(frozen=True)
class MarkingEvidence:
    """Marking pixels mapped to the ground. points_m: (N, 2) vehicle-frame (x, y) [m]; strength: (N,) top-hat
    response; uv_px: (N, 2) where they are in the image (u, v); weight: (N,) how much independent image evidence
    each point carries, 0..1 (far grid rows re-sample the same image rows, and a far pixel spans more ground);
    None = all 1; vehicles: the ``vehicles.VehicleBox`` es whose evidence was dropped (footage only)."""

    points_m: np.ndarray
    strength: np.ndarray
    uv_px: np.ndarray
    weight: np.ndarray | None = None
    vehicles: tuple = ()


@dataclass(frozen=True)
class LaneFit:
    """One frame's robust fit. estimate: the fitted lane (confidence from support and ambiguity); side: (N,) +1 left,
    -1 right, 0 outlier, per evidence point; residual_m: RMS residual of the inliers [m]; cov: (5, 5)
    covariance of (offset, heading, curvature, curvature_rate, width) from the least-squares normal equations;
    ambiguity: the support of the best rival lane (other boundaries, also about the car) as a share of both, 0..0.5
    (0: no rival); broken: whether each boundary's paint is a broken line (``line_kind``)."""

    estimate: LaneEstimate
    side: np.ndarray
    residual_m: float
    inliers_left: int
    inliers_right: int
    cov: np.ndarray
    ambiguity: float = 0.0
    broken: tuple = (None, None)  # (left, right): each boundary's paint broken (True), solid (False) or not known
    # (None), ``line_kind.line_kind`` of its inlier points
