"""`percept calibrate`: camera intrinsics (or a whole stereo rig) from chessboard photos.

Registered on the main typer app by ``percept.cli.app``; parses options, calls ``percept.sensors``, prints.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from .common import Command
from .options import flag


def _cam_rows(name: str, cal) -> list[tuple[str, str]]:
    """One camera's intrinsics and distortion as table rows, each label prefixed with ``name``."""
    cam = cal.camera
    return [(f"{name}fx, fy [px]", f"{cam.fx:.1f}, {cam.fy:.1f}"),
            (f"{name}cx, cy [px]", f"{cam.cx:.1f}, {cam.cy:.1f}"),
            (f"{name}dist (k1 k2 p1 p2 k3)", " ".join(f"{k:+.4f}" for k in cal.dist))]


def register(app: typer.Typer) -> None:
    """Add the ``calibrate`` command to ``app``."""

    @app.command("calibrate", cls=Command)
    def calibrate(
        folder: Path = typer.Argument(..., help="Folder of chessboard photos (one camera), or of left<N>/right<N> "
                                                "photo pairs with --stereo."),
        pattern: str = typer.Option("9x6", "--pattern", help="Inner corners per row x per column, e.g. 9x6."),
        stereo: Annotated[bool, flag("--stereo", help="Calibrate a stereo rig from left<N>.<ext> / right<N>.<ext> "
                                                      "pairs: both cameras, R, T, rectification.")] = False,
        square: float = typer.Option(1.0, "--square", help="Side of a board square in metres, 0.0001 to 10 (sets the "
                                                           "units of the stereo baseline; 1 = board squares)."),
        out: Optional[Path] = typer.Option(None, "--out", help="Calibration file to write (default DIR/calib.json, "
                                                               "DIR/stereo_calib.json with --stereo)."),
        json_path: Optional[Path] = typer.Option(None, "--json", help="Also write the figures to this JSON file."),
    ):
        """Camera intrinsics and distortion from chessboard photos (Zhang 2000); with --stereo, a whole rig.

        One camera: the file is what `percept lanes --calib` reads. Stereo: both cameras, the right camera's
        rotation and translation in the left one's frame (baseline in metres with --square), the rectified
        projections, and the mean epipolar error as a check. The files are written complete or not at all.

        A photo that cannot be read (empty, truncated, not an image), a stereo pair of two sizes and, with --stereo,
        a photo without its left/right partner are left out with a warning line naming them.
        """
        from percept.cli.common import check_outputs, console, fail, on_interrupt, write_error, write_json
        from percept.cli.options import check_number
        from percept.sensors.chessboard import chessboard_images, parse_pattern
        from percept.sensors.stereo_calibration import stereo_photos

        check_number("--square", square, 1e-4, 10.0)
        unpaired = []
        try:
            size = parse_pattern(pattern)
            items, unpaired = stereo_photos(folder) if stereo else (chessboard_images(folder), [])
        except ValueError as e:
            fail(str(e))
        for p in unpaired:
            _warn(_unpaired(p))
        target = out if out is not None else folder / ("stereo_calib.json" if stereo else "calib.json")
        photos = [p for item in items for p in (item if stereo else (item,))]
        check_outputs([target, json_path], photos)
        on_interrupt(f"nothing was written; {target} keeps what it held" if target.exists() else None)
        cal = _calibrate(items, size, square, stereo)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            cal.save(target)
        except OSError as e:
            fail(write_error(target, e))
        console.print(_table(cal, stereo, square, folder))
        console.print(f"wrote {target}")
        write_json(json_path, {**cal.to_dict(), "file": str(target), "folder": str(folder)})


def _calibrate(items: list, size: tuple[int, int], square: float, stereo: bool):
    """The camera (or, with ``stereo``, rig) calibration from ``items`` (photos, or (left, right) pairs) behind a
    progress bar; a warning line for each photo or pair left out, a one-line error when it cannot be done."""
    from percept.cli.common import fail, progress_bar
    from percept.sensors.chessboard import calibrate_chessboards
    from percept.sensors.stereo_calibration import calibrate_stereo

    problem, skipped, cal = None, [], None
    with progress_bar() as bar:
        what = "pairs" if stereo else "photos"
        task = bar.add_task(f"finding {size[0]}x{size[1]} chessboards in {len(items)} {what}", total=len(items))
        tick = lambda p, ok: bar.advance(task)  # noqa: E731
        skip = lambda p, why: skipped.append(why)  # noqa: E731
        try:
            cal = calibrate_stereo(items, size, square, tick, skip) if stereo else calibrate_chessboards(
                items, size, square, tick, skip)
        except ValueError as e:
            problem = str(e)
    for why in skipped:
        _warn(f"{why}; {'its pair' if stereo else 'the photo'} is left out")
    if problem is not None:
        fail(problem)
    return cal


def _warn(message: str) -> None:
    """One ``warning:`` line on the terminal (stderr)."""
    from rich.markup import escape

    from percept.cli.common import err

    err.print(f"[yellow]warning:[/] {escape(message)}", highlight=False, soft_wrap=True)


def _unpaired(path: Path) -> str:
    """Why a photo of a --stereo folder is in no pair: its partner (right<X> for left<X> and back) is missing, or
    it is named neither way."""
    name, low = path.name, path.name.lower()
    if low.startswith("left") or low.startswith("right"):
        partner = "right" + name[4:] if low.startswith("left") else "left" + name[5:]
        return f"{path} has no partner {partner}; it is left out"
    return f"{path} is named neither left<N> nor right<N>; it is left out"


def _table(cal, stereo: bool, square: float, folder: Path):
    """The figures of a camera (or stereo rig) calibration as a table."""
    from rich.markup import escape
    from rich.table import Table

    t = Table(title=f"{'stereo rig' if stereo else 'camera'} calibration from {folder}")
    t.add_column("quantity")
    t.add_column("value", justify="right")
    if stereo:
        unit = "m" if square != 1.0 else "squares"
        rows = [("stereo RMS reprojection error [px]", f"{cal.rms_px:.3f}"),
                ("mean epipolar error [px]", f"{cal.epipolar_px:.3f}"),
                ("pairs with the board in both", f"{cal.pairs_used} of {cal.pairs_total}"),
                (f"baseline [{unit}]", f"{cal.baseline_m:.4f}"),
                (f"T [{unit}]", " ".join(f"{v:+.4f}" for v in cal.T)),
                ("left / right RMS [px]", f"{cal.left.rms_px:.3f} / {cal.right.rms_px:.3f}"),
                ("image size [px]", f"{cal.left.camera.width}x{cal.left.camera.height}"),
                *_cam_rows("left ", cal.left), *_cam_rows("right ", cal.right)]
    else:
        skipped = cal.images_found - cal.images_used
        rows = [("RMS reprojection error [px]", f"{cal.rms_px:.3f}"),
                ("photos with the board", f"{cal.images_found} of {cal.images_total}"),
                ("photos used",
                 f"{cal.images_used}" + (f" ({skipped} of another size skipped)" if skipped else "")),
                ("image size [px]", f"{cal.camera.width}x{cal.camera.height}"), *_cam_rows("", cal)]
    for k, v in rows:
        t.add_row(escape(k), v)
    return t
