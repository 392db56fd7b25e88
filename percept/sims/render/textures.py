"""Procedural textures (grayscale albedo, 0..255) for the renderer, deterministic for a seed."""

from __future__ import annotations

import functools

import cv2
import numpy as np


def fractal_noise(size: int, octaves: list[tuple[int, float]], seed: int, tileable: bool = True) -> np.ndarray:
    """Sum of band-limited noise octaves on a size x size tile, float32 with zero mean, unit std.

    octaves: (feature size in texels, amplitude). Blurring with BORDER_WRAP keeps the tile seamless.
    """
    rng = np.random.default_rng(seed)
    acc = np.zeros((size, size), np.float32)
    for feat, amp in octaves:
        n = rng.standard_normal((size, size)).astype(np.float32)
        if feat > 1:
            k = int(feat) * 2 + 1
            pad = min(k, size) if tileable else 0
            # wrap-padding then cropping keeps a tile seamless (GaussianBlur has no wrap border)
            p = np.pad(n, pad, mode="wrap") if pad else n
            p = cv2.GaussianBlur(p, (k, k), feat / 2.0, borderType=cv2.BORDER_REFLECT)
            n = p[pad:pad + size, pad:pad + size] if pad else p
        n /= n.std() + 1e-9
        acc += amp * n
    acc -= acc.mean()
    acc /= acc.std() + 1e-9
    return acc


def to_albedo(noise: np.ndarray, mean: float, spread: float) -> np.ndarray:
    """Map zero-mean unit noise to uint8 albedo ``mean + spread * noise``, clipped."""
    return np.clip(mean + spread * noise, 0, 255).astype(np.uint8)


@functools.lru_cache(maxsize=8)
def ground_tile(seed: int, size: int = 1024) -> np.ndarray:
    """Seamless asphalt/grass grain: fine grit, pebbles and metre-scale blotches (8 m tile at 128 px/m).

    Cached per seed (both cameras and every renderer of a process share it); read-only."""
    n = fractal_noise(size, [(1, 0.9), (3, 0.7), (12, 0.6), (60, 0.5)], seed)
    out = to_albedo(n, 128, 42)
    out.flags.writeable = False
    return out


def mip_chain(tile: np.ndarray, levels: int) -> list[np.ndarray]:
    """Level 0 is the tile; each next level halves the resolution (Gaussian pyramid)."""
    out = [tile]
    for _ in range(levels):
        out.append(cv2.pyrDown(out[-1]))
    return out


def panel_texture(seed: int, size: int = 64, mean: float = 225, spread: float = 22, feat: int = 2) -> np.ndarray:
    """Mild grain for vehicle bodies and props, so that stereo has something to match."""
    return to_albedo(fractal_noise(size, [(1, 0.6), (feat, 1.0)], seed), mean, spread)


def building_texture(seed: int, w: int = 128, h: int = 128) -> np.ndarray:
    """A façade: light wall with grain and a grid of dark windows."""
    rng = np.random.default_rng(seed)
    wall = to_albedo(fractal_noise(max(w, h), [(1, 0.5), (4, 1.0)], seed)[:h, :w], 215, 18)
    nx, ny = int(rng.integers(5, 9)), int(rng.integers(4, 7))
    for i in range(nx):
        for j in range(ny):
            x0 = int((i + 0.25) * w / nx)
            y0 = int((j + 0.3) * h / ny)
            shade = int(rng.integers(40, 110))
            cv2.rectangle(wall, (x0, y0), (x0 + int(0.5 * w / nx), y0 + int(0.45 * h / ny)), shade, -1)
    return wall


def foliage_texture(seed: int, size: int = 64) -> np.ndarray:
    return to_albedo(fractal_noise(size, [(1, 0.8), (3, 1.0), (8, 0.6)], seed), 190, 45)


def marker_texture(marker_id: int, size: int = 96) -> np.ndarray:
    """A 4x4 ArUco marker (DICT_4X4_50) with a white quiet zone: the machine-readable face of a sign."""
    dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    inner = int(size * 0.7)
    m = cv2.aruco.generateImageMarker(dictionary, int(marker_id), inner)
    out = np.full((size, size), 250, np.uint8)
    o = (size - inner) // 2
    out[o:o + inner, o:o + inner] = np.maximum(m, 20)
    return out


class TextureAtlas:
    """Every texture of the renderer and its mip levels packed in one image, for vectorised sampling.

    Each entry keeps a one-texel wrapped border, so bilinear sampling across a tile's edge wraps.
    rects: (E, 4) int (x0, y0, w, h) of each entry's interior in ``image``; first: (T,) entry of each
    texture's level 0; levels: (T,) number of levels of each texture (down to MIN_MIP_PX).
    """

    MIN_MIP_PX = 4

    def __init__(self, textures: list[np.ndarray], width: int = 1024):
        self.count = len(textures)
        entries, first, levels = [], [], []
        for t in textures:
            chain = [np.ascontiguousarray(t, np.uint8)]
            while min(chain[-1].shape[:2]) >= 2 * self.MIN_MIP_PX:
                # wrap-pad, halve, crop: the tile stays seamless at every level
                p = cv2.pyrDown(np.pad(chain[-1], 4, mode="wrap"))
                chain.append(np.ascontiguousarray(p[2:-2, 2:-2]))
            first.append(len(entries))
            levels.append(len(chain))
            entries.extend(chain)
        # shelf packing, tallest first
        order = sorted(range(len(entries)), key=lambda i: (-entries[i].shape[0], i))
        rects = np.zeros((len(entries), 4), int)
        x = y = shelf = 0
        for i in order:
            h, w = entries[i].shape[0] + 2, entries[i].shape[1] + 2
            if x + w > width:
                x, y, shelf = 0, y + shelf, 0
            rects[i] = (x + 1, y + 1, w - 2, h - 2)
            x, shelf = x + w, max(shelf, h)
        self.image = np.zeros((max(y + shelf, 1), width), np.uint8)
        for i, e in enumerate(entries):
            x0, y0, w, h = rects[i]
            self.image[y0 - 1:y0 + h + 1, x0 - 1:x0 + w + 1] = np.pad(e, 1, mode="wrap")
        self.rects = rects
        self.first = np.asarray(first, int)
        self.levels = np.asarray(levels, int)
        self.sizes = np.array([t.shape[1::-1] for t in textures], float).reshape(-1, 2)
        """(T, 2) level-0 width and height of each texture [texels]."""
        self._tiled: dict[tuple[int, int, int], np.ndarray] = {}

    def tiled(self, entry: int, nx: int, ny: int) -> np.ndarray:
        """Entry ``entry`` repeated nx x ny times with a one-texel wrapped border (for OpenCV warps that stay
        inside the image: texel (x, y) of the repeat is at (x + 1, y + 1))."""
        key = (entry, max(nx, 1), max(ny, 1))
        t = self._tiled.get(key)
        if t is None:
            x0, y0, w, h = self.rects[entry]
            t = np.pad(np.tile(self.image[y0:y0 + h, x0:x0 + w], (key[2], key[1])), 1, mode="wrap")
            self._tiled[key] = t
        return t
