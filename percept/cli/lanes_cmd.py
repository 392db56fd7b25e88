"""`percept lanes`: the lane module on recorded footage.

Registered on the main typer app by ``percept.cli.app``; parses options, calls ``percept.lanes``, prints.
"""

from __future__ import annotations

import itertools
import math
import time
from enum import Enum
from pathlib import Path
from typing import Optional

import numpy as np
import typer

from .common import Command


class LanesFormat(str, Enum):
    """The JSON layout of ``percept lanes``."""

    PERCEPT = "percept"  # every estimate
    TUSIMPLE = "tusimple"  # the TuSimple benchmark's prediction lines


CALIBRATION_IMAGES = 30
"""At most this many images of a folder (evenly spread) measure the camera height."""


def register(app: typer.Typer) -> None:
    """Add the ``lanes`` command to ``app``."""

    @app.command("lanes", cls=Command)
    def lanes(
        source: Path = typer.Argument(..., help="An image, a video or a folder of images (dash camera, road ahead)."),
        json_path: Optional[Path] = typer.Option(None, "--json",
                                                 help="Write per-image / per-frame results to this JSON file."),
        out: Optional[Path] = typer.Option(None, "--out", help="Folder for overlays: NAME.lanes.png per image, "
                                                               "NAME.lanes.mp4 for a video."),
        calib: Optional[Path] = typer.Option(None, "--calib", help="Calibration JSON from `percept calibrate`: "
                                                                   "undistort and use its intrinsics."),
        mount_height: Optional[float] = typer.Option(
            None, "--mount-height", help="Camera height above the road in metres, 0.2 to 10; scales the metric values. "
                                         "Without it the height is measured from the lanes' width (--lane-width): "
                                         "over all the images of a folder, or the first frames of a video."),
        lane_width: float = typer.Option(3.65, "--lane-width", help="Width of the lanes filmed in metres, 2 to 6 (US "
                                                                    "freeways 3.6-3.7), used without --mount-height."),
        hfov: float = typer.Option(60.0, "--hfov", help="Horizontal field of view in degrees (3 to 177), used "
                                                        "without --calib."),
        speed: float = typer.Option(0.0, "--speed", help="Assumed speed in m/s (0 to 100) for tracking through a "
                                                         "video (0: no motion model)."),
        max_frames: Optional[int] = typer.Option(None, "--max-frames", help="Process at most this many video frames "
                                                                          "(at least 1)."),
        fmt: LanesFormat = typer.Option(LanesFormat.PERCEPT, "--format", help="JSON layout: percept (every "
                                        "estimate) or tusimple (the benchmark's prediction lines: each boundary's x "
                                        "at its h_samples rows, -2 where none; images only)."),
    ):
        """Fit the ego lane on recorded footage; pitch and horizon come from the lane lines' vanishing point.

        The JSON and every overlay are written complete or not at all: an error, a full disk or Ctrl-C leaves the
        files that were there untouched. Overlays of a folder are written one by one as each image is done.
        A single image that cannot be read (empty, truncated, not an image) is refused; in a folder it is skipped
        with a warning line naming it and listed in the JSON with its error.
        """
        _lanes(source, json_path, out, calib, mount_height, lane_width, hfov, speed, max_frames, fmt)


def _lanes(source: Path, json_path, out, calib, mount_height, lane_width: float, hfov: float, speed: float,
           max_frames, fmt: LanesFormat) -> None:
    """``percept lanes`` once its options are parsed: check them, list the footage, fit and write."""
    from percept.cli.common import check_outputs, fail
    from percept.cli.footage_out import footage_for, overlay_path
    from percept.lanes.realworld import FootageLanes, RealLaneConfig
    from percept.sensors import CameraCalibration, FootageKind, list_footage

    _check_options(mount_height, lane_width, hfov, speed, max_frames, fmt, json_path)
    try:
        cfg = RealLaneConfig(hfov_rad=math.radians(hfov), mount_height_m=mount_height, lane_width_m=lane_width,
                             speed_mps=speed)
        cal = CameraCalibration.load(calib) if calib is not None else None
        kind, files = list_footage(source)
        files = footage_for(files, out, "lanes")
    except ValueError as e:
        fail(str(e))
    video = kind is FootageKind.VIDEO
    if video and fmt is LanesFormat.TUSIMPLE:
        fail("--format tusimple is for images (TuSimple scores stills); extract the video's frames into a folder")
    overlays = [] if out is None else [overlay_path(out, p, "lanes", video) for p in files]
    check_outputs([json_path, *overlays], [*files, calib])
    runner = FootageLanes(cfg, cal)
    header = {"source": str(source), "kind": kind.value, "calibration": None if calib is None else str(calib),
              "hfov_deg": None if cal is not None else hfov, "lane_width_m": lane_width,
              "assumed_speed_mps": speed}
    if video:
        _run_video(runner, files[0], out, json_path, max_frames, header)
    else:
        _run_images(runner, files, out, json_path, header, single=source.is_file(),
                    tusimple=fmt is LanesFormat.TUSIMPLE)


def _check_options(mount_height, lane_width, hfov, speed, max_frames, fmt: LanesFormat, json_path) -> None:
    """One-line errors (exit 2) for option values out of range or that do not go together."""
    from percept.cli.common import fail
    from percept.cli.options import check_number

    check_number("--mount-height", mount_height, 0.2, 10.0)
    check_number("--lane-width", lane_width, 2.0, 6.0)
    check_number("--hfov", hfov, 3.0, 177.0)
    check_number("--speed", speed, 0.0, 100.0)
    check_number("--max-frames", max_frames, 1, 10**7)
    if fmt is LanesFormat.TUSIMPLE and json_path is None:
        fail("--format tusimple describes the --json file; give --json OUT")


