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
