"""`percept lanes`: the lane module on recorded footage.

Registered on the main typer app by ``percept.cli.app``; parses options, calls ``percept.lanes``, prints.
"""

from __future__ import annotations

import itertools
import math
import time
from pathlib import Path
from typing import Optional

import typer

from .common import Command


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
        mount_height: float = typer.Option(1.2, "--mount-height", help="Camera height above the road in metres, 0.2 "
                                                                       "to 10; scales the metric values."),
        hfov: float = typer.Option(60.0, "--hfov", help="Horizontal field of view in degrees (3 to 177), used "
                                                        "without --calib."),
        speed: float = typer.Option(0.0, "--speed", help="Assumed speed in m/s (0 to 100) for tracking through a "
                                                         "video (0: no motion model)."),
        max_frames: Optional[int] = typer.Option(None, "--max-frames", help="Process at most this many video frames "
                                                                          "(at least 1)."),
    ):
        """Fit the ego lane on recorded footage; pitch and horizon come from the lane lines' vanishing point.

        The JSON and every overlay are written complete or not at all: an error, a full disk or Ctrl-C leaves the
        files that were there untouched. Overlays of a folder are written one by one as each image is done.
        """
        from percept.cli.common import check_outputs, fail
        from percept.cli.footage_out import overlay_path
        from percept.cli.options import check_number
        from percept.lanes.realworld import FootageLanes, RealLaneConfig
        from percept.sensors import CameraCalibration, FootageKind, list_footage

        check_number("--mount-height", mount_height, 0.2, 10.0)
        check_number("--hfov", hfov, 3.0, 177.0)
        check_number("--speed", speed, 0.0, 100.0)
        check_number("--max-frames", max_frames, 1, 10**7)
        try:
            cfg = RealLaneConfig(hfov_rad=math.radians(hfov), mount_height_m=mount_height, speed_mps=speed)
            cal = CameraCalibration.load(calib) if calib is not None else None
            kind, files = list_footage(source)
        except ValueError as e:
            fail(str(e))
        video = kind is FootageKind.VIDEO
        overlays = [] if out is None else [overlay_path(out, p, "lanes", video) for p in files]
        if out is not None and out.exists() and not out.is_dir():
            fail(f"--out {out} is a file; give a folder for the overlays")
        check_outputs([json_path, *overlays], [*files, calib])
        runner = FootageLanes(cfg, cal)
        header = {"source": str(source), "kind": kind.value, "calibration": None if calib is None else str(calib),
                  "mount_height_m": mount_height, "hfov_deg": None if cal is not None else hfov,
                  "assumed_speed_mps": speed}
        if video:
            _run_video(runner, files[0], out, json_path, max_frames, header)
        else:
            _run_images(runner, files, out, json_path, header, single=source.is_file())


def _record(result, **keys) -> dict:
    return {**keys, **result.to_dict()}


def _summary(records: list[dict], ms: list[float]) -> dict:
    ok = [r for r in records if "error" not in r]
    return {"count": len(ok), "errors": len(records) - len(ok),
            "both_boundaries": sum(bool(r["both_boundaries"]) for r in ok),
            "lane_found": sum(r["offset_m"] is not None for r in ok),
            "ms_per_frame_median": float(sorted(ms)[len(ms) // 2]) if ms else None}


def _print_summary(title: str, summary: dict, out: Optional[Path]) -> None:
    from percept.cli.common import console, fmt

    ms = summary["ms_per_frame_median"]
    console.print(f"{title}: lane found in {summary['lane_found']} of {summary['count']}, both boundaries in "
                  f"{summary['both_boundaries']}" + (f", {summary['errors']} unreadable" if summary["errors"] else "")
                  + (f"; {fmt(ms, '{:.0f}')} ms each (median)" if ms else ""))
    if out is not None:
        console.print(f"overlays in {out}")


def _run_images(runner, files: list[Path], out: Optional[Path], json_path: Optional[Path], header: dict,
                single: bool) -> None:
    from percept.cli.common import fail, write_json
    from percept.cli.footage_out import process_images
    from percept.lanes.overlay import draw_overlay

    def work(image, path):
        result = runner.still(image)
        return _record(result, file=str(path)), lambda: draw_overlay(runner.prepare(image), result, path.name)

    records, ms = process_images(files, out, "lanes", "lanes on images", single, work)
    summary = _summary(records, ms)
    if summary["count"] == 0:
        fail(f"none of the {len(files)} images could be read; no JSON was written")
    write_json(json_path, {**header, "results": records, "summary": summary})
    _print_summary(f"{len(files)} image(s)", summary, out)


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
    from percept.cli.common import console, write_json
    from percept.cli.footage_out import process_video, video_header

    video, target, records, ms = process_video(path, out, "lanes", max_frames,
                                               lambda video, writer: _lanes_on_video(runner, video, path, writer))
    summary = _summary(records, ms)
    write_json(json_path, {**header, **video_header(video, target, records), "results": records, "summary": summary})
    _print_summary(f"{len(records)} frame(s) of {path.name}", summary, None)
    if target is not None:
        console.print(f"overlay video: {target}")
