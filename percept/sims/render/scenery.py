"""Static roadside clutter built once per scenario: guard rails, lamp poles, trees and buildings.

They give stereo matching and visual odometry texture at every depth. Props are placed along the
outer road edges at seeded random offsets, never on a paved surface (checked on a 1 m grid).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ..road_geometry import RoadGeometry
from .patches import PatchBatch, PatchBuilder

RAIL = (175, 178, 180)
POLE = (140, 140, 145)
TRUNK = (40, 60, 80)
CANOPIES = [(40, 95, 55), (35, 80, 45), (50, 110, 70)]
WALLS = [(170, 185, 200), (150, 160, 175), (190, 195, 200), (120, 140, 170), (160, 150, 140)]


@dataclass(frozen=True)
class SceneryTextures:
    """Indices into the renderer's texture bank."""

    panel: int
    foliage: int
    facades: tuple[int, ...]


class _RoadGrid:
    """Paved area rasterised on a 1 m grid, to keep props off the road."""

    def __init__(self, road: RoadGeometry, margin_m: float = 1.5):
        edges = [np.concatenate([s.left, s.right]) for s in road.strips]
        pts = np.concatenate(edges) if edges else np.zeros((1, 2))
        self.lo = pts.min(axis=0) - 80.0
        hi = pts.max(axis=0) + 80.0
        w, h = (hi - self.lo).astype(int) + 1
        self.grid = np.zeros((h, w), np.uint8)
        for s in road.strips:
            poly = np.concatenate([s.left, s.right[::-1]]) - self.lo
            cv2.fillPoly(self.grid, [np.round(poly).astype(np.int32)], 1)
        k = int(2 * margin_m) + 1
        self.grid = cv2.dilate(self.grid, np.ones((k, k), np.uint8))

    def free(self, xy: np.ndarray, radius_m: float) -> bool:
        c = np.round(xy - self.lo).astype(int)
        r = int(np.ceil(radius_m))
        y0, y1 = max(c[1] - r, 0), min(c[1] + r + 1, self.grid.shape[0])
        x0, x1 = max(c[0] - r, 0), min(c[0] + r + 1, self.grid.shape[1])
        return not self.grid[y0:y1, x0:x1].any()


