"""Evaluation plots as PNGs drawn with OpenCV (no plotting library is a dependency): the distribution of each
headline metric per scenario x condition (one dot per run, a bar at the mean), the range error against range per
scenario x condition, and the odometry trajectories (truth, visual odometry alone, the estimate)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from percept.outputs import png_bytes, write_bytes_atomic

from .metrics import run_metrics

FONT = cv2.FONT_HERSHEY_SIMPLEX
INK, GRID, DOT, MEAN = (40, 40, 40), (225, 225, 225), (200, 120, 30), (30, 30, 220)
PALETTE = [(170, 170, 170), (200, 120, 30), (40, 160, 40), (30, 30, 220), (160, 60, 160), (20, 170, 200)]
TRAJECTORY_SERIES = ("true", "estimate", "fused", "vo", "dead_reckoning")
"""The odometry trajectories of a run JSON (``odometry.trajectory``), the truth first."""
LEFT, RIGHT, TOP, BOTTOM = 190, 30, 64, 50
LEGEND_W = 170


def _ticks(lo: float, hi: float, n: int = 5) -> np.ndarray:
    """About n round tick values covering [lo, hi]."""
    span = hi - lo if hi > lo else 1.0
    step = 10 ** np.floor(np.log10(span / n))
    step *= min((m for m in (1, 2, 5, 10) if span / (step * m) <= n), default=10)
    return np.arange(np.ceil(lo / step) * step, hi + step / 2, step)


class _Canvas:
    """A white image with a plot area mapping data (x, y) to pixels."""

    def __init__(self, title: str, xr: tuple[float, float], yr: tuple[float, float], size=(900, 0), rows=0,
                 right: int = RIGHT):
        w = size[0]
        h = size[1] or TOP + BOTTOM + max(rows, 1) * 28 + 20
        self.img = np.full((h, w, 3), 255, np.uint8)
        self.x0, self.x1, self.y0, self.y1 = LEFT, w - right, TOP, h - BOTTOM
        pad = (xr[1] - xr[0]) * 0.05 or 1.0
        self.xr = (xr[0] - pad, xr[1] + pad)
        self.yr = yr if rows else (yr[0] - 0.05 * (yr[1] - yr[0] or 1.0), yr[1] + 0.05 * (yr[1] - yr[0] or 1.0))
        cv2.putText(self.img, title, (10, 28), FONT, 0.6, INK, 1, cv2.LINE_AA)

    def px(self, x, y) -> tuple[int, int]:
        u = self.x0 + (x - self.xr[0]) / (self.xr[1] - self.xr[0]) * (self.x1 - self.x0)
        v = self.y1 - (y - self.yr[0]) / (self.yr[1] - self.yr[0] or 1.0) * (self.y1 - self.y0)
        return int(round(u)), int(round(v))

    def x_axis(self, label: str) -> None:
        for t in _ticks(*self.xr):
            u = self.px(t, self.yr[0])[0]
            if not self.x0 <= u <= self.x1:
                continue
            cv2.line(self.img, (u, self.y0), (u, self.y1), GRID, 1)
            cv2.putText(self.img, f"{t:g}", (u - 14, self.y1 + 18), FONT, 0.4, INK, 1, cv2.LINE_AA)
        cv2.putText(self.img, label, (self.x0, self.y1 + 40), FONT, 0.45, INK, 1, cv2.LINE_AA)

    def y_axis(self, label: str) -> None:
        for t in _ticks(*self.yr):
            v = self.px(self.xr[0], t)[1]
            if not self.y0 <= v <= self.y1:
                continue
            cv2.line(self.img, (self.x0, v), (self.x1, v), GRID, 1)
            cv2.putText(self.img, f"{t:g}", (self.x0 - 60, v + 4), FONT, 0.4, INK, 1, cv2.LINE_AA)
        cv2.putText(self.img, label, (10, self.y0 - 8), FONT, 0.45, INK, 1, cv2.LINE_AA)


def distribution_png(title: str, groups: list[tuple[str, list[float]]]) -> np.ndarray:
    """One row per group (label, values): a dot per value and a red bar at the mean."""
    allv = [v for _, vs in groups for v in vs]
    c = _Canvas(title, (min(allv), max(allv)), (0, len(groups)), rows=len(groups))
    c.x_axis(title.split(" [")[0] if "[" not in title else title[title.index("["):])
    for i, (label, vs) in enumerate(groups):
        y = len(groups) - i - 0.5
        v = c.px(c.xr[0], y)[1]
        cv2.putText(c.img, label, (10, v + 4), FONT, 0.42, INK, 1, cv2.LINE_AA)
        for x in vs:
            cv2.circle(c.img, c.px(x, y), 4, DOT, -1, cv2.LINE_AA)
        u = c.px(float(np.mean(vs)), y)[0]
        cv2.line(c.img, (u, v - 10), (u, v + 10), MEAN, 2)
    return c.img


def lines_png(title: str, xlabel: str, ylabel: str, series: list[tuple[str, np.ndarray]],
              equal: bool = False) -> np.ndarray:
    """Polylines (label, (N, 2) points) with a legend; ``equal`` keeps metres square (trajectories)."""
    pts = np.concatenate([p for _, p in series])
    (xa, ya), (xb, yb) = pts.min(0), pts.max(0)
    size = (1000, 760 if equal else 500)
    pw, ph = size[0] - LEFT - LEGEND_W, size[1] - TOP - BOTTOM
    if equal:  # widen the shorter side so that one metre is as long on both axes (x gets 5 % padding each side)
        s = max((xb - xa) * 1.1 / pw, (yb - ya) * 1.1 / ph, 1e-9)
        cx, cy = (xa + xb) / 2, (ya + yb) / 2
        xa, xb = cx - s * pw / 2 / 1.1, cx + s * pw / 2 / 1.1
        ya, yb = cy - s * ph / 2, cy + s * ph / 2
    c = _Canvas(title, (xa, xb), (ya, yb), size=size, right=LEGEND_W)
    c.x_axis(xlabel)
    c.y_axis(ylabel)
    for i, (label, p) in enumerate(series):
        # the first series (the truth, where there is one) is drawn wide, so that the others show on it
        rgb = PALETTE[i % len(PALETTE)]
        cv2.polylines(c.img, [np.array([c.px(x, y) for x, y in p], np.int32)], False, rgb, 6 if i == 0 else 2,
                      cv2.LINE_AA)
    for i, (label, _) in enumerate(series):  # the legend, right of the plot area
        cv2.putText(c.img, label, (c.x1 + 14, c.y0 + 14 + 20 * i), FONT, 0.45, PALETTE[i % len(PALETTE)], 1,
                    cv2.LINE_AA)
    return c.img


def _runs(results, sc, c):
    return sorted((r for r in results if r.get("scenario") == sc and r.get("condition") == c and "error" not in r),
                  key=lambda r: r["seed"])


def write_plots(plan, results: list[dict], folder: Path, tasks) -> list[Path]:
    """Every plot the results allow, into ``folder``: each task's headline metrics, then each task's own plots
    (``Task.eval_plots``); the paths written."""
    images: dict[str, np.ndarray] = {}
    cells = [(sc, c) for sc in plan.scenarios for c in plan.conditions]
    metrics = {(sc, c): [run_metrics(r, tasks) for r in _runs(results, sc, c)] for sc, c in cells}
    for t in tasks:
        for h in t.headline:
            key = f"{t.name}.{h.key}"
            groups = [(f"{sc} / {c}", [m[key] for m in metrics[(sc, c)] if key in m]) for sc, c in cells]
            groups = [g for g in groups if g[1]]
            if groups:
                images[f"{key}.png"] = distribution_png(f"{t.name}: {h.label}", groups)
    for t in tasks:
        if t.eval_plots is not None:
            images.update(t.eval_plots(t.name, plan, results))
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for name, img in images.items():
        write_bytes_atomic(folder / name, png_bytes(img))
        out.append(folder / name)
    # plots/ is eval's own: a plot an earlier batch drew that this one does not would read as this batch's
    for stale in set(folder.glob("*.png")) - set(out):
        stale.unlink(missing_ok=True)
    return out


def range_error_by_range(task: str, plan, results: list[dict]) -> dict[str, np.ndarray]:
    """Per scenario, the in-path range error against range, one line per condition (the median over runs of each
    range bin's error, from the group's ``range_abs_rel_err_by_bin``)."""
    images = {}
    for sc in plan.scenarios:
        series = []
        for c in plan.conditions:
            per = [r[task].get("range_abs_rel_err_by_bin") or {} for r in _runs(results, sc, c)]
            names = sorted({b for p in per for b, v in p.items() if v is not None}, key=lambda b: int(b.split("-")[0]))
            # (bin centre [m], median relative error over the runs [%])
            pts = [(sum(map(float, b.split("-"))) / 2,
                    100.0 * float(np.median([p[b] for p in per if p.get(b) is not None]))) for b in names]
            if len(pts) >= 2:
                series.append((c, np.array(pts)))
        if series:
            images[f"{task}.range_error_by_range.{sc}.png"] = lines_png(
                f"{sc}: in-path range error against range (median over runs)", "range [m]", "|dZ|/Z [%]", series)
    return images


def worst_trajectories(task: str, plan, results: list[dict]) -> dict[str, np.ndarray]:
    """Per scenario x condition, the trajectories of the run whose estimate strayed furthest (landmark-fix ATE),
    so that a batch of hundreds of runs gets plots a reader can look through."""
    images = {}
    for sc in plan.scenarios:
        for c in plan.conditions:
            runs = [r for r in _runs(results, sc, c) if (r.get(task) or {}).get("trajectory")]
            if runs:
                r = max(runs, key=lambda r: r[task].get("ate_rmse_landmarks_m") or 0.0)
                traj = r[task]["trajectory"]
                series = [(name, np.asarray(traj[name], float)) for name in TRAJECTORY_SERIES if traj.get(name)]
                images[f"{task}.trajectory.{sc}-{c}-{r['seed']}.png"] = lines_png(
                    f"{task} {sc} / {c} / seed {r['seed']} (worst ATE of {len(runs)})", "x [m]", "y [m]", series,
                    equal=True)
    return images
