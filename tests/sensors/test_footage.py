"""Footage readers (listing a source, images, videos) and undistortion, on files written into tmp_path."""

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from percept.sensors import (CameraCalibration, FootageKind, PinholeCamera, Undistorter, list_footage, list_images,
                             open_video, read_image)
from percept.sensors.footage import truncation

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "data"


def _image(h: int = 48, w: int = 64) -> np.ndarray:
    """A colour test card with detail (so that the compressed file has some length)."""
    rng = np.random.default_rng(0)
    img = cv2.resize(rng.integers(0, 255, (h // 4, w // 4, 3), dtype=np.uint8), (w, h), interpolation=cv2.INTER_NEAREST)
    cv2.putText(img, "42", (5, h - 8), cv2.FONT_HERSHEY_SIMPLEX, 0.8, (255, 255, 255), 2)
    return img


def _write_video(path: Path, frames: int = 30, size: tuple[int, int] = (64, 48)) -> None:
    w = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 10.0, size)
    assert w.isOpened()
    for i in range(frames):
        w.write(np.roll(_image(size[1], size[0]), i, axis=1))
    w.release()


def test_listing_an_image_a_folder_and_a_video(tmp_path):
    for name in ("b.png", "a.jpg", "c.JPEG", ".hidden.jpg", "notes.txt"):
        (tmp_path / name).write_bytes(b"x")
    (tmp_path / "sub.png").mkdir()
    assert list_footage(tmp_path) == (FootageKind.IMAGES, [tmp_path / "a.jpg", tmp_path / "b.png", tmp_path / "c.JPEG"])
    assert list_images(tmp_path) == list_footage(tmp_path)[1]
    assert list_footage(tmp_path / "b.png") == (FootageKind.IMAGES, [tmp_path / "b.png"])
    (tmp_path / "v.MP4").write_bytes(b"x")
    assert list_footage(tmp_path / "v.MP4") == (FootageKind.VIDEO, [tmp_path / "v.MP4"])
    assert FootageKind.VIDEO.value == "video"


def test_listing_bad_sources(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(ValueError, match="neither an image .* nor a video"):
        list_footage(tmp_path / "notes.txt")
    with pytest.raises(ValueError, match="missing.png does not exist"):
        list_footage(tmp_path / "missing.png")
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ValueError, match="empty holds no images"):
        list_footage(empty)
    with pytest.raises(ValueError, match="is not a folder"):
        list_images(tmp_path / "notes.txt")


def test_reading_images_colour_and_grey(tmp_path):
    img = _image()
    cv2.imwrite(str(tmp_path / "a.png"), img)
    assert np.array_equal(read_image(tmp_path / "a.png"), img)
    assert read_image(tmp_path / "a.png", gray=True).shape == img.shape[:2]
    cv2.imwrite(str(tmp_path / "a.jpg"), img)
    assert read_image(tmp_path / "a.jpg").shape == img.shape
    # bytes after the end-of-image marker (metadata some cameras append) are not a truncation
    (tmp_path / "tail.jpg").write_bytes((tmp_path / "a.jpg").read_bytes() + b"trailing metadata")
    assert read_image(tmp_path / "tail.jpg").shape == img.shape


def test_reading_bad_images(tmp_path):
    with pytest.raises(ValueError, match="missing.jpg does not exist"):
        read_image(tmp_path / "missing.jpg")
    (tmp_path / "noise.png").write_bytes(bytes(range(256)) * 4)
    with pytest.raises(ValueError, match="cannot read .*noise.png as an image"):
        read_image(tmp_path / "noise.png")
    (tmp_path / "dir.jpg").mkdir()
    with pytest.raises(ValueError, match="is a folder, not an image"):
        read_image(tmp_path / "dir.jpg")


@pytest.mark.parametrize("suffix, why", [(".jpg", "no JPEG end-of-image marker FFD9"), (".png", "no PNG IEND chunk")])
@pytest.mark.parametrize("keep", [0.5, -2, -1], ids=["half", "end-2", "end-1"])
def test_truncated_images_are_reported(tmp_path, suffix, why, keep):
    good = tmp_path / f"good{suffix}"
    assert cv2.imwrite(str(good), _image(240, 320))
    data = good.read_bytes()
    cut = tmp_path / f"cut{suffix}"
    cut.write_bytes(data[:int(len(data) * keep) if keep > 0 else len(data) + keep])
    with pytest.raises(ValueError, match=f"cut{suffix} as an image: the file is truncated \\({why}\\)"):
        read_image(cut)


def test_a_truncated_jpeg_would_decode_without_the_check(tmp_path):
    """Why the check exists: cv2.imread decodes the first half of a JPEG without an error (libjpeg only warns)."""
    assert cv2.imwrite(str(tmp_path / "a.jpg"), _image(240, 320))
    data = (tmp_path / "a.jpg").read_bytes()
    (tmp_path / "cut.jpg").write_bytes(data[:len(data) // 2])
    assert cv2.imread(str(tmp_path / "cut.jpg")) is not None
    assert truncation(data[:len(data) // 2]) is not None and truncation(data) is None


def test_real_images_are_not_reported_as_truncated():
    files = [p for p in DATA.rglob("*") if p.suffix.lower() in (".jpg", ".jpeg", ".png")] if DATA.is_dir() else []
    if not files:
        pytest.skip(f"{DATA} is absent (real data in ../shared/data)")
    assert [p for p in files if truncation(p.read_bytes()) is not None] == []


def test_a_whole_video(tmp_path):
    _write_video(tmp_path / "v.avi", 30)
    with open_video(tmp_path / "v.avi") as video:
        assert video.size == (64, 48) and video.fps == pytest.approx(10.0) and video.declared_frames == 30
        frames = list(video)
    assert len(frames) == video.frames_read == 30 and frames[0].shape == (48, 64, 3)
    assert not video.ended_early
    short = open_video(tmp_path / "v.avi", max_frames=7)
    assert short.expected_frames == 7 and len(list(short)) == 7 and not short.ended_early


def test_a_truncated_video_ends_early(tmp_path):
    _write_video(tmp_path / "v.avi", 30)
    data = (tmp_path / "v.avi").read_bytes()
    (tmp_path / "cut.avi").write_bytes(data[:len(data) // 2])
    video = open_video(tmp_path / "cut.avi")
    assert video.declared_frames == 30
    n = sum(1 for _ in video)
    assert n == video.frames_read < 30 and video.ended_early


def test_bad_videos(tmp_path):
    (tmp_path / "text.mp4").write_text("not a video")
    with pytest.raises(ValueError, match="cannot read .*text.mp4 as a video"):
        open_video(tmp_path / "text.mp4")
    with pytest.raises(ValueError, match="gone.avi does not exist"):
        open_video(tmp_path / "gone.avi")
    _write_video(tmp_path / "v.avi", 3)
    with pytest.raises(ValueError, match="max_frames must be at least 1"):
        open_video(tmp_path / "v.avi", max_frames=0)


def _row_of_line(img: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Per column, the mean row of the bright pixels in the top half (where the test line is)."""
    top = img[: img.shape[0] // 2, cols].astype(float)
    rows = np.arange(top.shape[0])[:, None]
    return (top * rows).sum(0) / top.sum(0)


def test_undistortion_straightens_a_distorted_line():
    """A straight line near the top of an ideal image, seen through a barrel lens (k1 < 0) bows; undistorted it
    is straight again, within a fraction of a pixel."""
    cam = PinholeCamera.from_hfov(640, 480, math.radians(70))
    dist = (-0.3, 0.1, 0.0, 0.0, 0.0)
    # the line v = 70 of the ideal image through the lens: project its rays with the distortion (forward model)
    u = np.linspace(-200, 840, 2000)
    rays = np.stack([(u - cam.cx) / cam.fx, np.full_like(u, (70 - cam.cy) / cam.fy), np.ones_like(u)], axis=1)
    uv, _ = cv2.projectPoints(rays, np.zeros(3), np.zeros(3), cam.K, np.array(dist))
    distorted = np.zeros((480, 640), np.uint8)
    cv2.polylines(distorted, [np.round(uv * 16).astype(np.int32)], False, 255, 3, cv2.LINE_AA, shift=4)
    cols = np.arange(120, 520, 10)

    def bow(img):
        v = _row_of_line(img, cols)
        return np.abs(v - np.polyval(np.polyfit(cols, v, 1), cols)).max()

    assert bow(distorted) > 5.0
    fixed = Undistorter(cam, dist)(distorted)
    assert fixed.shape == distorted.shape and fixed.dtype == np.uint8
    assert bow(fixed) < 0.5
    assert np.abs(_row_of_line(fixed, cols) - 70).max() < 0.5
    cal = CameraCalibration(cam, dist, 0.1)
    assert np.array_equal(cal.undistorter()(distorted), fixed)


def test_undistorting_a_frame_of_another_size_is_refused():
    cam = PinholeCamera.from_hfov(640, 480, math.radians(60))
    und = Undistorter(cam, (0.1, 0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="image is 320x240 but the calibration is for 640x480"):
        und(np.zeros((240, 320, 3), np.uint8))
