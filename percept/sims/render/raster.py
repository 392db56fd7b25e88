"""Z-buffered rasterisation of planar patches for the stereo renderer.

A patch is a planar polygon ``{o + s e1 + t e2 : (s, t) in outline}`` with ``(s, t)`` in the unit
square (a quad, an ellipse, …). Depth is exact per pixel: for the plane ``n·X = d`` (camera frame)
and the pixel ray ``r = K^-1 (u, v, 1)``, the depth is ``Z = d / (n·r)``. Textures are mapped with
the plane homography ``H = K [e1/w, e2/h, o]`` (Hartley & Zisserman, sec. 8.1).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from percept.sensors import PinholeCamera, Transform

NEAR_M = 0.3
"""Near clipping plane [m]: geometry closer to the camera than this is cut away."""

QUAD = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_phi = np.linspace(0.0, 2 * np.pi, 20, endpoint=False)
ELLIPSE = np.column_stack([0.5 + 0.5 * np.cos(_phi), 0.5 + 0.5 * np.sin(_phi)])
OUTLINES = [QUAD, ELLIPSE]
"""Outline index 0: quad, 1: ellipse inscribed in the quad."""


@dataclass
class PatchBatch:
    """Planar patches in the world frame, struct-of-arrays. P patches.

    origin, e1, e2: (P, 3) [m]; color: (P, 3) BGR 0..255 before shading; texture: (P,) index into the
    renderer's texture bank, -1 for none; outline: (P,) index into OUTLINES; obj_id: (P,) object id
    (0 for scenery); two_sided: (P,) bool, False = culled when seen from the back (e1 x e2 points out);
    shade: (P,) bool, False = emissive (lights, sign faces keep their colour).
    """

    origin: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    color: np.ndarray
    texture: np.ndarray
    outline: np.ndarray
    obj_id: np.ndarray
    two_sided: np.ndarray
    shade: np.ndarray

    @staticmethod
    def empty() -> "PatchBatch":
        z3 = np.zeros((0, 3))
        zi = np.zeros(0, dtype=np.int32)
        zb = np.zeros(0, dtype=bool)
        return PatchBatch(z3, z3, z3, z3, zi, zi, zi, zb, zb)

    def __len__(self) -> int:
        return len(self.origin)

    @staticmethod
    def concat(batches: list["PatchBatch"]) -> "PatchBatch":
        batches = [b for b in batches if len(b)]
        if not batches:
            return PatchBatch.empty()
        return PatchBatch(*[np.concatenate([getattr(b, f) for b in batches]) for f in PatchBatch.__dataclass_fields__])


class PatchBuilder:
    """Accumulates patches one by one (readable model code), then packs them into a PatchBatch."""

    def __init__(self) -> None:
        self._rows: list[tuple] = []

    def add(self, origin, e1, e2, color, *, texture: int = -1, outline: int = 0, obj_id: int = 0,
            two_sided: bool = False, shade: bool = True) -> None:
        self._rows.append((origin, e1, e2, color, texture, outline, obj_id, two_sided, shade))

    def box(self, center, axes, size, color, *, texture: int = -1, obj_id: int = 0, bottom: bool = False,
            shade: bool = True) -> None:
        """Axis-aligned box in its own frame: center (3,), axes (3, 3) rows = unit x, y, z, size (3,) [m].

        Faces are oriented so that e1 x e2 points outwards (for back-face culling).
        """
        c = np.asarray(center, dtype=np.float64)
        ax = np.asarray(axes, dtype=np.float64)
        hx, hy, hz = (np.asarray(size, dtype=np.float64) / 2)[:, None] * ax
        faces = [
            (c + hx - hy - hz, 2 * hy, 2 * hz),  # front (+x)
            (c - hx + hy - hz, -2 * hy, 2 * hz),  # back (-x)
            (c + hx + hy - hz, -2 * hx, 2 * hz),  # left (+y)
            (c - hx - hy - hz, 2 * hx, 2 * hz),  # right (-y)
            (c - hx - hy + hz, 2 * hx, 2 * hy),  # top (+z)
        ]
        if bottom:
            faces.append((c - hx + hy - hz, 2 * hx, -2 * hy))
        for o, a, b in faces:
            self.add(o, a, b, color, texture=texture, obj_id=obj_id, shade=shade)

    def build(self) -> PatchBatch:
        if not self._rows:
            return PatchBatch.empty()
        cols = list(zip(*self._rows))
        return PatchBatch(
            np.asarray(cols[0], dtype=np.float64).reshape(-1, 3),
            np.asarray(cols[1], dtype=np.float64).reshape(-1, 3),
            np.asarray(cols[2], dtype=np.float64).reshape(-1, 3),
            np.asarray(cols[3], dtype=np.float64).reshape(-1, 3),
            np.asarray(cols[4], dtype=np.int32),
            np.asarray(cols[5], dtype=np.int32),
            np.asarray(cols[6], dtype=np.int32),
            np.asarray(cols[7], dtype=bool),
            np.asarray(cols[8], dtype=bool),
        )


@dataclass
class RenderTarget:
    """What one camera's rasteriser writes. image: (H, W, 3) uint8 BGR; depth: (H, W) float32 camera z [m]
    (inf where nothing is); ids: (H, W) int32 object id per pixel (0 = road or scenery, -1 = sky)."""

    image: np.ndarray
    depth: np.ndarray
    ids: np.ndarray
    pieces: dict[int, list] = field(default_factory=dict)
    """Per object id, its patches' masks (x0, y0, mask) before the z-test: the silhouette without occluders."""

    def silhouette_px(self, obj_id: int) -> int:
        """Pixels the object would cover inside the image if nothing occluded it."""
        parts = self.pieces.get(obj_id)
        if not parts:
            return 0
        x0 = min(p[0] for p in parts)
        y0 = min(p[1] for p in parts)
        x1 = max(p[0] + p[2].shape[1] for p in parts)
        y1 = max(p[1] + p[2].shape[0] for p in parts)
        union = np.zeros((y1 - y0, x1 - x0), bool)
        for px, py, m in parts:
            union[py - y0:py - y0 + m.shape[0], px - x0:px - x0 + m.shape[1]] |= m
        return int(union.sum())


