"""Both lane boundaries fitted jointly in the vehicle frame, robustly, with a lane-width prior.

Model (vehicle frame, y left): y = a0 + a1 x + a2 x^2 + a3 x^3 + s w/2, s = +1 on the left boundary, -1 on the
right, so the lane centre is y_c = a0 + a1 x + a2 x^2 + a3 x^3, i.e. offset = -a0, heading = atan(-a1),
curvature = 2 a2, curvature rate (a clothoid) = 6 a3. It is linear in (a0, a1, a2, w, a3): iteratively
reweighted least squares with Huber weights (Huber 1964; Zhang, "Parameter estimation techniques", IVC 1997),
points assigned to a side by gating around the prediction, pseudo-observations for the priors (width, heading,
curvature and its rate near zero) so that one visible side suffices.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from .line_kind import line_kind
from .types import LaneEstimate, LaneFit, MarkingEvidence


@dataclass(frozen=True)
class FitConfig:
    """Settings of the joint lane fit: the priors, the side gate, the robust loss and the seeds of a fresh search."""

    width_prior_m: float = 3.7  # the lane width prior's mean [m]
    width_sigma_m: float = 0.4  # and its standard deviation [m]
    curvature_sigma_1pm: float = 0.01  # prior spread of the curvature around 0 [1/m]
    curvature_rate_sigma_1pm2: float = 1e-4  # prior spread of the curvature's change along the road [1/m²]
    heading_sigma_rad: float = 0.05  # prior spread of the car's heading relative to its lane [rad]
    gate_m: float = 0.7  # side-assignment gate around a prediction [m]
    huber_m: float = 0.08  # Huber threshold [m]
    min_points: int = 12  # fewest assigned points for a fit
    # a fresh search also grows each seed from a straight line, not only from its own near-range fit: a few scattered
    # near points can bend a short fit, and the bent boundary then gates out its own far markings
    straight_seeds: bool = False


def _initial_sides(pts: np.ndarray, cfg: FitConfig, candidates: int = 4) -> list[np.ndarray]:
    """Without a prediction: side assignments seeded by the strongest pairs of near-range lateral clusters that
    straddle the car about a lane apart, each distinct one once (each is fitted; the fit with the strongest evidence
    wins)."""
    near = pts[:, 0] < 16.0
    if near.sum() < 4:
        return []
    bins = np.arange(-6.0, 6.05, 0.15)
    hist, _ = np.histogram(pts[near, 1], bins=bins)
    hist = np.convolve(hist, [1, 2, 1], mode="same")
    centres = (bins[:-1] + bins[1:]) / 2
    pairs = []
    for i in np.flatnonzero((centres > 0) & (hist > 0)):
        for j in np.flatnonzero((centres < 0) & (hist > 0)):
            w = centres[i] - centres[j]
            if 2.6 <= w <= 4.8:
                score = min(hist[i], hist[j]) + 0.1 * (hist[i] + hist[j]) - 2.0 * abs(w - cfg.width_prior_m)
                pairs.append((score, centres[i], centres[j]))
    pairs.sort(reverse=True)
    # the clusters' own peaks: a seed takes no point nearer another peak than its own (a seam or an old line beside
    # a marking is a rival to be fitted on its own, not averaged with it)
    peaks = centres[(hist >= 2) & (hist >= np.roll(hist, 1)) & (hist >= np.roll(hist, -1))]

    def gate(y: float) -> float:
        others = np.abs(peaks - y)
        others = others[others > 0.2]
        return min(cfg.gate_m, 0.5 * float(others.min())) if others.size else cfg.gate_m

    out, seen = [], set()
    for _, yl, yr in pairs[:candidates]:
        # straight-line seeds over the near range only; the fit then grows along each boundary
        sides = np.zeros(len(pts), dtype=int)
        sides[near & (np.abs(pts[:, 1] - yl) < gate(yl))] = 1
        sides[near & (np.abs(pts[:, 1] - yr) < gate(yr))] = -1
        # neighbouring pairs often gate the same points: each distinct seed is grown once
        if sides.tobytes() not in seen:
            seen.add(sides.tobytes())
            out.append(sides)
    return out


@lru_cache(maxsize=8)
def _prior_normal(cfg: FitConfig) -> tuple[np.ndarray, np.ndarray]:
    """P^T P and P^T q of the priors, as pseudo-observations on the scaled parameters: w = w0, a2 = 0, a3 = 0
    and heading ~ 0 (a car drives roughly along its lane): a1 = 0 with sigma_heading."""
    P = np.array([[0, 0, 0, 1.0 / cfg.width_sigma_m, 0],
                  [0, 0, 2.0 * 0.01 / cfg.curvature_sigma_1pm, 0, 0],
                  [0, 0, 0, 0, 6.0 * 0.001 / cfg.curvature_rate_sigma_1pm2],
                  [0, 0.1 / cfg.heading_sigma_rad, 0, 0, 0]]) * cfg.huber_m
    q = np.array([cfg.width_prior_m / cfg.width_sigma_m, 0.0, 0.0, 0.0]) * cfg.huber_m
    return P.T @ P, P.T @ q


_UNSCALE = np.array([1.0, 0.1, 0.01, 1.0, 0.001])
_POLY = [0, 1, 2, 4]
"""Parameters that multiply powers of x (a0, a1, a2, a3); index 3 is the width."""


class _Points(NamedTuple):
    """One frame's evidence, prepared once per fit: y (N,); powers (N, 4) of x / 10 m (1, x, x^2, x^3), which
    keeps the normal equations well conditioned (undone with _UNSCALE); base (N,) point weights."""

    y: np.ndarray
    powers: np.ndarray
    base: np.ndarray

    @classmethod
    def of(cls, ev: MarkingEvidence) -> "_Points":
        xs = ev.points_m[:, 0] / 10.0
        base = np.clip(ev.strength, 1, None) * (1.0 if ev.weight is None else ev.weight)
        return cls(ev.points_m[:, 1], np.column_stack([np.ones_like(xs), xs, xs * xs, xs ** 3]), base)

    def boundary(self, params: np.ndarray, side: int) -> np.ndarray:
        """y of the fitted boundary on ``side`` at every point's x."""
        return self.powers @ (params[_POLY] / _UNSCALE[_POLY]) + side * params[3] / 2


