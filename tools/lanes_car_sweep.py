"""A car straddling an ego lane line: how far does the fitted lane move?

Pastes the dark SUV of TuSimple 3.jpg (its outline only, CAR_OUTLINE_PX), scaled to 1.9 m wide, with its bottom
centre on the left or the right ego boundary of each frame at ranges of 12-50 m, and reports per placement the lane's
curvature, heading, width and confidence and how far each boundary moved (max |du| [px]) in the rows below the car,
against the same frame without the car.

    python tools/lanes_car_sweep.py FRAME... [--calib FILE] [--height M] [--out DIR]

FRAME: image files of one camera (a TuSimple sample name such as 1.jpg means that sample). Without ``--height``
the camera height is measured over the frames, as ``percept lanes`` does for a folder. ``--out`` writes a small
overlay per placement. Needs ../shared/data/tusimple-samples (the car comes from 3.jpg).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import cv2
import numpy as np

from percept.lanes.overlay import draw_overlay
from percept.lanes.realworld import FootageLanes, RealLaneConfig
from percept.sensors import CameraCalibration, read_image

SAMPLES = Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "tusimple-samples"
RANGES_M = (12, 16, 20, 25, 30, 40, 50)
CAR_OUTLINE_PX = np.array([(180, 376), (180, 262), (187, 250), (200, 240), (212, 236), (317, 235), (335, 250),
                           (350, 272), (366, 283), (366, 300), (363, 376)], np.int32)
"""The SUV's outline in 3.jpg (u, v) [px]: the road and the markings around it stay out of the paste."""
CAR_WIDTH_M = 1.9
TOLERANCE_PX = 20


def frame_path(name: str) -> Path:
    """A TuSimple sample's path for its bare name, else the path given."""
    return SAMPLES / name if not Path(name).exists() and (SAMPLES / name).exists() else Path(name)


def sweep(path: Path, frame: np.ndarray, lanes: FootageLanes, out: Path | None,
          sides: tuple[str, ...] = ("left", "right"), ranges: tuple[int, ...] = RANGES_M) -> tuple[int, int]:
    """Placements tried on ``frame`` (as the fit sees it: undistorted), over each line of ``sides`` at each of
    ``ranges`` [m], and those that moved a boundary by more than TOLERANCE_PX below the car."""
    u, v, w, h = cv2.boundingRect(CAR_OUTLINE_PX)
    car = read_image(SAMPLES / "3.jpg")[v:v + h, u:u + w]
    outline = cv2.fillPoly(np.zeros((h, w), np.uint8), [CAR_OUTLINE_PX - [u, v]], 255)
    plain = lanes.still(frame)
    height_m = plain.rig.mount_height_m
    rows = np.arange(160, frame.shape[0], 10)
    before = plain.u_at_rows(rows)
    e = plain.estimate
    print(f"{path.name} at {height_m:.2f} m, no car: curvature {e.curvature_1pm:+.5f} 1/m, heading "
          f"{math.degrees(e.heading_rad):+.2f} deg, width {e.width_m:.2f} m")
    tried = moved = 0
    for side in sides:
        for x in ranges:
            # bottom row v = horizon + f h / x; width f W / x [px]
            v_bottom = int(round(plain.rig.horizon_row + plain.rig.camera.fx * height_m / x))
            w_px = int(round(plain.rig.camera.fx * CAR_WIDTH_M / x))
            h_px = int(round(w_px * car.shape[0] / car.shape[1]))
            u_c = plain.u_at_rows(np.array([v_bottom]))[side][0]
            if v_bottom >= frame.shape[0] - 1 or v_bottom < h_px or not np.isfinite(u_c):
                continue
            u0 = int(round(u_c - w_px / 2))
            a, b = max(u0, 0), min(u0 + w_px, frame.shape[1])
            if b - a < 8:
                continue
            image = frame.copy()
            pasted = cv2.resize(car, (w_px, h_px), interpolation=cv2.INTER_AREA)[:, a - u0:b - u0]
            inside = cv2.resize(outline, (w_px, h_px), interpolation=cv2.INTER_AREA)[:, a - u0:b - u0] > 127
            image[v_bottom - h_px:v_bottom, a:b][inside] = pasted[inside]
            r = lanes.still(image)
            after = r.u_at_rows(rows)
            below = rows > v_bottom
            du = {k: np.abs(after[k][below] - before[k][below]) for k in after}
            worst = {k: float(np.nanmax(d)) if np.isfinite(d).any() else float("nan") for k, d in du.items()}
            tried += 1
            moved += max(worst.values()) > TOLERANCE_PX
            e = r.estimate
            print(f"  car on the {side:5s} line at {x:2d} m: curvature {e.curvature_1pm:+.5f}, heading "
                  f"{math.degrees(e.heading_rad):+.2f} deg, width {e.width_m:.2f} m, confidence {e.confidence:.2f}; "
                  f"moved below the car: left {worst['left']:.0f} px, right {worst['right']:.0f} px")
            if out is not None:
                small = cv2.resize(draw_overlay(image, r, f"car on the {side} line at {x} m"), (640, 360))
                cv2.imwrite(str(out / f"{path.stem}_{side}_{x}m.png"), small)
    return tried, moved


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("frames", nargs="+", help="image files of one camera, or TuSimple sample names (1.jpg)")
    ap.add_argument("--calib", type=Path, default=None, help="calibration file from `percept calibrate`")
    ap.add_argument("--height", type=float, default=None, help="camera height [m] (default: from the frames)")
    ap.add_argument("--out", type=Path, default=None, help="folder for overlays")
    args = ap.parse_args()
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
    paths = [frame_path(n) for n in args.frames]
    lanes = FootageLanes(RealLaneConfig(mount_height_m=args.height),
                         CameraCalibration.load(args.calib) if args.calib else None)
    # undistorted once here, so that the car is pasted where the fit sees the road
    frames = [lanes.prepare(read_image(p)) for p in paths]
    lanes = lanes.for_prepared()
    if args.height is None:
        lanes.calibrate(frames)
    tried = moved = 0
    for path, frame in zip(paths, frames):
        t, m = sweep(path, frame, lanes, args.out)
        tried, moved = tried + t, moved + m
    print(f"{moved} of {tried} placements moved a boundary by more than {TOLERANCE_PX} px below the car")


if __name__ == "__main__":
    main()
