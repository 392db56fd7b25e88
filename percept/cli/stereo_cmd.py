"""`percept stereo`: dense disparity and depth of a rectified image pair, against OpenCV's StereoSGBM.

Registered on the main typer app by ``percept.cli.app``; parses options, calls ``percept.longitudinal.dense``,
prints.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import numpy as np
import typer

from . import options as opt

MAX_AUTO_WIDTH = 1000
"""Without --scale, images wider than this are halved until they are not [px]: dense matching's cost grows with the
pixel count times the disparity range, and both grow with the width."""
MAX_ROW_MISALIGNMENT_PX = 1.5
"""A pair whose matched features differ by more rows than this (median) is refused as not rectified."""
LABELS = {"percept": "percept dense", "sgbm": "SGBM plain", "sgbm_sample": "SGBM sample"}
OUT_FILES = ("disparity.png", "depth.npy", "disparity_sgbm.png")


def stereo(
    left: Annotated[Path, typer.Argument(help="Left image of a rectified pair.")],
    right: Annotated[Path, typer.Argument(help="Right image of the pair (same size).")],
    calib: Annotated[Path, typer.Option("--calib", help="Middlebury calib.txt or the stereo_calib.json of "
                                                        "`percept calibrate --stereo`.")],
    gt: Annotated[Optional[Path], typer.Option("--gt", help="Ground-truth disparity of the left image (.npz, .npy "
                                                            "or .pfm, same size): adds error metrics.")] = None,
    json_path: opt.JsonOut = None,
    out: Annotated[Optional[Path], typer.Option("--out", help="Folder for disparity.png, depth.npy (metres) and "
                                                              "disparity_sgbm.png.")] = None,
    scale: Annotated[Optional[float], typer.Option("--scale", help="Resize the pair by this factor, 0.05 to 1 "
                                                                   "(default: halve until at most 1000 px "
                                                                   "wide).")] = None,
    num_disparities: Annotated[Optional[int], typer.Option("--num-disparities", help="Search range in px at the "
                                                           "working scale, a multiple of 16 from 16 to 1024 and "
                                                           "below the working width less half the block (default: "
                                                           "the calibration's ndisp, else width/6, within that "
                                                           "bound).")] = None,
    block_size: Annotated[int, typer.Option("--block-size", help="Matching block in px, odd, 1 to 11.")] = 3,
):
    """Dense disparity and depth of a rectified pair: percept's dense mode against OpenCV's StereoSGBM.

    percept's dense mode: SGBM both ways, WLS filter with left-right confidence, hole filling, sub-pixel steps.
    Both run with the same range and block in one run. With --gt: bad 2.0 px %, mean error, depth error.
    Refuses (exit code 2) images of different sizes, a pair whose rows do not match, unreadable files (empty,
    truncated, not an image), a search range too wide for the images and a calibration without a baseline. Every output is written complete or not at all.
    """
    from percept.cli.common import check_outputs, fail, on_interrupt
    from percept.longitudinal.dense import DenseConfig
    from percept.sensors.stereo_io import RectifiedStereo

    opt.check_number("--scale", scale, 0.05, 1.0)
    try:  # the matcher's own checks, before any work; the bound set by the width is checked once the pair is read
        DenseConfig(num_disparities=16 if num_disparities is None else num_disparities, block_size=block_size)
    except ValueError as e:
        fail(f"--{str(e).replace('_', '-')}")
    if out is not None and out.exists() and not out.is_dir():
        fail(f"--out {out} is a file; give a folder")
    outputs = [] if out is None else [out / name for name in OUT_FILES]
    check_outputs([json_path, *outputs], [left, right, calib, gt])
    on_interrupt("nothing was written (every output is written only when complete)")
    try:
        rig = RectifiedStereo.load(calib)
    except ValueError as e:
        fail(str(e))
    left_img, right_img, truth, rig, s = _inputs(left, right, gt, rig, scale)
    h, w = left_img.shape[:2]
    cfg = DenseConfig(num_disparities=_search_range(num_disparities, w, h, s, block_size, rig.ndisp),
                      block_size=block_size)
    rows = _check_rectified(left_img, right_img)
    results = _run(left_img, right_img, truth, rig, cfg)
    _print_table(results, s, w, h, cfg.num_disparities, truth is not None)
    header = {"left": str(left), "right": str(right), "calibration": rig.to_dict(),
              "ground_truth": None if gt is None else str(gt), "scale": s, "image_size_px": [w, h],
              "num_disparities": cfg.num_disparities, "block_size": block_size, "row_misalignment_px": rows[0],
              "row_matches": rows[1], "note": _note(s, gt is not None)}
    _write(out, json_path, results, {**header, **results["percept"]["metrics"], "outputs": [str(p) for p in outputs],
                                     "methods": {k: {**v["metrics"], "ms": v["ms"]} for k, v in results.items()}})


def max_num_disparities(width: int, block_size: int) -> int:
    """The widest search range [px] OpenCV's StereoSGBM accepts on images ``width`` px wide: the largest multiple
    of 16, at most 1024, that leaves more than half a block of columns to match, n + block_size // 2 < width."""
    from percept.longitudinal.dense import MAX_DISPARITIES

    # n + b // 2 < w, n a multiple of 16
    return min(MAX_DISPARITIES, (width - block_size // 2 - 1) // 16 * 16)


def _search_range(num_disparities: Optional[int], w: int, h: int, s: float, block_size: int,
                  ndisp: Optional[int]) -> int:
    """The search range [px] for the pair (w x h px at the working scale ``s``): --num-disparities when it is within
    ``max_num_disparities``, a one-line error when it is wider, else the default cut to that bound."""
    from percept.cli.common import fail
    from percept.longitudinal.dense import default_num_disparities

    n_max = max_num_disparities(w, block_size)
    if num_disparities is not None and num_disparities > n_max:
        fail(f"--num-disparities must be a multiple of 16 from 16 to {n_max} for these {w}x{h} px images at scale "
             f"{s:g} with --block-size {block_size}, got {num_disparities}; lower it or raise --scale")
    return num_disparities if num_disparities is not None else min(default_num_disparities(w, ndisp), n_max)


def _note(s: float, with_gt: bool) -> str:
    """The JSON's note on the units of pixel values at the working scale ``s``."""
    return (f"pixel values (disparities, errors) are at the working scale {s:g} of the input images"
            + ("; the ground truth was resized by nearest neighbour and its disparities multiplied by the scale"
               if with_gt and s != 1.0 else ""))


def _auto_scale(width: int) -> float:
    """The working scale without --scale: 1 halved until ``width`` [px] is at most MAX_AUTO_WIDTH."""
    s = 1.0
    while width * s > MAX_AUTO_WIDTH:
        s /= 2.0
    return s


def _inputs(left: Path, right: Path, gt: Optional[Path], rig, scale: Optional[float]):
    """(left, right, ground truth or None, rig, scale) at the working scale; one-line errors for bad input."""
    import cv2

    from percept.cli.common import fail
    from percept.longitudinal.dense import check_pair
    from percept.sensors import read_image
    from percept.sensors.stereo_io import read_disparity, resize_disparity

    try:
        images = [read_image(p) for p in (left, right)]
        check_pair(*images)
        truth = None if gt is None else read_disparity(gt)
        h, w = images[0].shape[:2]
        if truth is not None and truth.shape != (h, w):
            raise ValueError(f"the ground truth {gt} is {truth.shape[1]}x{truth.shape[0]} px but the images are "
                             f"{w}x{h}; give the disparity map of the left image")
        rig = rig.for_image(w, h)
    except ValueError as e:
        fail(str(e))
    s = scale if scale is not None else _auto_scale(w)
    size = (max(1, round(w * s)), max(1, round(h * s)))
    if min(size) < 32:
        fail(f"at scale {s:g} the images are {size[0]}x{size[1]} px; at least 32x32 are needed (raise --scale)")
    if s != 1.0:
        images = [cv2.resize(im, size, interpolation=cv2.INTER_AREA) for im in images]
        truth = None if truth is None else resize_disparity(truth, *size)
        rig = rig.scaled(size[0] / w)
    return images[0], images[1], truth, rig, s


def _check_rectified(left: np.ndarray, right: np.ndarray) -> tuple[Optional[float], int]:
    """Measure the rows' misalignment; refuse a pair above MAX_ROW_MISALIGNMENT_PX, warn when it cannot be told."""
    from rich.markup import escape

    from percept.cli.common import err, fail
    from percept.longitudinal.dense import row_misalignment_px

    dy, count = row_misalignment_px(left, right)
    if dy is None:
        why = f"only {count} consistent feature matches: cannot check that the pair is rectified"
        err.print(f"[yellow]warning:[/] {escape(why)}", highlight=False, soft_wrap=True)
    elif dy > MAX_ROW_MISALIGNMENT_PX:
        fail(f"the pair is not rectified: matched features differ by a median {dy:.2f} rows over {count} matches "
             f"(at most {MAX_ROW_MISALIGNMENT_PX} allowed); rectify it first (e.g. cv2.stereoRectify and "
             "cv2.initUndistortRectifyMap with the rig's calibration)")
    return dy, count


def _run(left: np.ndarray, right: np.ndarray, truth: Optional[np.ndarray], rig, cfg) -> dict:
    """Per method: disparity [px], depth [m], metrics (against ``truth``, or summary statistics) and ms."""
    from percept.longitudinal.dense import compare_methods
    from percept.longitudinal.metrics import disparity_metrics, disparity_summary

    results = {}
    for name, (d, ms) in compare_methods(left, right, cfg).items():
        z = rig.depth_m(d)
        metrics = (disparity_summary(d, z) if truth is None else
                   disparity_metrics(d, truth, rig.fx, rig.baseline_m, rig.doffs_px))
        results[name] = {"disparity": d, "depth": z, "metrics": metrics, "ms": ms}
    return results


def _print_table(results: dict, s: float, w: int, h: int, n: int, with_gt: bool) -> None:
    """Each method's metrics and time as a table."""
    from rich.table import Table

    from percept.cli.common import console, fmt

    t = Table(title=f"dense stereo at scale {s:g} ({w}x{h} px, {n} disparities)",
              caption="SGBM plain: StereoSGBM_create(0, n, block); SGBM sample: OpenCV's stereo_match settings"
                      + ("; a pixel without estimate counts as bad" if with_gt else ""))
    cols = (("bad 2.0 %", "bad_2_0_pct"), ("MAE px", "mae_px"), ("Z rel. err", "depth_abs_rel_err"),
            ("density %", "density_pct")) if with_gt else (
        ("density %", "density_pct"), ("d p50 px", "disparity_px_p50"), ("Z p5 m", "depth_m_p5"),
        ("Z p50 m", "depth_m_p50"), ("Z p95 m", "depth_m_p95"))
    t.add_column("method")
    for label, _ in cols:
        t.add_column(label, justify="right")
    t.add_column("ms", justify="right")
    for name, r in results.items():
        spec = {"depth_abs_rel_err": "{:.4f}", "density_pct": "{:.1f}"}
        t.add_row(LABELS[name], *(fmt(r["metrics"][k], spec.get(k, "{:.2f}")) for _, k in cols), f"{r['ms']:.0f}")
    console.print(t)


def colour_disparity(d: np.ndarray, d_max: float) -> np.ndarray:
    """BGR uint8 image of a disparity map: turbo colour map over 0 .. d_max px, black where there is none."""
    import cv2

    ok = np.isfinite(d)
    u8 = np.clip(np.nan_to_num(d) * (255.0 / max(d_max, 1e-6)), 0, 255).astype(np.uint8)
    img = cv2.applyColorMap(u8, cv2.COLORMAP_TURBO)
    img[~ok] = 0
    return img


def _write(out: Optional[Path], json_path: Optional[Path], results: dict, data: dict) -> None:
    """disparity.png, depth.npy, disparity_sgbm.png (with ``out``; one colour scale for both PNGs) and the JSON,
    written as one unit: all complete, or none replaced."""
    import json

    from percept.cli.common import console, fail, write_error
    from percept.outputs import npy_bytes, png_bytes, write_files_atomic

    files = {}
    if out is not None:
        ours, peer = results["percept"]["disparity"], results["sgbm"]["disparity"]
        finite = ours[np.isfinite(ours)]
        d_max = float(np.percentile(finite, 99.5)) if finite.size else 1.0
        files[out / "depth.npy"] = npy_bytes(results["percept"]["depth"])
        for name, d in (("disparity.png", ours), ("disparity_sgbm.png", peer)):
            files[out / name] = png_bytes(colour_disparity(d, d_max))
    if json_path is not None:
        files[Path(json_path)] = json.dumps(data, indent=2).encode()
    try:
        write_files_atomic(files)
    except OSError as e:
        fail(write_error(out if out is not None else json_path, e))
    if out is not None:
        console.print(f"wrote {', '.join(OUT_FILES)} in {out}")
