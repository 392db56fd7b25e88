"""`percept odometry`: visual odometry over a KITTI-layout folder, stereo when both cameras are there, else
monocular with the scale from the camera's height; scored against poses.txt when the folder has one.

Registered on the main typer app by ``percept.cli.app``; parses options, calls ``percept.odometry``, prints.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated, Optional

import numpy as np
import typer

from percept.odometry.trajectory_io import TrajectoryFormat

from . import options as opt

PLOT_NAME = "trajectory.png"
FRAME_PERIOD_S = 0.1
"""Timestamps of a TUM file when the folder has no times.txt: KITTI's 10 Hz."""


def odometry(
    folder: Annotated[Path, typer.Argument(help="KITTI-layout folder: image_0/ or image_l/ (image_1/ or image_r/ "
                                                "for stereo), calib.txt, optional poses.txt and times.txt.")],
    json_path: opt.JsonOut = None,
    poses_out: Annotated[Optional[Path], typer.Option("--poses-out", dir_okay=False, help="Write the estimated "
                                                      "trajectory (world-from-camera poses) to this file.")] = None,
    fmt: Annotated[TrajectoryFormat, typer.Option("--format", help="Layout of --poses-out: kitti (12 numbers a "
                                                  "line) or tum (timestamp tx ty tz qx qy qz qw).")] =
    TrajectoryFormat.KITTI,
    out: Annotated[Optional[Path], typer.Option("--out", help=f"Folder for {PLOT_NAME}: the path seen from above "
                                                "(estimated and true).")] = None,
    camera_height: Annotated[float, typer.Option("--camera-height", help="Height of the left camera above the "
                                                 "road in metres, 0.1 to 10; gives the monocular scale (stereo: "
                                                 "where the near road's disparity search starts).")] = 1.65,
):
    """Visual odometry on a recorded sequence: stereo (PnP on stereo depth) when the folder has right images,
    else monocular (essential matrix, scale from the road plane and --camera-height).

    Poses accumulate T_k = T_(k-1) T_step; a step that fails adds no motion and is counted. With poses.txt the
    estimate starts from its first pose and is scored: ATE RMSE, KITTI drift (segments scaled to the run),
    final position error. Refuses (exit code 2) a folder without images or P0, images of mixed sizes and a
    poses.txt whose line count is not the image count. Every output is written complete or not at all.
    """
    from percept.cli.common import check_outputs, fail, on_interrupt
    from percept.odometry.kitti_folder import load_kitti_folder

    opt.check_number("--camera-height", camera_height, 0.1, 10.0)
    try:
        seq = load_kitti_folder(folder)
    except ValueError as e:
        fail(str(e))
    if out is not None and out.exists() and not out.is_dir():
        fail(f"--out {out} is a file; give a folder")
    plot = None if out is None else out / PLOT_NAME
    inputs = [*seq.left, *(seq.right or ()), folder / "calib.txt", folder / "poses.txt", folder / "times.txt"]
    check_outputs([json_path, poses_out, plot], inputs)
    on_interrupt("nothing was written (every output is written only when the run is complete)")
    est, failed, reasons, ms = _run(seq, camera_height)
    if seq.poses is not None:
        est = seq.poses[0] @ est  # the estimate starts from the known first pose
    data = {"folder": str(folder), "mode": "stereo" if seq.stereo else "mono", "frames": len(seq),
            "steps_failed": failed, "failure_reasons": reasons, "ms_per_frame": ms,
            "camera_height_m": camera_height,
            "baseline_m": seq.baseline_m if seq.stereo else None,
            **_scores(est, seq.poses), "outputs": [str(p) for p in (json_path, poses_out, plot) if p is not None]}
    _print_summary(data)
    _write(data, est, seq, json_path, poses_out, fmt, plot)