def _record(result, **keys) -> dict:
    """One image's or frame's JSON record: ``keys`` (file, frame, time) and the fit's figures."""
    return {**keys, **result.to_dict()}


def _summary(records: list[dict], ms: list[float]) -> dict:
    """The JSON summary: read and unreadable records, in how many a lane and both boundaries were found, the median
    time [ms]."""
    from percept.cli.footage_out import summary

    return summary(records, ms, lambda ok: {"both_boundaries": sum(bool(r["both_boundaries"]) for r in ok),
                                            "lane_found": sum(r["offset_m"] is not None for r in ok)})


def _print_summary(title: str, summary: dict, out: Optional[Path]) -> None:
    """The summary as one line, and where the overlays are."""
    from percept.cli.common import console
    from percept.cli.footage_out import summary_tail

    console.print(f"{title}: lane found in {summary['lane_found']} of {summary['count']}, both boundaries in "
                  f"{summary['both_boundaries']}" + summary_tail(summary))
    if out is not None:
        console.print(f"overlays in {out}")


def _calibrate(runner, files: list[Path], header: dict) -> None:
    """Without a given height: measure it over (up to CALIBRATION_IMAGES of) the folder's images, one camera."""
    from percept.cli.common import console
    from percept.sensors import read_image

    if runner.height_m is None and len(files) > 1:
        pick = files if len(files) <= CALIBRATION_IMAGES else [files[int(i)] for i in np.linspace(
            0, len(files) - 1, CALIBRATION_IMAGES)]
        images = []
        for p in pick:
            try:
                images.append(read_image(p))
            except ValueError:
                continue  # reported when the image's turn comes
        if images and runner.calibrate(images) is not None:
            console.print(f"camera height {runner.height_m:.2f} m from the lane width over {len(images)} images")
    header["mount_height_m"] = runner.height_m
    header["mount_height_source"] = runner.height_source or "lane-width prior (each image)"


def _run_images(runner, files: list[Path], out: Optional[Path], json_path: Optional[Path], header: dict,
                single: bool, tusimple: bool = False) -> None:
    """The lane fit on each image, then the JSON (percept's or TuSimple's layout) and a summary."""
    from percept.cli.common import fail, write_json
    from percept.cli.footage_out import process_images
    from percept.lanes.overlay import draw_overlay
    from percept.lanes.tusimple import tusimple_record

    _calibrate(runner, files, header)

    def work(image, path):
        t0 = time.perf_counter()
        result = runner.still(image)
        ms = 1000 * (time.perf_counter() - t0)
        h, w = image.shape[:2]
        record = tusimple_record(result, str(path), h, w, ms) if tusimple else _record(result, file=str(path))
        return record, lambda: draw_overlay(runner.prepare(image), result, path.name)

    records, ms = process_images(files, out, "lanes", "lanes on images", single, work)
    if tusimple:
        done = [r for r in records if "error" not in r]
        if not done:
            fail(f"none of the {len(files)} images could be read; no JSON was written")
        _write_lines(json_path, done)
        from percept.cli.common import console

        console.print(f"{len(done)} image(s) in TuSimple's format: {json_path}")
        return
    summary = _summary(records, ms)
    if summary["count"] == 0:
        fail(f"none of the {len(files)} images could be read; no JSON was written")
    write_json(json_path, {**header, "results": records, "summary": summary})
    _print_summary(f"{len(files)} image(s)", summary, out)


def _write_lines(path: Path, records: list[dict]) -> None:
    """One JSON object per line (TuSimple's prediction file), written atomically."""
    import json

    from percept.cli.common import fail, write_error
    from percept.outputs import write_text_atomic

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(path, "".join(json.dumps(r) + "\n" for r in records))
    except OSError as e:
        fail(write_error(path, e))


def _lanes_on_video(runner, video, path: Path, writer) -> tuple[list[dict], list[float]]:
    """Records and per-frame times of the lane module over ``video``; ValueError naming ``path`` when a frame
    cannot be used (e.g. another size than the calibration)."""
    from percept.cli.common import progress_bar
    from percept.lanes.overlay import draw_overlay

    records, ms, fps = [], [], video.fps
    with progress_bar() as bar:
        task = bar.add_task(f"lanes on {path.name}", total=video.expected_frames)
        stream = runner.video(video, fps)
        for i in itertools.count():
            t0 = time.perf_counter()
            try:
                item = next(stream, None)
            except ValueError as e:
                raise ValueError(f"{path}: {e}") from None
            if item is None:
                return records, ms
            ms.append(1000 * (time.perf_counter() - t0))
            image, result = item
            records.append(_record(result, file=str(path), frame=i, time_s=round(i / fps, 4)))
            if writer is not None:
                writer.write(draw_overlay(image, result, f"{path.name} #{i}"))
            bar.advance(task)


def _run_video(runner, path: Path, out: Optional[Path], json_path: Optional[Path], max_frames, header: dict) -> None:
    """The lane fit through a video, then the JSON and a summary."""
    from percept.cli.common import console, write_json
    from percept.cli.footage_out import process_video, video_header

    video, target, records, ms = process_video(path, out, "lanes", max_frames,
                                               lambda video, writer: _lanes_on_video(runner, video, path, writer))
    summary = _summary(records, ms)
    # one geometry for the whole video (from its first frames)
    header.update({k: records[0][k] if records else None for k in ("mount_height_m", "mount_height_source")})
    write_json(json_path, {**header, **video_header(video, target, records), "results": records, "summary": summary})
    _print_summary(f"{len(records)} frame(s) of {path.name}", summary, None)
    if target is not None:
        console.print(f"overlay video: {target}")
