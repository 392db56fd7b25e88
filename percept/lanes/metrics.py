"""Lane scoring formulas (pure numpy), shared by the closed-loop scorer and the footage commands."""

from __future__ import annotations

import numpy as np

LANE_ERROR_KEYS = ("offset_rmse_m", "heading_rmse_rad", "curvature_rmse_1pm")


def rmse_columns(errors, keys: tuple[str, ...] = LANE_ERROR_KEYS) -> dict[str, float | None]:
    """RMS of each column of per-frame errors (N, len(keys)): {key: sqrt(mean(e^2))}; None for all without rows."""
    if len(errors) == 0:
        return {k: None for k in keys}
    e = np.asarray(errors, dtype=float).reshape(len(errors), len(keys))
    # RMSE_k = sqrt(1/N sum_i e_ik^2)
    return {k: float(v) for k, v in zip(keys, np.sqrt(np.mean(e * e, axis=0)))}


def centering(offsets_m) -> dict[str, float | None]:
    """centering_rms_m and centering_max_m of the true lateral offsets from the lane centre [m]; None when empty."""
    off = np.abs(np.asarray(offsets_m, dtype=float))
    if not len(off):
        return {"centering_rms_m": None, "centering_max_m": None}
    return {"centering_rms_m": float(np.sqrt(np.mean(off ** 2))), "centering_max_m": float(off.max())}