def _run(seq, camera_height: float) -> tuple[np.ndarray, int, dict, float]:
    """(poses (N, 4, 4) in the first camera's frame, failed steps, {reason: count}, ms per frame)."""
    from percept.cli.common import fail, progress_bar
    from percept.sensors import read_image

    if seq.stereo:
        from percept.odometry.stereo_vo import StereoVO

        vo, label = StereoVO(seq.K, seq.baseline_m, camera_height), "stereo odometry"
    else:
        from percept.odometry.mono_vo import MonoVO

        vo, label = MonoVO(seq.K, camera_height), "mono odometry"
    poses, failed, reasons, spent = [np.eye(4)], 0, {}, 0.0
    with progress_bar() as bar:
        task = bar.add_task(label, total=len(seq))
        for k, path in enumerate(seq.left):
            try:
                images = [read_image(p, gray=True) for p in (path, *((seq.right[k],) if seq.stereo else ()))]
                t0 = time.perf_counter()
                step = vo.process(*images)
                spent += time.perf_counter() - t0
            except ValueError as e:
                fail(f"frame {k} ({path.name}): {e}")
            ok = step.ok and np.all(np.isfinite(step.T_prev_cur))
            if k > 0:  # the first frame has no motion to measure: neither a step nor a failure
                # T_k = T_(k-1) T_prev_cur; a failed step adds no motion
                poses.append(poses[-1] @ step.T_prev_cur if ok else poses[-1].copy())
                if not ok:
                    failed += 1
                    reason = step.reason or "not measured"
                    reasons[reason] = reasons.get(reason, 0) + 1
            bar.advance(task)
    return np.stack(poses), failed, reasons, 1000.0 * spent / len(seq)


def _scores(est: np.ndarray, true: Optional[np.ndarray]) -> dict:
    """Path lengths and, against ``true`` (N, 4, 4) when given, ATE, KITTI drift and final error (else None)."""
    from percept.odometry.metrics import ate_rmse_m, final_position_error_m, kitti_drift, path_length_m

    scores = {"path_length_m": path_length_m(est), "true_path_length_m": None, "ate_rmse_m": None,
              "drift_pct": None, "rot_drift_deg_per_100m": None, "final_error_m": None,
              "final_error_pct_of_path": None}
    if true is None:
        return scores
    length = path_length_m(true)
    drift = kitti_drift(est, true)
    final = final_position_error_m(est, true)
    return {**scores, "true_path_length_m": length, "ate_rmse_m": ate_rmse_m(est, true),
            "drift_pct": drift["drift_pct"], "rot_drift_deg_per_100m": drift["rot_drift_deg_per_100m"],
            "final_error_m": final, "final_error_pct_of_path": 100.0 * final / length if length > 0 else None}


def _print_summary(d: dict) -> None:
    """The run's figures as a table."""
    from rich.table import Table

    from percept.cli.common import console, fmt

    t = Table(title=f"{d['mode']} odometry on {d['frames']} frames of {d['folder']}")
    t.add_column("metric")
    t.add_column("value", justify="right")
    rows = (("failed steps", f"{d['steps_failed']} of {d['frames'] - 1}"),
            ("path length m (estimated / true)", f"{fmt(d['path_length_m'])} / {fmt(d['true_path_length_m'])}"),
            ("final error m (% of path)", f"{fmt(d['final_error_m'])} ({fmt(d['final_error_pct_of_path'])} %)"),
            ("ATE RMSE m", fmt(d["ate_rmse_m"], "{:.3f}")), ("drift %", fmt(d["drift_pct"])),
            ("rotation drift deg/100 m", fmt(d["rot_drift_deg_per_100m"])), ("ms per frame", fmt(d["ms_per_frame"],
                                                                                                  "{:.0f}")))
    for name, value in rows:
        t.add_row(name, value)
    console.print(t)


def _write(data: dict, est: np.ndarray, seq, json_path, poses_out, fmt: TrajectoryFormat, plot) -> None:
    """The JSON, the trajectory file and the plot, written as one unit: all complete, or none replaced."""
    import json

    from percept.cli.common import console, fail, write_error
    from percept.odometry.trajectory_io import format_trajectory
    from percept.outputs import png_bytes, write_files_atomic

    files = {}
    if poses_out is not None:
        times = seq.timestamps_s if seq.timestamps_s is not None else FRAME_PERIOD_S * np.arange(len(est))
        try:
            files[Path(poses_out)] = format_trajectory(est, times, fmt).encode()
        except ValueError as e:
            fail(f"--poses-out: {e}")
    if plot is not None:
        title = (f"{data['mode']}, {data['frames']} frames" + ("" if data["final_error_pct_of_path"] is None else
                 f", final error {data['final_error_pct_of_path']:.2f} % of path"))
        files[plot] = png_bytes(draw_trajectories(est[:, [0, 2], 3], None if seq.poses is None else
                                                  seq.poses[:, [0, 2], 3], title, data["mode"]))
    if json_path is not None:
        files[Path(json_path)] = json.dumps(data, indent=2).encode()
    try:
        write_files_atomic(files)
    except OSError as e:
        fail(write_error(next(iter(files)), e))
    for p in files:
        console.print(f"wrote {p}")


