"""Planar patches, the renderer's only primitive: struct-of-arrays batches and a builder for model code.

A patch is the planar region ``{o + s e1 + t e2 : (s, t) in outline}`` with ``(s, t)`` in the unit
square: the square itself (a quad) or the ellipse inscribed in it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba.extending import register_jitable

from .vec3 import Vec3, add, mul, sub, vec

SUN_DIR = np.array([0.35, -0.45, 0.82]) / np.linalg.norm([0.35, -0.45, 0.82])
"""Unit vector towards the sun in the world frame (x forward, y left, z up); shading of every patch."""

QUAD = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_phi = np.linspace(0.0, 2 * np.pi, 20, endpoint=False)
ELLIPSE = np.column_stack([0.5 + 0.5 * np.cos(_phi), 0.5 + 0.5 * np.sin(_phi)])
OUTLINES = [QUAD, ELLIPSE]
"""Outline index 0: quad, 1: ellipse inscribed in the quad (the polygons are for reference; the
rasteriser tests the exact shapes)."""


@dataclass
class PatchBatch:
    """Planar patches in the world frame, struct-of-arrays. P patches.

    origin, e1, e2: (P, 3) [m]; color: (P, 3) BGR 0..255 before shading; texture: (P,) index into the
    renderer's texture bank, -1 for none; outline: (P,) index into OUTLINES; obj_id: (P,) object id
    (0 for scenery); two_sided: (P,) bool, False = culled when seen from the back (e1 x e2 points out);
    shade: (P,) bool, False = emissive (lights, sign faces keep their colour); repeat: (P, 2) how many
    times the texture tiles along e1 and e2 (None: once).
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
    repeat: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.repeat is None:
            self.repeat = np.ones((len(self.origin), 2))

    @staticmethod
    def empty() -> "PatchBatch":
        z3 = np.zeros((0, 3))
        zi = np.zeros(0, dtype=np.int32)
        zb = np.zeros(0, dtype=bool)
        return PatchBatch(z3, z3, z3, z3, zi, zi, zi, zb, zb, np.zeros((0, 2)))

    def __len__(self) -> int:
        return len(self.origin)

    def pack(self) -> np.ndarray:
        """All fields as one (P, 19) float64 array (see ``unpack``): cheap to select and stack."""
        return np.column_stack([self.origin, self.e1, self.e2, self.color, self.texture, self.outline, self.obj_id,
                                self.two_sided, self.shade, self.repeat]).astype(np.float64)

    @staticmethod
    def unpack(a: np.ndarray) -> "PatchBatch":
        """Inverse of ``pack``; geometry and colour are views of ``a``."""
        return PatchBatch(a[:, 0:3], a[:, 3:6], a[:, 6:9], a[:, 9:12], a[:, 12].astype(np.int32),
                          a[:, 13].astype(np.int32), a[:, 14].astype(np.int32), a[:, 15] > 0.5, a[:, 16] > 0.5,
                          a[:, 17:19])


@register_jitable
def box_faces(c: Vec3, axes: tuple[Vec3, Vec3, Vec3], size: Vec3) -> list[tuple[Vec3, Vec3, Vec3]]:
    """(origin, e1, e2) of the front (+x), back, left (+y), right, top (+z) and bottom faces of the box centred at
    ``c`` with unit ``axes`` x, y, z and ``size`` along them [m]; e1 x e2 points outwards (for back-face culling).
    Compiled into the kernels that call it (the pedestrians' shoes)."""
    hx, hy, hz = mul(size[0] / 2, axes[0]), mul(size[1] / 2, axes[1]), mul(size[2] / 2, axes[2])
    return [(sub(sub(add(c, hx), hy), hz), mul(2, hy), mul(2, hz)),
            (sub(add(sub(c, hx), hy), hz), mul(-2, hy), mul(2, hz)),
            (sub(add(add(c, hx), hy), hz), mul(-2, hx), mul(2, hz)),
            (sub(sub(sub(c, hx), hy), hz), mul(2, hx), mul(2, hz)),
            (add(sub(sub(c, hx), hy), hz), mul(2, hx), mul(2, hy)),
            (sub(add(sub(c, hx), hy), hz), mul(2, hx), mul(-2, hy))]


class PatchBuilder:
    """Accumulates patches one by one (readable model code), then packs them into a PatchBatch."""

    def __init__(self) -> None:
        self._rows: list[tuple] = []

    def add(self, origin, e1, e2, color, *, texture: int = -1, outline: int = 0, obj_id: int = 0,
            two_sided: bool = False, shade: bool = True, repeat=(1.0, 1.0)) -> None:
        self._rows.append((origin, e1, e2, color, texture, outline, obj_id, two_sided, shade, repeat))

    def box(self, center, axes, size, color, *, texture: int = -1, obj_id: int = 0, bottom: bool = False,
            shade: bool = True, faces: str = "fblrt") -> None:
        """Axis-aligned box in its own frame: center (3,), axes (3, 3) rows = unit x, y, z, size (3,) [m].

        faces: which of front (+x), back, left (+y), right, top to add (plus the bottom if ``bottom``).
        Faces are oriented so that e1 x e2 points outwards (for back-face culling).
        """
        front, back, left, right, top, under = box_faces(vec(center), tuple(vec(a) for a in axes), vec(size))
        all_faces = {"f": front, "b": back, "l": left, "r": right, "t": top}
        chosen = [all_faces[k] for k in faces] + ([under] if bottom else [])
        for o, a, b in chosen:
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
            np.asarray(cols[9], dtype=np.float64).reshape(-1, 2),
        )
