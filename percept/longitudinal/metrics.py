"""Scoring formulas for range and time to contact of the in-path lead: pure numpy.

DESIGN, "Scoring definitions": for the in-path lead object, |estimate - truth| / truth, median
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