class _Grown(NamedTuple):
    """strength: the inliers' evidence weights, favouring both sides seen (a bright marking outweighs a faint seam
    or strip of pale concrete beside it)."""

    strength: float
    params: np.ndarray
    sides: np.ndarray
    residual: np.ndarray
    used: np.ndarray
    cov: np.ndarray
    inliers: np.ndarray
    n_left: int
    n_right: int


def _solve(pts: _Points, sides: np.ndarray, cfg: FitConfig, iterations: int = 3):
    """IRLS on the normal equations (5 unknowns); returns params, residuals, mask of used points, covariance."""
    m = sides != 0
    y, X = pts.y[m], pts.powers[m]
    # columns: a0, a1, a2, w, and a3 (x^3) that absorbs curvature changing ahead (a clothoid: a3 = dkappa/ds / 6)
    A = np.column_stack([X[:, :3], sides[m] / 2.0, X[:, 3]])
    sig = cfg.huber_m
    PtP, Ptq = _prior_normal(cfg)
    base = pts.base[m]
    w2 = base / base.mean()
    for _ in range(iterations):
        # weighted normal equations (A^T W A + P^T P) p = A^T W y + P^T q
        Aw = A * w2[:, None]
        normal = A.T @ Aw + PtP
        sol = np.linalg.solve(normal, Aw.T @ y + Ptq)
        r = A @ sol - y
        # Huber weights: 1 inside the threshold, threshold/|r| outside
        w2 = base * (sig / np.maximum(np.abs(r), sig))
        w2 /= w2.mean()
    params = sol * _UNSCALE
    # parameter covariance: sigma^2 (A^T W A)^-1 with the weighted residual scale, back in unscaled units
    sigma2 = max(float(np.sum(w2 * r * r) / max(len(r) - 5, 1)), sig * sig / 4)
    cov = sigma2 * np.linalg.inv(normal) * np.outer(_UNSCALE, _UNSCALE)
    return params, r, m, cov


@lru_cache(maxsize=8)
def _straight(cfg: FitConfig) -> FitConfig:
    """``cfg`` with curvature and its rate held at 0 (priors of 1e-6 1/m and 1e-8 1/m^2): a straight-line fit."""
    return replace(cfg, curvature_sigma_1pm=1e-6, curvature_rate_sigma_1pm2=1e-8)


STRAIGHT_MARGIN = 1.1
"""With ``FitConfig.straight_seeds``, a lane grown from a straight start replaces the best grown from the seeds' own
near-range fits only when its evidence is this many times stronger: where scattered near points bent the near-range
fit, a straight start gathers 1.1-1.3 times its evidence; where nothing bent, a straight start is at most a few per
cent stronger and would pull a boundary off its dashes."""


GROW_REACH_M = (35.0,)
"""A fresh search (no prediction) grows the fit outwards: points nearer than each of these ranges first, so that a
boundary follows its own markings before far clutter (a vehicle ahead) can bend it [m]; one step, since more steps
can leave a boundary off its dashes."""


def _grow(pts: _Points, sides: np.ndarray, cfg: FitConfig, reach: tuple[float, ...] = (),
          straight: bool = False) -> _Grown | None:
    """Fit (a straight line first when ``straight``), re-gate the points around the fitted boundaries (those nearer
    than each range of ``reach`` first, then all of them: twice at most without a reach, until the assignment
    settles, once after one) and refit."""
    if (sides != 0).sum() < cfg.min_points:
        return None
    params, r, m, cov = _solve(pts, sides, _straight(cfg) if straight else cfg)
    x = pts.powers[:, 1] * 10.0
    for limit in reach + (np.inf,) * (2 if not reach else 1):
        new = np.zeros(len(pts.y), dtype=int)
        for s in (1, -1):
            new[(np.abs(pts.y - pts.boundary(params, s)) < 3 * cfg.huber_m + 0.1) & (x < limit)] = s
        if (new != 0).sum() < cfg.min_points or (np.isinf(limit) and np.array_equal(new, sides)):
            break
        sides = new
        params, r, m, cov = _solve(pts, sides, cfg)
    if not 2.4 <= params[3] <= 5.2:
        return None
    inl = np.abs(r) < 3 * cfg.huber_m
    left, right = (sides[m] == 1) & inl, (sides[m] == -1) & inl
    nl, nr = int(left.sum()), int(right.sum())
    wl, wr = float(pts.base[m][left].sum()), float(pts.base[m][right].sum())
    # strength favours both sides seen
    return _Grown(wl + wr + 2 * min(wl, wr), params, sides, r, m, cov, inl, nl, nr)