def _frame(p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """Axes (3, 3): along p0->p1, its left normal, up."""
    d = np.append(p1 - p0, 0.0)
    d /= np.linalg.norm(d) + 1e-12
    return np.array([d, [-d[1], d[0], 0.0], [0.0, 0.0, 1.0]])


def straight_runs(line: np.ndarray, step: int = 4, tol_m: float = 0.015,
                  max_len_m: float = 64.0) -> list[tuple[int, int]]:
    """Split a polyline (N, 2) into pieces (i, j) of whole ``step`` sample runs, each as long as it stays
    within ``tol_m`` of its chord (so a straight road's guard rail is a few long patches, a curve's many)."""
    n = len(line)
    out = []
    i = 0
    while i + step <= n - 1:
        j = i + step
        while j + step <= n - 1:
            k = j + step
            a, b = line[i], line[k]
            d = b - a
            L = float(np.hypot(*d))
            if L > max_len_m:
                break
            # distance of the samples between a and b from the chord: |cross(d, p - a)| / |d|
            p = line[i:k + 1] - a
            if np.abs(d[0] * p[:, 1] - d[1] * p[:, 0]).max() / (L + 1e-12) > tol_m:
                break
            j = k
        out.append((i, j))
        i = j
    return out


def _tree(b: PatchBuilder, rng: np.random.Generator, c: np.ndarray, r: float, ax: np.ndarray,
          tex: SceneryTextures) -> None:
    """A trunk (four sides) under two crossed, two-sided elliptical canopies."""
    trunk_h = float(rng.uniform(1.5, 3.0))
    col = CANOPIES[int(rng.integers(len(CANOPIES)))]
    canopy_h = float(rng.uniform(2.5, 5.0))
    top = trunk_h + 0.35 * canopy_h
    b.box(np.append(c, top / 2), ax, (0.35, 0.35, top), TRUNK, texture=tex.panel, faces="fblr")
    centre = np.append(c, trunk_h + canopy_h / 2)
    up = np.array([0.0, 0.0, canopy_h])
    for k in (0, 1):
        e1 = 2 * r * ax[k]
        b.add(centre - e1 / 2 - up / 2, e1, up, col, texture=tex.foliage, outline=1, two_sided=True,
              repeat=(max(1.0, r / 1.5), max(1.0, canopy_h / 3.0)))


SIGN_CLEAR_M = 20.0
"""No lamp pole stands within this distance of a landmark sign [m]: as on a real road, nothing is put in front of
a sign (poles every 40 m would otherwise hide every sign on one side of a road whenever the two spacings line up)."""


def build_scenery(road: RoadGeometry, seed: int, tex: SceneryTextures,
                  signs_xy: np.ndarray | None = None) -> PatchBatch:
    """signs_xy: (N, 2) world positions of landmark signs to keep clear of lamp poles [m]."""
    rng = np.random.default_rng(seed + 7919)
    signs = np.zeros((0, 2)) if signs_xy is None else np.asarray(signs_xy, float).reshape(-1, 2)
    grid = _RoadGrid(road)
    b = PatchBuilder()
    for edge, outward in road.edges:
        n = len(edge)
        if n < 2:
            continue
        seg = np.diff(edge, axis=0)
        normal = np.column_stack([-seg[:, 1], seg[:, 0]]) * outward
        normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-12
        normal = np.vstack([normal, normal[-1:]])
        # guard rail: 0.32 m tall beam, 0.6 m outside the paved edge, merged where the edge is straight
        rail = edge + 0.6 * normal
        for i, j in straight_runs(rail):
            p0, p1 = rail[i], rail[j]
            length = float(np.hypot(*(p1 - p0)))
            b.add(np.append(p0, 0.45), np.append(p1 - p0, 0.0), np.array([0, 0, 0.32]), RAIL, texture=tex.panel,
                  two_sided=True, repeat=(max(1.0, round(length / 4.0)), 1.0))
        # rail posts every 4 m
        for i in range(0, n - 4, 4):
            b.box(np.append(rail[i], 0.3), _frame(rail[i], rail[i + 4]), (0.1, 0.1, 0.6), POLE, faces="fblr")
        # lamp poles every 40 m, 2.5 m out
        for i in range(int(rng.integers(0, 40)), n, 40):
            c = edge[i] + 2.5 * normal[i]
            if len(signs) and np.min(np.hypot(*(signs - c).T)) < SIGN_CLEAR_M:
                continue
            b.box(np.append(c, 4.0), _frame(edge[max(i - 1, 0)], edge[min(i + 1, n - 1)]), (0.18, 0.18, 8.0), POLE,
                  texture=tex.panel, faces="fblr")
        # trees: clusters 6-25 m out
        i = int(rng.integers(0, 10))
        while i < n:
            off = float(rng.uniform(6.0, 25.0))
            c = edge[i] + off * normal[i] + rng.normal(0, 1.0, 2)
            r = float(rng.uniform(1.5, 3.0))
            if grid.free(c, r + 1):
                _tree(b, rng, c, r, _frame(edge[max(i - 1, 0)], edge[min(i + 1, n - 1)]), tex)
            i += int(rng.integers(6, 18))
        # buildings: 30-70 m out, every 35-80 m
        i = int(rng.integers(0, 30))
        while i < n:
            off = float(rng.uniform(30.0, 70.0))
            size = rng.uniform([10.0, 8.0, 6.0], [28.0, 18.0, 22.0])
            c = edge[i] + (off + size[1] / 2) * normal[i]
            if grid.free(c, max(size[0], size[1]) / 2 + 2):
                ax = _frame(edge[max(i - 1, 0)], edge[min(i + 1, n - 1)])
                wall = WALLS[int(rng.integers(len(WALLS)))]
                facade = tex.facades[int(rng.integers(len(tex.facades)))]
                b.box(np.append(c, size[2] / 2), ax, size, wall, texture=facade)
            i += int(rng.integers(35, 80))
    return b.build()
