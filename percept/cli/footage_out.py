"""What the footage commands (``percept lanes``, ``percept detect``) share: where an overlay goes, writing an image
overlay atomically, a video writer, the image and video jobs, and the summary of their records."""

from __future__ import annotations

from pathlib import Path
from typing import Callable


def overlay_path(out: Path, source: Path, tag: str, video: bool) -> Path:
    """``OUT/NAME.TAG.png`` for an image, ``OUT/NAME.TAG.mp4`` for a video."""
    return out / f"{source.stem}.{tag}{'.mp4' if video else '.png'}"


def footage_for(files: list[Path], out: Path | None, tag: str) -> list[Path]:
    """The footage a command with overlays in ``out`` (None: none) reads: ``files`` less the overlays it writes
    (``OUT/NAME.TAG.png``), so that a second run with ``--out`` inside the footage folder does not read its own
    overlays as footage. ValueError when ``out`` is a file or nothing else is left."""
    if out is None:
        return files
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out} is a file; give a folder for the overlays")
    keep = [p for p in files if not (p.parent.resolve() == out.resolve() and p.stem.endswith(f".{tag}"))]
    if not keep:
        raise ValueError(f"{out} holds only percept's own {tag} overlays; give the folder of the footage itself")
    return keep


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


def summary(records: list[dict], ms: list[float], counts: Callable[[list[dict]], dict]) -> dict:
    """The JSON summary of a footage command's records: how many were read (``count``) and not (``errors``), the
    command's ``counts(read records)``, and the median time a frame [ms] (the upper one of an even count; None
    without a timed frame)."""
    ok = [r for r in records if "error" not in r]
    return {"count": len(ok), "errors": len(records) - len(ok), **counts(ok),
            "ms_per_frame_median": float(sorted(ms)[len(ms) // 2]) if ms else None}


def summary_tail(summary: dict) -> str:
    """The end of a footage command's summary line: the unreadable ones and the median time, where there are any."""
    from percept.cli.common import fmt

    ms = summary["ms_per_frame_median"]
    return ((f", {summary['errors']} unreadable" if summary["errors"] else "")
            + (f"; {fmt(ms, '{:.0f}')} ms each (median)" if ms else ""))


def video_header(video, target: Path | None, records: list) -> dict:
    """The JSON keys every footage command writes about a video it went through."""
    return {"fps": video.fps, "frames": len(records), "frames_declared": video.declared_frames,
            "ended_early": video.ended_early, "overlay": None if target is None else str(target)}


def process_images(files: list[Path], out: Path | None, tag: str, title: str, single: bool, work) -> tuple:
    """The image job of a footage command: for each file, ``work(image, path) -> (record, draw)`` (``draw()`` makes
    its overlay), timed; an unreadable or unusable image is skipped with a warning (a one-line error when it is the
    only one); each overlay is written as it is made (``OUT/NAME.TAG.png``, atomically). Returns (records, ms);
    a record of a skipped image is {file, error}."""
    import time

    from rich.markup import escape

    from percept.cli.common import err, fail, on_interrupt, progress_bar, write_error
    from percept.sensors import read_image

    records, ms, done = [], [], []
    on_interrupt(lambda: f"{len(done)} overlay(s) kept in {out}; no JSON was written" if done else None)
    with progress_bar() as bar:
        task = bar.add_task(title, total=len(files))
        for path in files:
            try:
                image = read_image(path)
                t0 = time.perf_counter()
                record, draw = work(image, path)
                ms.append(1000 * (time.perf_counter() - t0))
            except ValueError as e:
                if single:
                    fail(str(e) if str(path) in str(e) else f"{path}: {e}")
                err.print(f"[yellow]skipped:[/] {escape(str(e))}", highlight=False, soft_wrap=True)
                records.append({"file": str(path), "error": str(e)})
                bar.advance(task)
                continue
            records.append(record)
            if out is not None:
                target = overlay_path(out, path, tag, video=False)
                try:
                    write_overlay(target, draw())
                except OSError as e:
                    kept = f"; {len(done)} overlay(s) before it are kept" if done else ""
                    fail(f"{write_error(target, e)}{kept}; no JSON was written")
                done.append(target)
            bar.advance(task)
    return records, ms
