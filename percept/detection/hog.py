"""HOG features computed once per image (or strip) and scale, and a linear model scored over every window at once.

Dalal & Triggs (CVPR 2005): gradient orientations in 8x8-pixel cells, 9 unsigned bins weighted by magnitude,
16x16 blocks of 2x2 cells stepped by 8 pixels, each block normalised (L2-Hys); a 64x128 window's descriptor is
its 7x15 blocks in a row. Every block of an image (block (bx, by) covers pixels (8 bx, 8 by) to (8 bx + 15,
8 by + 15)) is computed once and shared by all the windows that contain them (OpenCV's own ``detectMultiScale``
shares them too, within a scale): OpenCV's ``HOGDescriptor`` computes the gradients, and ``hog_blocks`` sums them
into blocks separably in one compiled pass (OpenCV's own blocks, from ``compute`` with one window as large as the
image, to float32 rounding). A linear model w on a window at block (x, y) scores

    s(x, y) = b + sum_{i < 7, j < 15} w_ij . B(x + i, y + j)

which is computed per row of windows y: one product (BLAS) of each block column's 15 blocks from row y (540
values, contiguous) with the window's 7 columns of weights gives R(bx, y, i) = sum_j w_ij . B(bx, y + j), and one
compiled pass adds s(x, y) = b + sum_i R(x + i, y, i). Only the products some window needs are made: a strip a few
windows tall (the constrained search's) has most of its blocks in fewer than 15 windows' rows.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import cv2
import numpy as np

from percept.compiled import kernel

from .blocks import BINS, CELL_PX, L2HYS_CLIP, WINDOW_PX, hog_blocks, hog_descriptor

BLOCK_PX = 16
BLOCKS = ((WINDOW_PX[0] - BLOCK_PX) // CELL_PX + 1, (WINDOW_PX[1] - BLOCK_PX) // CELL_PX + 1)
"""Blocks across and down one window: (7, 15)."""
BLOCK_LEN = 4 * BINS
SIM_MODEL_PATH = Path(__file__).parent / "models" / "people_sim.npz"
"""The shipped sim-trained people model."""
DESCRIPTOR_LEN = BLOCKS[0] * BLOCKS[1] * BLOCK_LEN


def block_grid(image: np.ndarray, cell_px: int = CELL_PX) -> np.ndarray:
    """Every HOG block of ``image`` (grey or BGR uint8, at least one window): (nbx, nby, 36) float32, block (bx, by)
    at pixel (c bx, c by) for cells of c = ``cell_px`` pixels (a window is 8 c x 16 c px). Columns and rows past
    the last whole block are not covered. The blocks are OpenCV's (``hog_descriptor(...).compute`` with one window
    as large as the image) to float32 rounding, computed by ``hog_blocks`` from OpenCV's gradients."""
    h, w = image.shape[:2]
    c = int(cell_px)
    win = (WINDOW_PX[0] * c // CELL_PX, WINDOW_PX[1] * c // CELL_PX)
    if w < win[0] or h < win[1]:
        raise ValueError(f"image of {w}x{h} px is smaller than the {win[0]}x{win[1]} detection window")
    return hog_blocks(image, c)


@dataclass(frozen=True)
class LinearModel:
    """A linear window classifier on HOG: weights (3780,) float32 in OpenCV's descriptor order, bias; name: where
    it came from. ``score_map`` scores every window of a block grid.

    second: an optional second stage (a two-stage cascade, Viola & Jones, CVPR 2001): a detection made of the first
    model's windows is kept only if the second model scores one of its windows at least ``second_threshold``
    (``second_scores``; ``pyramid.second_stage_kept``). Its score stays the first model's."""

    weights: np.ndarray
    bias: float
    name: str
    second: "LinearModel | None" = None
    second_threshold: float = 0.0

    def __post_init__(self) -> None:
        if self.weights.shape != (DESCRIPTOR_LEN,) or not np.all(np.isfinite(self.weights)):
            raise ValueError(f"model {self.name}: expected {DESCRIPTOR_LEN} finite weights, got shape "
                             f"{self.weights.shape}")
        if self.second is not None and (self.second.second is not None or not np.isfinite(self.second_threshold)):
            raise ValueError(f"model {self.name}: a second stage must be a single linear model with a finite "
                             f"threshold")

    @classmethod
    def inria(cls) -> "LinearModel":
        """OpenCV's people detector, trained on the INRIA person photographs (Dalal & Triggs)."""
        d = np.asarray(cv2.HOGDescriptor_getDefaultPeopleDetector(), np.float32).ravel()
        return cls(d[:DESCRIPTOR_LEN].copy(), float(d[DESCRIPTOR_LEN]), "inria")

    @classmethod
    def sim(cls) -> "LinearModel":
        """percept's own model, trained on rendered people by ``percept train-detector`` (shipped in the package,
        its training record beside it in ``people_sim.json``): a cascade whose first stage has the command's
        defaults and whose second stage, trained with hard negatives from the traffic scenarios too, confirms a
        detection when it scores one of its windows at least -0.5."""
        return cls.load(SIM_MODEL_PATH)

    @staticmethod
    def file_of(name: str) -> Path | None:
        """The file a model name stands for: None for 'inria' (built into OpenCV), the packaged file for 'sim', else
        the path ``name``."""
        return None if name == "inria" else SIM_MODEL_PATH if name == "sim" else Path(name)

    @classmethod
    def named(cls, name: str) -> "LinearModel":
        """'inria', 'sim' or the path of a model file; ValueError when the file is missing or corrupt."""
        path = cls.file_of(name)
        return cls.inria() if path is None else cls.load(path)

    @classmethod
    def load(cls, path: Path) -> "LinearModel":
        """A model saved by ``save`` (an .npz with ``weights`` and ``bias``); ValueError when missing or corrupt."""
        path = Path(path)
        try:
            with open(path, "rb") as f:
                if f.read(4) != b"PK\x03\x04":  # every .npz is a zip archive
                    raise ValueError(f"model file {path} is not a percept HOG model (not an .npz archive"
                                     f"{', it is empty' if f.tell() == 0 else ''})")
            with np.load(path, allow_pickle=False) as z:
                if missing := [k for k in ("weights", "bias") if k not in z]:
                    raise ValueError(f"model file {path} is not a percept HOG model (it has no "
                                     f"{' and no '.join(missing)} array)")
                name = "sim" if path == SIM_MODEL_PATH else str(path)
                second = (cls(np.asarray(z["second_weights"], np.float32), float(z["second_bias"]), f"{name} (second)")
                          if "second_weights" in z else None)
                return cls(np.asarray(z["weights"], np.float32), float(z["bias"]), name, second,
                           float(z["second_threshold"]) if second is not None else 0.0)
        except FileNotFoundError:
            raise ValueError(f"model file {path} does not exist") from None
        except IsADirectoryError:
            raise ValueError(f"model file {path} is a folder") from None
        except (OSError, KeyError, ValueError, TypeError, EOFError, zipfile.BadZipFile) as e:
            if str(e).startswith(f"model file {path} "):
                raise
            raise ValueError(f"model file {path} is not a percept HOG model ({type(e).__name__}: {e})") from None

    def save(self, path: Path, **meta: str) -> None:
        """Write the model (weights, bias and string metadata, e.g. its training data) to an .npz, atomically."""
        import io

        from percept.outputs import write_bytes_atomic

        buf = io.BytesIO()
        stages = {} if self.second is None else dict(second_weights=self.second.weights.astype(np.float32),
                                                     second_bias=np.float32(self.second.bias),
                                                     second_threshold=np.float32(self.second_threshold))
        np.savez(buf, weights=self.weights.astype(np.float32), bias=np.float32(self.bias), **stages,
                 **{k: np.asarray(v) for k, v in meta.items()})
        write_bytes_atomic(path, buf.getvalue())

    def opencv_detector(self) -> np.ndarray:
        """The model as OpenCV's ``setSVMDetector`` takes it: weights then bias, (3781,) float32. ValueError for a
        cascade (OpenCV's detector is one linear model)."""
        if self.second is not None:
            raise ValueError(f"model {self.name} is a cascade; OpenCV's HOG detector takes a single linear model")
        return np.append(self.weights, np.float32(self.bias)).astype(np.float32)

    def score_map(self, blocks: np.ndarray) -> np.ndarray:
        """Score of the window at every block position of ``blocks`` (nbx, nby, 36): (nbx - 6, nby - 14)."""
        nbx, nby, _ = blocks.shape
        ny = nby - BLOCKS[1] + 1
        blocks = np.ascontiguousarray(blocks, np.float32)
        # R[y, bx, i] = sum_j w_ij . B(bx, y + j): one product per row of windows y (numpy's stacked matmul), each
        # block column's 15 blocks from row y (540 contiguous values) against the 7 columns of the window's weights
        sx, sy, sk = blocks.strides
        column_blocks = np.ndarray((ny, nbx, BLOCKS[1] * BLOCK_LEN), np.float32, blocks, 0, (sy, sx, sk))
        return _window_sums(np.matmul(column_blocks, self._weights_by_column), np.float32(self.bias))

    def second_scores(self, blocks: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray | None:
        """The second stage's scores (N,) float32 of the windows at block positions (``x``, ``y``) (N,) of ``blocks``
        (nbx, nby, 36); None without a second stage."""
        if self.second is None:
            return None
        if not len(x):
            return np.zeros(0, np.float32)
        # a window's descriptor is its blocks (x + i, y + j), i < 7, j < 15, in OpenCV's order: (N, 7, 15, 36), copied
        # window by window (a frame's strips hold a few windows each)
        d = np.empty((len(x), BLOCKS[0], BLOCKS[1], BLOCK_LEN), blocks.dtype)
        for n, (bx, by) in enumerate(zip(np.asarray(x).tolist(), np.asarray(y).tolist())):
            d[n] = blocks[bx:bx + BLOCKS[0], by:by + BLOCKS[1]]
        # s2 = b2 + w2 . descriptor
        return (d.reshape(len(x), DESCRIPTOR_LEN) @ self.second.weights + np.float32(self.second.bias)).astype(
            np.float32)

    @cached_property
    def _weights_by_column(self) -> np.ndarray:
        """The weights as a (15 * 36, 7) matrix: column i holds the blocks j = 0..14 of the window's block column
        i in a row, w_ij at rows 36 j..36 j + 35."""
        w = self.weights.reshape(BLOCKS[0], BLOCKS[1], BLOCK_LEN)
        return np.ascontiguousarray(w.transpose(1, 2, 0).reshape(BLOCKS[1] * BLOCK_LEN, BLOCKS[0]))


@kernel()
def _window_sums(r, bias):  # pragma: no cover - compiled
    """s(x, y) = b + sum_i R[y, x + i, i] from R (ny, nbx, 7) float32: (nbx - 6, ny) float32, accumulated in
    float32 from the bias on."""
    ny, nbx, ni = r.shape
    nx = nbx - ni + 1
    s = np.empty((nx, ny), np.float32)
    for x in range(nx):
        for y in range(ny):
            v = r[y, x, 0] + bias
            for i in range(1, ni):
                v += r[y, x + i, i]
            s[x, y] = v
    return s
