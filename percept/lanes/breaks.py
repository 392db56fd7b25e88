"""A curvature break ahead: the road's curvature changes at a distance d (arc after a straight, or the reverse).

Roads built from straights and arcs (highway-env's) have piecewise-constant curvature; a single polynomial
blurs the change into the near-range estimate. The model y = a0 + a1 x + a2 x^2 + b max(0, x - d)^2 +- w/2
keeps the near curvature 2 a2 clean and reports the far one 2 (a2 + b) and where it starts, tried at a grid
of d and kept when it explains the marking points clearly better (Dickmanns & Mysliwetz, PAMI 1992,
piecewise clothoid road model).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BREAKS_M = (9.0, 12.0, 15.0, 19.0, 23.0, 28.0, 34.0, 40.0)


@dataclass(frozen=True)
class CurvatureBreak:
    """distance_m: where the curvature changes, ahead of the vehicle centre [m]; near_params: (a0, a1, a2, w) of
    the lane before it; curvature_far_1pm: the curvature after it; normal: (4, 4) normal matrix of near_params."""

    distance_m: float
    near_params: np.ndarray
    curvature_far_1pm: float
    normal: np.ndarray


def _wls(A: np.ndarray, y: np.ndarray, w: np.ndarray, prior_rows: np.ndarray, prior_rhs: np.ndarray):
    """Weighted least squares with pseudo-observations; returns parameters, weighted SSE and normal matrix."""
    Aw = A * w[:, None]
    N = A.T @ Aw + prior_rows.T @ prior_rows
    p = np.linalg.solve(N, Aw.T @ y + prior_rows.T @ prior_rhs)
    r = A @ p - y
    return p, float(np.sum(w * r * r)), N


def find_break(x: np.ndarray, y: np.ndarray, s: np.ndarray, w: np.ndarray, width_prior_m: float,
               width_sigma_m: float, noise_m: float, min_points: int = 15, gain: float = 0.6) -> CurvatureBreak | None:
    """Best curvature break for points (x, y) on sides s (+1 left, -1 right) with weights w, or None."""
    xs = x / 10.0
    base = np.column_stack([np.ones_like(xs), xs, xs * xs, s / 2])
    prior = np.zeros((1, 5))
    prior[0, 3] = noise_m / width_sigma_m
    rhs = np.array([width_prior_m * noise_m / width_sigma_m])
    _, sse0, _ = _wls(base, y, w, prior[:, :4], rhs)
    best = None
    for d in BREAKS_M:
        beyond = x > d
        if beyond.sum() < min_points or (~beyond).sum() < min_points:
            continue
        hinge = np.where(beyond, (xs - d / 10.0) ** 2, 0.0)
        p, sse, N = _wls(np.column_stack([base, hinge]), y, w, prior, rhs)
        if best is None or sse < best[1]:
            best = (d, sse, p, N)
    if best is None or best[1] > gain * sse0:
        return None
    d, _, p, N = best
    unscale = np.array([1.0, 0.1, 0.01, 1.0])
    # curvature after the break: 2 (a2 + b), both in units of 1/(10 m)^2
    return CurvatureBreak(d, p[:4] * unscale, float(2 * (p[2] + p[4]) * 0.01),
                          N[:4, :4] / np.outer(unscale, unscale))