def clip_near(points: np.ndarray, near: float = NEAR_M) -> np.ndarray:
    """Sutherland–Hodgman clip of a polygon (M, 3), camera frame, against the plane z = near."""
    out = []
    n = len(points)
    for i in range(n):
        a, b = points[i], points[(i + 1) % n]
        ina, inb = a[2] >= near, b[2] >= near
        if ina:
            out.append(a)
        if ina != inb:
            # point on segment a + t (b - a) where z = near
            t = (near - a[2]) / (b[2] - a[2])
            out.append(a + t * (b - a))
    return np.asarray(out).reshape(-1, 3)


def rasterize(target: RenderTarget, batch: PatchBatch, cam: PinholeCamera, cam_from_world: Transform,
              textures: list[np.ndarray], sun_dir_world: np.ndarray, ambient: float = 0.55) -> None:
    """Draw ``batch`` into ``target`` with a z-test; camera pose ``cam_from_world``."""
    if not len(batch):
        return
    R, t = cam_from_world.R, cam_from_world.t
    O = batch.origin @ R.T + t
    E1 = batch.e1 @ R.T
    E2 = batch.e2 @ R.T
    N = np.cross(E1, E2)
    # back-face test: a face is seen from the front when n·(o - camera) < 0, the camera being the origin
    front = np.einsum("ij,ij->i", N, O) < 0
    keep = front | batch.two_sided
    # coarse frustum test on the parallelogram corners
    corners = np.stack([O, O + E1, O + E2, O + E1 + E2], axis=1)  # (P, 4, 3)
    zmax = corners[..., 2].max(axis=1)
    keep &= zmax > NEAR_M
    # shading in the world frame: ambient + diffuse * max(0, n·sun)
    nw = np.cross(batch.e1, batch.e2)
    nw /= np.linalg.norm(nw, axis=1, keepdims=True) + 1e-12
    lam = np.abs(nw @ sun_dir_world)
    shade = np.where(batch.shade, ambient + (1.0 - ambient) * lam, 1.0)
    colors = np.clip(batch.color * shade[:, None], 0, 255)
    # draw far to near so that the z-test rejects as early as possible is not needed; any order is exact
    H, W = target.depth.shape
    fx, fy, cx, cy = cam.fx, cam.fy, cam.cx, cam.cy
    K = cam.K
    for i in np.flatnonzero(keep):
        st = OUTLINES[batch.outline[i]]
        pts = O[i] + st[:, :1] * E1[i] + st[:, 1:] * E2[i]
        if pts[:, 2].min() < NEAR_M:
            pts = clip_near(pts)
            if len(pts) < 3:
                continue
        u = fx * pts[:, 0] / pts[:, 2] + cx
        v = fy * pts[:, 1] / pts[:, 2] + cy
        x0, x1 = max(int(np.floor(u.min())), 0), min(int(np.ceil(u.max())) + 1, W)
        y0, y1 = max(int(np.floor(v.min())), 0), min(int(np.ceil(v.max())) + 1, H)
        if x1 <= x0 or y1 <= y0:
            continue
        bw, bh = x1 - x0, y1 - y0
        mask = np.zeros((bh, bw), np.uint8)
        poly = np.round(np.column_stack([u - x0, v - y0]) * 16).astype(np.int32)
        cv2.fillPoly(mask, [poly], 1, lineType=cv2.LINE_8, shift=4)
        n = N[i]
        d = float(n @ O[i])
        # Z(u, v) = d / (n · ((u - cx)/fx, (v - cy)/fy, 1))
        denom = (n[0] / fx) * (np.arange(x0, x1) - cx)[None, :] + ((n[1] / fy) * (np.arange(y0, y1) - cy) + n[2])[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            Z = (d / denom).astype(np.float32)
        zpatch = target.depth[y0:y1, x0:x1]
        inside = mask.view(bool) & (Z > NEAR_M * 0.5)
        oid = int(batch.obj_id[i])
        if oid > 0:
            target.pieces.setdefault(oid, []).append((x0, y0, inside))
        vis = inside & (Z < zpatch)
        if not vis.any():
            continue
        tex_id = batch.texture[i]
        ipatch = target.image[y0:y1, x0:x1]
        if tex_id >= 0:
            tex = textures[tex_id]
            th, tw = tex.shape[:2]
            # texture pixel (i, j) -> point o + (i/w) e1 + (j/h) e2 -> image; then shift to the bbox
            Ht = K @ np.column_stack([E1[i] / tw, E2[i] / th, O[i]])
            Ht = np.array([[1, 0, -x0], [0, 1, -y0], [0, 0, 1.0]]) @ Ht
            warped = cv2.warpPerspective(tex, Ht, (bw, bh), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_WRAP)
            col = (warped[vis].astype(np.float32)[:, None] * (colors[i] / 255.0)).astype(np.uint8)
            ipatch[vis] = col
        else:
            ipatch[vis] = colors[i].astype(np.uint8)
        zpatch[vis] = Z[vis]
        target.ids[y0:y1, x0:x1][vis] = oid
