"""Z-buffered rasterisation of planar patches for the stereo renderer.

A patch is a planar polygon ``{o + s e1 + t e2 : (s, t) in outline}`` with ``(s, t)`` in the unit
square (a quad or the ellipse inscribed in it). With the camera-frame matrix ``A = K [e1 e2 o]``
(the plane homography, Hartley & Zisserman, sec. 8.1), a pixel ``(u, v)`` sees the plane point

    (s/Z, t/Z, 1/Z) = A^-1 (u, v, 1)

so the inverse depth ``1/Z`` and the texture coordinates are affine in ``(u, v)`` up to one division.
Depth is exact per pixel, the inside test is exact at pixel centres (quad: ``0 <= s, t <= 1``; ellipse:
``(s - 1/2)^2 + (t - 1/2)^2 <= 1/4``), and the nearest plane wins (largest ``1/Z``).

Patches are culled and prepared in one vectorised pass (back faces, near plane, image bounds, level of
detail, texture mip level); ``fragments.py`` then fills them row span by row span: large patches one by
one over their bounding box with OpenCV texture warps, small ones all at once as per-pixel fragments
shaded from a mip-mapped texture atlas.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from percept.compiled import optional
from percept.sensors import PinholeCamera, Transform

from .cull import inverse_rows, project_patches
from .fragments import NEAR_M, PreparedPatches, WinnerMap, rasterize_prepared
from .patches import ELLIPSE, OUTLINES, QUAD, PatchBatch, PatchBuilder
from .pixels import silhouette_stats
from .textures import TextureAtlas
from .vec3 import cross, dot

__all__ = ["ELLIPSE", "LOD_PX", "NEAR_M", "OUTLINES", "QUAD", "PatchBatch", "PatchBuilder", "RenderTarget",
           "prepare", "rasterize", "warm_up"]

LOD_PX = 0.5
"""Scenery patches narrower than this on screen [px] are skipped."""


@dataclass
class RenderTarget:
    """What one camera's rasteriser writes. image: (H, W, 3) uint8 BGR; depth: (H, W) float32 camera z [m]
    (inf where nothing is) or None to skip; ids: (H, W) int32 object id per pixel (0 = road or scenery,
    -1 = sky) or None to skip; inv_depth: (H, W) float32 1/z, the z-buffer (None: derived from depth);
    base_inv_depth: what inv_depth held before any patch (None: a copy is taken), to find the pixels
    patches were drawn on; emission: (H, W) float32, the fraction of each pixel a lamp covers (untextured,
    unshaded patches: vehicles' lights), or None to skip."""

    image: np.ndarray
    depth: np.ndarray | None
    ids: np.ndarray | None
    inv_depth: np.ndarray | None = None
    base_inv_depth: np.ndarray | None = None
    emission: np.ndarray | None = None
    silhouettes: dict[int, list[np.ndarray]] = field(default_factory=dict)
    """Per object id, flat pixel indices (row * W + col) its patches cover before the z-test: the
    silhouette without occluders (may repeat pixels)."""
    winner: WinnerMap | None = None
    """The camera's scratch map for the large patches, reused from frame to frame (None: a fresh one is filled)."""

    def __post_init__(self) -> None:
        if self.inv_depth is None:
            if self.depth is None:
                raise ValueError("RenderTarget needs inv_depth or depth (the z-buffer to start from)")
            with np.errstate(divide="ignore"):
                self.inv_depth = np.where(np.isfinite(self.depth), 1.0 / self.depth, 0.0).astype(np.float32)
        if self.base_inv_depth is None:
            self.base_inv_depth = self.inv_depth.copy()

    def silhouette(self, obj_id: int) -> tuple[tuple[int, int, int, int], int, int] | None:
        """The object's unoccluded silhouette: its tight box (u0, v0, u1, v1) (u1, v1 exclusive), its pixel
        count, and how many of those pixels show the object (``ids``; 0 without ids). None if it has none."""
        parts = self.silhouettes.get(obj_id)
        if not parts:
            return None
        pix = np.concatenate(parts)
        if not len(pix):
            return None
        ids = optional(self.ids, np.int32).reshape(-1)
        u0, v0, u1, v1, count, seen = silhouette_stats(pix, self.image.shape[1], ids, obj_id)
        return (int(u0), int(v0), int(u1), int(v1)), int(count), int(seen)


def rasterize(target: RenderTarget, batch: PatchBatch, cam: PinholeCamera, cam_from_world: Transform,
              textures: TextureAtlas | list[np.ndarray], sun_dir_world: np.ndarray, ambient: float = 0.55,
              silhouettes: bool = True, lod_px: float = LOD_PX, antialias: bool = True) -> None:
    """Draw ``batch`` into ``target`` with a z-test; camera pose ``cam_from_world``.

    silhouettes: record each object's unoccluded pixels in ``target.silhouettes``; lod_px: scenery
    (obj_id 0) narrower than this on screen is skipped; antialias: blend the pixels vertical edges cross by
    their coverage (``spans.smooth_edges``)."""
    atlas = textures if isinstance(textures, TextureAtlas) else TextureAtlas(list(textures))
    prep = prepare(batch, cam, [cam_from_world], atlas, sun_dir_world, ambient, lod_px)[0]
    if prep is not None:
        rasterize_prepared(target, prep, atlas, silhouettes, antialias)


_WARM: list[bool] = []


def warm_up() -> None:
    """Compile the rasteriser's kernels (numba: the first time after an install) or load them from numba's disk
    cache, once per process, by drawing a small synthetic scene
    through every path the renderer takes: large and small patches, textured and not, quads and discs, a lamp, a
    patch cut by the near plane, into a left camera's targets (depth, read off the z-buffer, ids, silhouettes) and a
    right one's, each with a reused winner map. The renderer calls it when it is built, so that no
    timed frame pays for it."""
    if _WARM:
        return
    cam = PinholeCamera(150.0, 150.0, 80.0, 60.0, 160, 120)
    b = PatchBuilder()
    b.add(np.array([-3.0, -2.0, 4.0]), np.array([6.0, 0, 0]), np.array([0, 4.0, 0]), (180.0,) * 3, texture=0,
          two_sided=True)
    for k in range(4):
        # untextured and textured quads and discs; the untextured disc unshaded (a lamp)
        b.add(np.array([-1.0 + 0.5 * k, -0.2, 3.0]), np.array([0.1, 0, 0]), np.array([0, 0.1, 0]), (90.0,) * 3,
              texture=k % 2 - 1, outline=k // 2, obj_id=k + 1, shade=k != 2, two_sided=True)
    b.add(np.array([-1.0, 1.0, -1.0]), np.array([2.0, 0, 0]), np.array([0, 0, 6.0]), (120.0,) * 3, two_sided=True)
    batch, atlas = b.build(), TextureAtlas([np.full((16, 16), 128, np.uint8)])
    for left in (True, False):
        h, w = cam.height, cam.width
        target = RenderTarget(np.zeros((h, w, 3), np.uint8), np.full((h, w), np.inf, np.float32) if left else None,
                              np.zeros((h, w), np.int32) if left else None, np.zeros((h, w), np.float32),
                              emission=np.zeros((h, w), np.float32), winner=WinnerMap((h, w)))
        rasterize(target, batch, cam, Transform(np.eye(3), np.zeros(3)), atlas, np.array([0.0, 0.0, -1.0]),
                  silhouettes=left)
        if left:
            target.silhouette(1)
    _WARM.append(True)


def prepare(batch: PatchBatch, cam: PinholeCamera, cams_from_world: list[Transform], atlas: TextureAtlas,
            sun_dir_world: np.ndarray, ambient: float = 0.55, lod_px: float = LOD_PX) -> list[PreparedPatches | None]:
    """Cull the batch for each camera and compute, per kept patch, its pixel box and inverse-homography rows.

    The cameras must share their orientation (a rectified rig). Shading, level of detail and texture mip
    levels are decided once for all cameras (by the first one that sees a patch), so that both images of
    a stereo pair show the same things."""
    if not len(batch):
        return [None] * len(cams_from_world)
    R = cams_from_world[0].R
    # np.allclose's test, |R_k - R| <= atol + rtol |R| (rtol 1e-5, atol 1e-8), without its generic machinery (whose
    # overhead is many times the test's)
    if not all(bool((np.abs(T.R - R) <= 1e-8 + 1e-5 * np.abs(R)).all()) for T in cams_from_world):
        raise ValueError("prepare() needs cameras with one orientation (a rectified rig); render them one by one")
    # shading in the world frame: ambient + diffuse |n·sun| (two-sided lighting); vec3's formulas on the columns
    nw = cross(batch.e1.T, batch.e2.T)
    lam = np.abs(np.column_stack(nw) @ sun_dir_world) / (np.sqrt(dot(nw, nw)) + 1e-12)
    shade = np.where(batch.shade, ambient + (1.0 - ambient) * lam, 1.0)
    colors = np.clip(batch.color * shade[:, None], 0, 255).astype(np.float32)
    E1 = batch.e1 @ R.T
    E2 = batch.e2 @ R.T
    O0 = batch.origin @ R.T
    views = [_project(batch, cam, O0 + T.t, E1, E2) for T in cams_from_world]
    # projected area and width per patch, from the first camera that sees it fully in front
    area = np.full(len(batch), np.nan)
    width = np.full(len(batch), np.nan)
    for v in reversed(views):
        if v is not None:
            area[v["idx"]], width[v["idx"]] = v["area"], v["width"]
    # level of detail: scenery (obj_id 0) narrower than lod_px, or smaller than lod_px^2, is skipped
    with np.errstate(invalid="ignore"):
        tiny = ((width < lod_px) | (area < lod_px * lod_px)) & (batch.obj_id == 0)
    level = _mip_levels(batch, atlas, area)
    return [None if v is None else _finish(batch, cam, v, tiny, level, colors, atlas) for v in views]


def _project(batch: PatchBatch, cam: PinholeCamera, O: np.ndarray, E1: np.ndarray, E2: np.ndarray) -> dict | None:
    """Per camera (patches in its frame: O, E1, E2): back faces and patches behind the near plane
    culled, the rest with their pixel box (x0, x1, y0, y1), nearest depth, crossing flag, area, width
    (``cull.project_patches``)."""
    idx, box, zmin, crossing, area, width = project_patches(O, E1, E2, batch.two_sided, cam.fx, cam.fy, cam.cx,
                                                            cam.cy, cam.width, cam.height, NEAR_M)
    if not len(idx):
        return None
    return dict(idx=idx, o=O[idx], e1=E1[idx], e2=E2[idx], x0=box[:, 0], x1=box[:, 1], y0=box[:, 2], y1=box[:, 3],
                zmin=zmin, crossing=crossing, area=area, width=width)


def _mip_levels(batch: PatchBatch, atlas: TextureAtlas, area: np.ndarray) -> np.ndarray:
    """Texture mip level per patch: log2 of texels per pixel over its projected area (0 where unknown)."""
    level = np.zeros(len(batch), int)
    has = np.flatnonzero(batch.texture >= 0)
    if len(has):
        tex = batch.texture[has]
        rep = batch.repeat[has]
        tsz = atlas.sizes[tex]
        texels = tsz[:, 0] * tsz[:, 1] * rep[:, 0] * rep[:, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            lvl = np.floor(0.5 * np.log2(texels / np.maximum(area[has], 1e-6)) + 0.25)
        level[has] = np.clip(np.nan_to_num(lvl, nan=0.0, posinf=0.0, neginf=0.0), 0, atlas.levels[tex] - 1)
    return level


def _finish(batch: PatchBatch, cam: PinholeCamera, v: dict, tiny: np.ndarray, level: np.ndarray, colors: np.ndarray,
            atlas: TextureAtlas) -> PreparedPatches | None:
    """The camera's drawable patches and their affine rows a', b', c (see fragments.py)."""
    idx = v["idx"]
    ok = (v["x1"] > v["x0"]) & (v["y1"] > v["y0"]) & ~(tiny[idx] & ~v["crossing"])
    # the affine rows a', b', c of each patch from A^-1, A = K [e1 e2 o] (singular ones dropped)
    sel, ma, mb, mc = inverse_rows(v["o"], v["e1"], v["e2"], ok, cam.fx, cam.fy, cam.cx, cam.cy)
    if not len(sel):
        return None
    pi = idx[sel]
    tex = batch.texture[pi]
    has = tex >= 0
    entry = np.where(has, atlas.first[np.maximum(tex, 0)] + level[pi], -1)
    # texels across the patch at that level: the entry's size times the repeat count
    texsize = np.where(has[:, None], atlas.rects[np.maximum(entry, 0), 2:4] * batch.repeat[pi], 0.0)
    crossing = v["crossing"][sel]
    return PreparedPatches(
        x0=v["x0"][sel], x1=v["x1"][sel], y0=v["y0"][sel], y1=v["y1"][sel],
        # affine rows of a' = 2 s/Z - 1/Z, b' = 2 t/Z - 1/Z, c = 1/Z: inside a quad iff max(|a'|, |b'|) <= c
        ma=ma, mb=mb, mc=mc,
        ellipse=batch.outline[pi] == 1, crossing=crossing, zmin=np.maximum(v["zmin"][sel], NEAR_M),
        area=v["area"][sel], obj_id=batch.obj_id[pi].astype(np.int32), color=colors[pi], entry=entry,
        texsize=texsize, emissive=~batch.shade[pi] & ~has)