def _nice_step(span_m: float, lines: int = 8) -> float:
    """A grid step of 1, 2 or 5 x 10^k metres giving at most about ``lines`` lines over ``span_m``."""
    raw = max(span_m / lines, 1e-3)
    k = 10.0 ** np.floor(np.log10(raw))
    return float(next(m * k for m in (1, 2, 5, 10) if m * k >= raw))


def draw_trajectories(est_xz: np.ndarray, true_xz: Optional[np.ndarray], title: str, mode: str,
                      size_px: int = 720) -> np.ndarray:
    """BGR (size, size, 3) top-down plot of camera positions (N, 2) as (x, z) [m] (x right, z forward, camera
    axes of the first camera): equal axes, a metre grid with labels, a scale bar and a legend."""
    import cv2

    pts = np.concatenate([est_xz, true_xz]) if true_xz is not None else est_xz
    margin, lo, hi = 60, pts.min(axis=0), pts.max(axis=0)
    span = max(float((hi - lo).max()) * 1.1, 1.0)
    corner = (lo + hi) / 2 - span / 2
    s = (size_px - 2 * margin) / span  # px per metre, the same on both axes

    def px(xz: np.ndarray) -> np.ndarray:
        # u = margin + (x - x0) s; v = size - margin - (z - z0) s (forward is up)
        return np.column_stack([margin + (xz[:, 0] - corner[0]) * s,
                                size_px - margin - (xz[:, 1] - corner[1]) * s]).round().astype(np.int32)

    img = np.full((size_px, size_px, 3), 255, np.uint8)
    step = _nice_step(span)
    font, grey = cv2.FONT_HERSHEY_SIMPLEX, (200, 200, 200)
    for axis in (0, 1):
        for g in np.arange(np.ceil(corner[axis] / step), np.floor((corner[axis] + span) / step) + 1) * step:
            a = np.array([[g, corner[1]], [g, corner[1] + span]]) if axis == 0 else \
                np.array([[corner[0], g], [corner[0] + span, g]])
            (u0, v0), (u1, v1) = px(a)
            cv2.line(img, (u0, v0), (u1, v1), grey, 1)
            at = (u0 - 12, size_px - margin + 18) if axis == 0 else (8, v0 + 4)
            cv2.putText(img, f"{g + 0.0:g}", at, font, 0.4, (90, 90, 90), 1, cv2.LINE_AA)
    curves = [(est_xz, (200, 60, 0), f"estimated ({mode})")]
    if true_xz is not None:
        curves.append((true_xz, (0, 0, 220), "ground truth"))
    for k, (xz, colour, label) in reversed(list(enumerate(curves))):  # the estimate drawn over the truth
        cv2.polylines(img, [px(xz).reshape(-1, 1, 2)], False, colour, 3 if k else 2, cv2.LINE_AA)
        cv2.line(img, (margin + 10, margin + 20 + 22 * k), (margin + 40, margin + 20 + 22 * k), colour, 2)
        cv2.putText(img, label, (margin + 48, margin + 25 + 22 * k), font, 0.5, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.circle(img, tuple(int(v) for v in px(est_xz[:1])[0]), 5, (0, 0, 0), -1)
    bar, right = int(round(step * s)), size_px - margin - 10  # scale bar, top right
    cv2.line(img, (right - bar, margin + 20), (right, margin + 20), (0, 0, 0), 3)
    cv2.putText(img, f"{step:g} m", (right - bar, margin + 12), font, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(img, title, (margin, 30), font, 0.55, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(img, "x [m] (right)", (size_px // 2 - 50, size_px - 8), font, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    cv2.putText(img, "z [m] (forward)", (4, margin - 8), font, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    return img