RIVAL_SHIFT_M = 0.5
"""A fitted lane is a rival of the best when either of its boundaries lies this far from the best's [m] (at
RIVAL_RANGE_M ahead): another pair of markings, not the same pair fitted again."""
RIVAL_RANGE_M = 10.0
"""The range ahead at which a rival's boundaries are compared with the best's [m]."""


def _boundaries_at(params: np.ndarray, x: float) -> np.ndarray:
    """(left, right) y [m] of a fit at x [m]: y = a0 + a1 x + a2 x^2 + a3 x^3 +- w / 2."""
    a0, a1, a2, w, a3 = params
    centre = a0 + a1 * x + a2 * x * x + a3 * x ** 3
    return np.array([centre + w / 2, centre - w / 2])


def _ambiguity(best: _Grown, grown: list[_Grown]) -> float:
    """The best rival's share of the evidence, s_rival / (s_best + s_rival) (``strength``; 0 without a rival)."""
    ref = _boundaries_at(best.params, RIVAL_RANGE_M)
    rivals = [g.strength for g in grown
              if np.abs(_boundaries_at(g.params, RIVAL_RANGE_M) - ref).max() > RIVAL_SHIFT_M]
    return max(rivals) / (best.strength + max(rivals)) if rivals else 0.0


def fit_lane(ev: MarkingEvidence, prior: LaneEstimate | None, cfg: FitConfig = FitConfig()) -> LaneFit | None:
    """Fit both boundaries; ``prior`` (a prediction) gates the assignment. None when evidence is too thin."""
    if len(ev.points_m) < cfg.min_points:
        return None
    if prior is not None and prior.valid:
        x, y = ev.points_m[:, 0], ev.points_m[:, 1]
        sides = np.zeros(len(x), dtype=int)
        gate = cfg.gate_m * (1.5 - 0.5 * prior.confidence)
        for s in (1, -1):
            sides[np.abs(y - prior.boundary_y(x, s)) < gate] = s
        seeds = [sides]
    else:
        seeds = _initial_sides(ev.points_m, cfg)
    pts = _Points.of(ev)
    reach = () if prior is not None and prior.valid else GROW_REACH_M
    grown = [g for g in (_grow(pts, sides, cfg, reach) for sides in seeds) if g is not None]
    straight = [g for g in (_grow(pts, sides, cfg, reach, True) for sides in seeds)
                if g is not None] if cfg.straight_seeds and reach else []
    if not grown and not straight:
        return None
    best = max(grown, key=lambda g: g.strength) if grown else None  # the first of equals
    alt = max(straight, key=lambda g: g.strength) if straight else None
    if best is None or (alt is not None and alt.strength > STRAIGHT_MARGIN * best.strength):
        best = alt
    grown += straight
    a0, a1, a2, w, a3 = best.params
    nl, nr = best.n_left, best.n_right
    ambiguity = _ambiguity(best, grown)
    # confidence: how much evidence, both sides seen, and the best lane's share of the evidence against its best
    # rival (two equally supported lanes about the car: a coin toss, 0.5 at most)
    support = min(1.0, (nl + nr) / 80.0) * (1.0 if nl >= 5 and nr >= 5 else 0.6) * (1.0 - ambiguity)
    est = LaneEstimate(-float(a0), float(np.arctan(-a1)), float(2 * a2), float(w), float(support),
                       curvature_rate_1pm2=float(6 * a3))
    r, inl = best.residual, best.inliers
    res = float(np.sqrt(np.mean(r[inl] ** 2))) if inl.any() else float("nan")
    # (a0, a1, a2, w, a3) -> (offset, heading, curvature, curvature_rate, width): rows of the Jacobian
    J = np.zeros((5, 5))
    J[0, 0], J[1, 1], J[2, 2], J[3, 4], J[4, 3] = -1.0, -1.0 / (1 + a1 * a1), 2.0, 6.0, 1.0
    side = np.where(best.used, best.sides, 0)
    inlier = np.zeros(len(side), bool)
    inlier[np.flatnonzero(best.used)[inl]] = True
    broken = tuple(line_kind(ev.points_m[inlier & (side == s), 0]) for s in (1, -1))
    return LaneFit(est, side, res, nl, nr, J @ best.cov @ J.T, ambiguity, broken)
