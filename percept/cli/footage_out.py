"""Overlay outputs shared by the footage commands (``percept lanes``, ``percept detect``): where an overlay goes,
writing an image overlay atomically, and a video writer."""

from __future__ import annotations

from pathlib import Path


def overlay_path(out: Path, source: Path, tag: str, video: bool) -> Path:
    """``OUT/NAME.TAG.png`` for an image, ``OUT/NAME.TAG.mp4`` for a video."""
    return out / f"{source.stem}.{tag}{'.mp4' if video else '.png'}"


def write_overlay(target: Path, image) -> None:
    """One overlay PNG, complete or absent (encoded in memory, then written atomically)."""
    from percept.outputs import png_bytes, write_bytes_atomic

    write_bytes_atomic(target, png_bytes(image))


def open_writer(tmp: Path, fps: float, size: tuple[int, int]):
    """An mp4v writer on the temporary ``tmp`` (.mp4); OSError when this OpenCV build cannot write mp4v."""
    import cv2

    w = cv2.VideoWriter(str(tmp), cv2.VideoWriter_fourcc(*"mp4v"), fps, size)
    if not w.isOpened():
        raise OSError(f"this OpenCV build cannot write mp4v video into {tmp.parent}")
    return w


def process_video(path: Path, out: Path | None, tag: str, max_frames: int | None, frames) -> tuple:
    """The video job of a footage command: open ``path`` (at most ``max_frames``), run ``frames(video, writer)
    -> (records, ms)`` with an overlay writer on ``OUT/NAME.TAG.mp4`` when ``out`` is given (written atomically:
    complete or absent), warn when the video ended before its header said. Returns (video, overlay or None,
    records, ms); an unreadable video, a frame that cannot be used or a failed write is a one-line error."""
    import contextlib

    from rich.markup import escape

    from percept.cli.common import err, fail, on_interrupt, write_error
    from percept.outputs import atomic_path
    from percept.sensors import open_video

    try:
        video = open_video(path, max_frames)
    except ValueError as e:
        fail(str(e))
    target = None if out is None else overlay_path(out, path, tag, video=True)
    on_interrupt("nothing was written (the overlay video and the JSON are written only when complete)")
    try:
        with contextlib.ExitStack() as stack:
            tmp = None if target is None else stack.enter_context(atomic_path(target))
            writer = None if tmp is None else open_writer(tmp, video.fps, video.size)
            try:
                records, ms = frames(video, writer)
            finally:
                video.close()
                if writer is not None:
                    writer.release()
    except ValueError as e:
        fail(f"{e}; nothing was written")
    except OSError as e:
        fail(write_error(target, e))
    if video.ended_early:
        err.print(f"[yellow]warning:[/] {escape(str(path))} ended after {video.frames_read} of the "
                  f"{video.declared_frames} frames its header declares (truncated or damaged?)", highlight=False,
                  soft_wrap=True)
    return video, target, records, ms


def video_header(video, target: Path | None, records: list) -> dict:
    """The JSON keys every footage command writes about a video it went through."""
    return {"fps": video.fps, "frames": len(records), "frames_declared": video.declared_frames,
            "ended_early": video.ended_early, "overlay": None if target is None else str(target)}
