"""`percept detect`: people in recorded footage, HOG over the full image pyramid (no calibration needed).

Registered on the main typer app by ``percept.cli.app``; parses options, calls ``percept.detection``, prints.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Optional

import typer

from .common import Command


def register(app: typer.Typer) -> None:
    """Add the ``detect`` command to ``app``."""

    @app.command("detect", cls=Command)
    def detect(
        source: Path = typer.Argument(..., help="An image, a video or a folder of images."),
        json_path: Optional[Path] = typer.Option(None, "--json", help="Write per-image / per-frame detections to "
                                                                      "this JSON file."),
        out: Optional[Path] = typer.Option(None, "--out", help="Folder for overlays: NAME.detect.png per image, "
                                                               "NAME.detect.mp4 for a video."),
        model: str = typer.Option("inria", "--model", help="'inria' (OpenCV's people detector, trained on the "
                                                           "INRIA photographs), 'sim' (percept's, trained on "
                                                           "rendered people) or a model file (.npz) saved by "
                                                           "percept train-detector."),
        scale_step: float = typer.Option(1.05, "--scale-step", help="Pyramid scale step, 1.01 to 2."),
        threshold: float = typer.Option(0.0, "--threshold", help="Smallest window score kept (the linear "
                                                                 "model's margin), -10 to 10."),
        max_frames: Optional[int] = typer.Option(None, "--max-frames", help="Process at most this many video "
                                                                          "frames (at least 1)."),
    ):
        """Find people with a HOG sliding window over every scale of the image (64x128 windows, 8-pixel stride),
        features computed once per scale and shared by all its windows.

        The JSON has, per image or frame, `file`, `frame` and `detections` [{`box_px` \\[u0, v0, u1, v1], `score`}].
        The JSON and every overlay are written complete or not at all. A single image that cannot be read
        (empty, truncated, not an image) is refused; in a folder it is skipped with a warning line naming it and
        listed in the JSON with its error.
        """
        from percept.cli.common import check_outputs, fail
        from percept.cli.footage_out import footage_for, overlay_path
        from percept.cli.options import check_number
        from percept.detection import LinearModel
        from percept.sensors import FootageKind, list_footage

        check_number("--scale-step", scale_step, 1.01, 2.0)
        check_number("--threshold", threshold, -10.0, 10.0)
        check_number("--max-frames", max_frames, 1, 10**7)
        try:
            linear = LinearModel.named(model)
            kind, files = list_footage(source)
            files = footage_for(files, out, "detect")
        except ValueError as e:
            fail(str(e))
        video = kind is FootageKind.VIDEO
        check_outputs([json_path, *([] if out is None else [overlay_path(out, p, "detect", video) for p in files])],
                      [*files, LinearModel.file_of(model)])
        header = {"source": str(source), "kind": kind.value, "model": linear.name, "scale_step": scale_step,
                  "threshold": threshold}
        params = dict(model=linear, step=scale_step, threshold=threshold)
        if video:
            _run_video(files[0], out, json_path, max_frames, header, params)
        else:
            _run_images(files, out, json_path, header, params, single=source.is_file())


def _detect(image, params: dict) -> tuple[list, float]:
    """The people found on ``image`` and the time it took [ms]."""
    from percept.detection import detect_multiscale

    t0 = time.perf_counter()
    found = detect_multiscale(image, **params)
    return found, 1000 * (time.perf_counter() - t0)


def _summary(records: list[dict], ms: list[float]) -> dict:
    """The JSON summary: read and unreadable records, the detections in all, the median time [ms]."""
    from percept.cli.footage_out import summary

    return summary(records, ms, lambda ok: {"detections": sum(len(r["detections"]) for r in ok)})


def _print_summary(title: str, summary: dict) -> None:
    """The summary as one line."""
    from percept.cli.common import console
    from percept.cli.footage_out import summary_tail

    console.print(f"{title}: {summary['detections']} detection(s) in {summary['count']}" + summary_tail(summary))


def _run_images(files: list[Path], out: Optional[Path], json_path: Optional[Path], header: dict, params: dict,
                single: bool) -> None:
    """The detector on each image, then the JSON and a summary."""
    from percept.cli.common import console, fail, write_json
    from percept.cli.footage_out import process_images
    from percept.detection import detect_multiscale
    from percept.detection.overlay import draw_detections

    def work(image, path):
        found = detect_multiscale(image, **params)
        record = {"file": str(path), "frame": None, "detections": [d.to_dict() for d in found]}
        return record, lambda: draw_detections(image, found, path.name)

    records, ms = process_images(files, out, "detect", "people in images", single, work)
    summary = _summary(records, ms)
    if summary["count"] == 0:
        fail(f"none of the {len(files)} images could be used; no JSON was written")
    write_json(json_path, {**header, "results": records, "summary": summary})
    _print_summary(f"{len(files)} image(s)", summary)
    if out is not None:
        console.print(f"overlays in {out}")


def _frames(video, path: Path, params: dict, writer) -> tuple[list[dict], list[float]]:
    """Records and per-frame times of the detector over ``video``, each frame's overlay to ``writer`` if given."""
    from percept.cli.common import progress_bar
    from percept.detection.overlay import draw_detections

    records, ms = [], []
    with progress_bar() as bar:
        task = bar.add_task(f"people in {path.name}", total=video.expected_frames)
        for i, image in enumerate(video):
            try:
                found, t = _detect(image, params)
            except ValueError as e:
                raise ValueError(f"{path} frame {i}: {e}") from None
            ms.append(t)
            records.append({"file": str(path), "frame": i, "time_s": round(i / video.fps, 4),
                            "detections": [d.to_dict() for d in found]})
            if writer is not None:
                writer.write(draw_detections(image, found, f"{path.name} #{i}"))
            bar.advance(task)
    return records, ms


def _run_video(path: Path, out: Optional[Path], json_path: Optional[Path], max_frames, header: dict,
               params: dict) -> None:
    """The detector through a video, then the JSON and a summary."""
    from percept.cli.common import console, write_json
    from percept.cli.footage_out import process_video, video_header

    video, target, records, ms = process_video(path, out, "detect", max_frames,
                                               lambda video, writer: _frames(video, path, params, writer))
    summary = _summary(records, ms)
    write_json(json_path, {**header, **video_header(video, target, records), "results": records, "summary": summary})
    _print_summary(f"{len(records)} frame(s) of {path.name}", summary)
    if target is not None:
        console.print(f"overlay video: {target}")
