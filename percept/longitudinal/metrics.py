"""Scoring formulas for range and time to contact of the in-path lead: pure numpy.

docs/design.md, "Scoring definitions": for the in-path lead object, |estimate - truth| / truth, median
overall and per range bin of the true range. The per-bin breakdown follows the usual way of
reporting stereo range error against distance (error grows with range squared for a fixed
disparity error; Hartley & Zisserman, "Multiple View Geometry", 2nd ed., ch. 12).

Samples are paired by index; a pair where either value is non-finite (no estimate, no lead) is
dropped, and so is a range pair whose true range is not positive (contact: no relative error).
A metric with no sample left is None, never 0.
"""

from __future__ import annotations

import numpy as np

# true-range bins [m]: lower bound inclusive, upper exclusive; beyond 80 m no bin
RANGE_BINS_M: tuple[tuple[int, int], ...] = ((0, 20), (20, 40), (40, 60), (60, 80))


def bin_key(bin_m: tuple[float, float]) -> str:
    """JSON key of a range bin, e.g. ``(20, 40) -> "20-40"``."""
    lo, hi = bin_m
    return f"{lo:g}-{hi:g}"


def _finite_pairs(est: np.ndarray, true: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray]:
    """Both as 1-D float arrays of equal length, keeping only pairs where both are finite."""
    e = np.asarray(est, dtype=np.float64)
    t = np.asarray(true, dtype=np.float64)
    if e.ndim != 1 or t.ndim != 1:
        raise ValueError(f"{what}: expected 1-D arrays, got shapes {e.shape} and {t.shape}")
    if e.shape != t.shape:
        raise ValueError(f"{what}: estimate and truth differ in length ({e.size} vs {t.size}); pair them by frame")
    keep = np.isfinite(e) & np.isfinite(t)
    return e[keep], t[keep]


def _median_or_none(values: np.ndarray) -> float | None:
    return float(np.median(values)) if values.size else None


