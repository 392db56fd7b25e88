"""`percept lanes`: the lane module on recorded footage.

Registered on the main typer app by ``percept.cli.app``; parses options, calls ``percept.lanes``, prints.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Optional

import typer


def register(app: typer.Typer) -> None:
    """Add the ``lanes`` command to ``app``."""

    @app.command("lanes")
    def lanes(
        source: Path = typer.Argument(..., help="An image, a video or a folder of images (dash camera, road ahead)."),
        json_path: Optional[Path] = typer.Option(None, "--json",
                                                 help="Write per-image / per-frame results to this JSON file."),
        out: Optional[Path] = typer.Option(None, "--out", help="Folder for overlays: NAME.lanes.png per image, "
                                                               "NAME.lanes.mp4 for a video."),
        calib: Optional[Path] = typer.Option(None, "--calib", help="Calibration JSON from `percept calibrate`: "
                                                                   "undistort and use its intrinsics."),
        mount_height: float = typer.Option(1.2, "--mount-height", help="Camera height above the road in metres; "
                                                                       "scales the metric values."),
        hfov: float = typer.Option(60.0, "--hfov", help="Horizontal field of view in degrees, used without --calib."),
        speed: float = typer.Option(0.0, "--speed", help="Assumed speed in m/s for tracking through a video "
                                                         "(0: no motion model)."),
        max_frames: Optional[int] = typer.Option(None, "--max-frames", help="Process at most this many video frames."),
    ):
        """Fit the ego lane on recorded footage; pitch and horizon come from the lane lines' vanishing point."""
        from percept.cli.common import fail
        from percept.lanes.realworld import FootageLanes, RealLaneConfig
        from percept.sensors import CameraCalibration, FootageKind, list_footage

        if max_frames is not None and max_frames < 1:
            fail(f"--max-frames must be at least 1, got {max_frames}")
        try:
            cfg = RealLaneConfig(hfov_rad=math.radians(hfov), mount_height_m=mount_height, speed_mps=speed)
            cal = CameraCalibration.load(calib) if calib is not None else None
            kind, files = list_footage(source)
        except ValueError as e:
            fail(str(e))
        if out is not None:
            try:
                out.mkdir(parents=True, exist_ok=True)
            except OSError as e:
                fail(f"cannot create {out}: {e.strerror or e}")
        runner = FootageLanes(cfg, cal)
        header = {"source": str(source), "kind": kind.value, "calibration": None if calib is None else str(calib),
                  "mount_height_m": mount_height, "hfov_deg": None if cal is not None else hfov,
                  "assumed_speed_mps": speed}
        if kind is FootageKind.VIDEO:
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
    from percept.cli.common import console

    console.print(f"{title}: lane found in {summary['lane_found']} of {summary['count']}, both boundaries in "
                  f"{summary['both_boundaries']}" + (f", {summary['errors']} unreadable" if summary["errors"] else "")
                  + (f"; {summary['ms_per_frame_median']:.0f} ms each (median)"
                     if summary["ms_per_frame_median"] else ""))
    if out is not None:
        console.print(f"overlays in {out}")


def _run_images(runner, files: list[Path], out: Optional[Path], json_path: Optional[Path], header: dict,
                single: bool) -> None:
    import cv2

    from percept.cli.common import err, fail, progress_bar, write_json
    from percept.lanes.overlay import draw_overlay
    from percept.sensors import read_image

    records, ms, problem = [], [], None
    with progress_bar() as bar:
        task = bar.add_task("lanes on images", total=len(files))
        for path in files:
            try:
                image = read_image(path)
                t0 = time.perf_counter()
                result = runner.still(image)
                ms.append(1000 * (time.perf_counter() - t0))
            except ValueError as e:
                if single:
                    problem = str(e)
                    break
                err.print(f"[yellow]skipped:[/] {e}", highlight=False)
                records.append({"file": str(path), "error": str(e)})
                bar.advance(task)
                continue
            records.append(_record(result, file=str(path)))
            if out is not None:
                target = out / f"{path.stem}.lanes.png"
                if not cv2.imwrite(str(target), draw_overlay(runner.prepare(image), result, path.name)):
                    problem = f"cannot write {target}"
                    break
            bar.advance(task)
    summary = _summary(records, ms)
    write_json(json_path, {**header, "results": records, "summary": summary})
    if problem is not None:
        fail(problem)
    if summary["count"] == 0:
        fail(f"none of the {len(files)} images could be read")
    _print_summary(f"{len(files)} image(s)", summary, out)


def _run_video(runner, path: Path, out: Optional[Path], json_path: Optional[Path], max_frames, header: dict) -> None:
    from percept.cli.common import err, fail, progress_bar, write_json
    from percept.lanes.overlay import draw_overlay
    from percept.sensors import open_video

    try:
        video = open_video(path, max_frames)
    except ValueError as e:
        fail(str(e))
    fps = video.fps
    writer, target = _open_writer(out, path.stem, fps, video.size) if out is not None else (None, None)
    records, ms, problem = [], [], None
    try:
        with progress_bar() as bar:
            task = bar.add_task(f"lanes on {path.name}", total=video.expected_frames)
            stream = runner.video(video, fps)
            i = 0
            while True:
                t0 = time.perf_counter()
                try:
                    item = next(stream, None)
                except ValueError as e:
                    problem = f"{path}: {e}"
                    break
                if item is None:
                    break
                ms.append(1000 * (time.perf_counter() - t0))
                image, result = item
                records.append(_record(result, file=str(path), frame=i, time_s=round(i / fps, 4)))
                if writer is not None:
                    writer.write(draw_overlay(image, result, f"{path.name} #{i}"))
                i += 1
                bar.advance(task)
    finally:
        video.close()
        if writer is not None:
            writer.release()
    if video.ended_early:
        err.print(f"[yellow]warning:[/] {path} ended after {video.frames_read} of the {video.declared_frames} frames "
                  "its header declares (truncated or damaged?)", highlight=False)
    summary = _summary(records, ms)
    write_json(json_path, {**header, "fps": fps, "frames": len(records), "frames_declared": video.declared_frames,
                           "ended_early": video.ended_early,
                           "overlay": None if target is None else str(target), "results": records, "summary": summary})
    if problem is not None:
        fail(problem)
    _print_summary(f"{len(records)} frame(s) of {path.name}", summary, None)
    if target is not None:
        from percept.cli.common import console
        console.print(f"overlay video: {target}")


def _open_writer(out: Path, stem: str, fps: float, size: tuple[int, int]):
    """An mp4v .mp4 writer, or MJPG .avi when this OpenCV build cannot write mp4."""
    import cv2

    from percept.cli.common import fail

    for fourcc, ext in (("mp4v", ".mp4"), ("MJPG", ".avi")):
        target = out / f"{stem}.lanes{ext}"
        w = cv2.VideoWriter(str(target), cv2.VideoWriter_fourcc(*fourcc), fps, size)
        if w.isOpened():
            return w, target
    fail(f"cannot write a video into {out} (neither mp4v nor MJPG is available)")
