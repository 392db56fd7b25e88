"""Training a linear HOG people model: window crops, their features, a linear SVM (OpenCV's ``cv2.ml``), hard
negatives.

Dalal & Triggs (CVPR 2005), section 4: positives are person windows (the person the middle 96 of 128 rows, a 1:2
window) with their mirror images; negatives are windows without people; after a first model, the false
positives it scores on the negative images ("hard negatives") join the negatives and the model is trained again.
Crops are taken at the resolution the constrained search scores (``SEARCH_WINDOW_PX``: 4-pixel cells), so the
model learns the features it is applied to.
"""

from __future__ import annotations

import cv2
import numpy as np

from .constrained import SearchConfig
from .hog import CELL_PX, DESCRIPTOR_LEN, WINDOW_PX, LinearModel, hog_descriptor

CELL = SearchConfig().cell_px
SEARCH_WINDOW_PX = (WINDOW_PX[0] * CELL // CELL_PX, WINDOW_PX[1] * CELL // CELL_PX)
"""The window as the constrained search sees it (width, height) [px]."""

Box = tuple[float, float, float, float]


def window_crop(image: np.ndarray, window: Box) -> np.ndarray | None:
    """The window (u0, v0, u1, v1) resized to ``SEARCH_WINDOW_PX``; None when it leaves the image."""
    h, w = image.shape[:2]
    u0, v0, u1, v1 = (int(round(c)) for c in window)
    if u0 < 0 or v0 < 0 or u1 > w or v1 > h or u1 - u0 < 8 or v1 - v0 < 16:
        return None
    return cv2.resize(image[v0:v1, u0:u1], SEARCH_WINDOW_PX, interpolation=cv2.INTER_LINEAR)


def features(crops: list[np.ndarray], mirror: bool = False) -> np.ndarray:
    """HOG descriptors (N, 3780) float32 of ``SEARCH_WINDOW_PX`` crops (or of their mirror images), in OpenCV's
    window order."""
    hog = hog_descriptor(SEARCH_WINDOW_PX, CELL)
    out = np.empty((len(crops), DESCRIPTOR_LEN), np.float32)
    for i, c in enumerate(crops):
        out[i] = hog.compute(cv2.flip(c, 1) if mirror else c).ravel()
    return out


def train_linear_svm(pos: np.ndarray, neg: np.ndarray, c: float = 0.01, name: str = "sim") -> LinearModel:
    """A linear SVM (positives +1, negatives -1) as a ``LinearModel`` whose score is positive for people."""
    if len(pos) == 0 or len(neg) == 0:
        raise ValueError(f"training needs positives and negatives, got {len(pos)} and {len(neg)}")
    x = np.vstack([pos, neg]).astype(np.float32)
    y = np.concatenate([np.ones(len(pos), np.int32), -np.ones(len(neg), np.int32)])
    svm = cv2.ml.SVM_create()
    svm.setType(cv2.ml.SVM_C_SVC)
    svm.setKernel(cv2.ml.SVM_LINEAR)
    svm.setC(c)
    svm.setTermCriteria((cv2.TERM_CRITERIA_MAX_ITER + cv2.TERM_CRITERIA_EPS, 20000, 1e-4))
    svm.train(x, cv2.ml.ROW_SAMPLE, y)
    sv = svm.getSupportVectors().ravel().astype(np.float32)  # a linear SVM keeps one compressed vector
    rho, alpha, _ = svm.getDecisionFunction(0)
    w, b = float(alpha.ravel()[0]) * sv, -float(rho)
    # OpenCV's sign convention depends on the label order: make people score positive
    if np.mean(pos @ w + b) < np.mean(neg @ w + b):
        w, b = -w, -b
    return LinearModel(w.astype(np.float32), b, name)


def hard_negatives(model: LinearModel, neg_pool: np.ndarray, limit: int) -> np.ndarray:
    """The ``limit`` highest-scoring windows of ``neg_pool`` that the model calls people (score >= 0)."""
    s = neg_pool @ model.weights + model.bias
    idx = np.flatnonzero(s >= 0.0)
    return neg_pool[idx[np.argsort(-s[idx])][:limit]]