def _range_pairs(est_m: np.ndarray, true_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    e, t = _finite_pairs(est_m, true_m, "range")
    # relative error is undefined at r_true <= 0 (contact or overlap): not scored
    keep = t > 0.0
    return e[keep], t[keep]


def _rel_err(e: np.ndarray, t: np.ndarray) -> np.ndarray:
    # eps = |r_est - r_true| / r_true
    return np.abs(e - t) / t


def range_abs_rel_err(est_m: np.ndarray, true_m: np.ndarray) -> float | None:
    """Median absolute relative range error over the samples; None when no finite pair."""
    e, t = _range_pairs(est_m, true_m)
    return _median_or_none(_rel_err(e, t))


def range_abs_rel_err_by_bin(est_m: np.ndarray, true_m: np.ndarray) -> dict[str, float | None]:
    """Median absolute relative range error per bin of the TRUE range (``RANGE_BINS_M``).

    Keys "0-20", "20-40", "40-60", "60-80"; a bin without sample is None.
    """
    e, t = _range_pairs(est_m, true_m)
    err = _rel_err(e, t)
    out: dict[str, float | None] = {}
    for lo, hi in RANGE_BINS_M:
        # lo <= r_true < hi
        in_bin = (t >= lo) & (t < hi)
        out[bin_key((lo, hi))] = _median_or_none(err[in_bin])
    return out


def ttc_abs_err_s(est_s: np.ndarray, true_s: np.ndarray, max_ttc_s: float = 10.0) -> float | None:
    """Median |TTC_est - TTC_true| [s] over pairs with a finite estimate and 0 < TTC_true <= max_ttc_s.

    A lead that is not closing has no (or an infinite) time to contact; beyond ``max_ttc_s`` the
    value no longer matters for braking, so those samples are not scored. None when no sample fits.
    """
    if not (np.isfinite(max_ttc_s) and max_ttc_s > 0.0):
        raise ValueError(f"max_ttc_s must be finite and > 0 s, got {max_ttc_s!r}")
    e, t = _finite_pairs(est_s, true_s, "time to contact")
    keep = (t > 0.0) & (t <= max_ttc_s)
    # err = |ttc_est - ttc_true|
    return _median_or_none(np.abs(e[keep] - t[keep]))


# --- dense disparity against a ground-truth map (`percept stereo --gt`) ---------------------------------------

BAD_PIXEL_PX = 2.0
"""The bad-pixel threshold of ``disparity_metrics`` (Middlebury's "bad 2.0")."""


def _depth(disparity_px: np.ndarray, focal_px: float, baseline_m: float, doffs_px: float) -> np.ndarray:
    d = disparity_px + doffs_px
    with np.errstate(divide="ignore", invalid="ignore"):
        # Z = f b / (d + doffs); no depth at or beyond infinity (d + doffs <= 0)
        return np.where(d > 0, focal_px * baseline_m / d, np.nan)


def disparity_metrics(est_px: np.ndarray, gt_px: np.ndarray, focal_px: float, baseline_m: float,
                      doffs_px: float = 0.0) -> dict[str, float | int | None]:
    """Errors of a dense disparity map ``est_px`` (H, W) [px] against the ground truth ``gt_px`` (H, W) [px].

    A ground-truth pixel is valid when finite and > 0 (Middlebury marks "unknown" by inf, 0 or NaN); an estimate
    exists where it is finite. Over the valid ground-truth pixels:

    - bad_2_0_pct: % whose |d - d_gt| > 2 px OR that have no estimate: a pixel with no estimate counts as bad,
      so a map cannot score well by leaving hard pixels out (Scharstein & Szeliski 2002, "bad pixels");
    - density_pct: % with an estimate;
    - mae_px: mean |d - d_gt| over the pixels with an estimate;
    - depth_abs_rel_err: median |Z - Z_gt| / Z_gt, Z = f b / (d + doffs), over the pixels with both depths;
    - valid_px: how many valid ground-truth pixels there are.

    A value with no pixel to compute it from is None, never 0.
    """
    e = np.asarray(est_px, dtype=np.float64)
    t = np.asarray(gt_px, dtype=np.float64)
    if e.shape != t.shape or e.ndim != 2:
        raise ValueError(f"disparity maps must be 2-D and of one shape, got {e.shape} and {t.shape}")
    for name, v in (("focal_px", focal_px), ("baseline_m", baseline_m)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
    valid = np.isfinite(t) & (t > 0)
    n = int(valid.sum())
    has = valid & np.isfinite(e)
    err = np.abs(e[has] - t[has])
    # bad = (no estimate) or |d - d_gt| > 2 px, over the valid ground truth
    bad = (n - has.sum()) + int((err > BAD_PIXEL_PX).sum())
    z, z_gt = _depth(e[has], focal_px, baseline_m, doffs_px), _depth(t[has], focal_px, baseline_m, doffs_px)
    both = np.isfinite(z) & np.isfinite(z_gt)
    return {"bad_2_0_pct": float(100.0 * bad / n) if n else None,
            "density_pct": float(100.0 * has.sum() / n) if n else None,
            "mae_px": float(err.mean()) if err.size else None,
            # eps_Z = |Z - Z_gt| / Z_gt
            "depth_abs_rel_err": _median_or_none(np.abs(z[both] - z_gt[both]) / z_gt[both]),
            "valid_px": n}


def disparity_summary(disparity_px: np.ndarray, depth_m: np.ndarray) -> dict[str, float | None]:
    """Without ground truth: density_pct (% of all pixels with a finite disparity) and the 5th, 50th and 95th
    percentiles of the finite disparities [px] and depths [m] (None when there are none)."""
    d = np.asarray(disparity_px, dtype=np.float64)
    z = np.asarray(depth_m, dtype=np.float64)
    out: dict[str, float | None] = {"density_pct": 100.0 * float(np.isfinite(d).mean()) if d.size else None}
    for name, values in (("disparity_px", d[np.isfinite(d)]), ("depth_m", z[np.isfinite(z)])):
        for q in (5, 50, 95):
            out[f"{name}_p{q}"] = float(np.percentile(values, q)) if values.size else None
    return out
