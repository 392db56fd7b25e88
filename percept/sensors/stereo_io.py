"""The calibration of a rectified stereo pair, read from Middlebury's calib.txt or percept's stereo_calib.json.

After rectification both cameras share the focal length f and the image rows; a point seen at column x_l in the
left image and x_r in the right one has the disparity d = x_l - x_r [px] and the depth

    Z = f b / (d + doffs)

with b the baseline and doffs = cx_right - cx_left the difference of the principal points' columns (0 when both
were rectified to the same principal point, as ``cv2.stereoRectify`` does by default). Hartley & Zisserman,
*Multiple View Geometry*, 2nd ed., sec. 11.12; Scharstein et al., GCPR 2014 (the Middlebury 2014 files).

Formats read by ``RectifiedStereo.load``:

- Middlebury's calib.txt: ``key=value`` lines, ``cam0=[f 0 cx; 0 f cy; 0 0 1]``, ``cam1=[...]``, ``doffs``,
  ``baseline`` [mm], ``width``, ``height``, ``ndisp`` (other keys ignored); also the ``key value`` variant with
  ``focal_px``, ``cx_px``, ``cy_px``, ``doffs_px``, ``baseline_mm`` (or ``baseline_m``) and ``#`` comments.
- percept's stereo_calib.json (``percept calibrate DIR --stereo``): the rectified projections P1, P2 (3x4);
  f = P1[0,0], b = -P2[0,3] / P2[0,0] (in the units of the calibration's square size: metres with --square).
"""

from __future__ import annotations

import json
import math
import re
import zipfile
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Optional

import cv2
import numpy as np

from .footage import decode_image

_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


@dataclass(frozen=True)
class RectifiedStereo:
    """Intrinsics shared by both rectified images and the rig's baseline.

    fx, fy: focal lengths [px]; cx, cy: the left image's principal point [px]; baseline_m: distance between the
    optical centres [m] (> 0); doffs_px: cx_right - cx_left [px]; width, height: the image size these values
    hold for [px] (None when the file does not say); ndisp: the disparity search range the file suggests [px]
    (None when it gives none); source: the file read.
    """

    fx: float
    fy: float
    cx: float
    cy: float
    baseline_m: float
    doffs_px: float = 0.0
    width: Optional[int] = None
    height: Optional[int] = None
    ndisp: Optional[int] = None
    source: str = ""

    def __post_init__(self) -> None:
        if not all(math.isfinite(v) for v in (self.fx, self.fy, self.cx, self.cy, self.doffs_px)):
            raise ValueError(f"calibration values must be finite, got fx={self.fx} fy={self.fy} cx={self.cx} "
                             f"cy={self.cy} doffs={self.doffs_px}")
        if not (self.fx > 0 and self.fy > 0):
            raise ValueError(f"focal lengths must be positive, got fx={self.fx}, fy={self.fy}")
        if not (math.isfinite(self.baseline_m) and self.baseline_m > 0):
            raise ValueError(f"the baseline must be a positive distance, got {self.baseline_m}")
        for name in ("width", "height", "ndisp"):
            v = getattr(self, name)
            if v is not None and v < 1:
                raise ValueError(f"{name} must be at least 1, got {v}")

    def depth_m(self, disparity_px: np.ndarray) -> np.ndarray:
        """Depth [m] (float32, same shape) of each disparity [px]; NaN where the disparity is not finite or
        d + doffs <= 0 (at or beyond infinity)."""
        d = np.asarray(disparity_px, dtype=np.float64) + self.doffs_px
        with np.errstate(divide="ignore", invalid="ignore"):
            # Z = f b / (d + doffs)
            z = np.where(d > 0, self.fx * self.baseline_m / d, np.nan)
        return z.astype(np.float32)

    def scaled(self, s: float) -> "RectifiedStereo":
        """The same rig for images resized by ``s``: pixel quantities times s (pixel centres at integers:
        x' = s (x + 0.5) - 0.5)."""
        if not (math.isfinite(s) and s > 0):
            raise ValueError(f"scale must be a positive number, got {s}")
        size = {k: (None if v is None else max(1, round(v * s))) for k, v in
                (("width", self.width), ("height", self.height), ("ndisp", self.ndisp))}
        return replace(self, fx=self.fx * s, fy=self.fy * s, cx=s * (self.cx + 0.5) - 0.5,
                       cy=s * (self.cy + 0.5) - 0.5, doffs_px=self.doffs_px * s, **size)

    def for_image(self, width: int, height: int) -> "RectifiedStereo":
        """This calibration for images of ``width`` x ``height`` px: itself when the size matches or the file gave
        none, rescaled when the images are a uniform down- or up-sampling of the calibrated size (e.g. Middlebury's
        full-size calib.txt with its quarter-size images). ValueError when the aspect ratios differ."""
        if self.width is None or self.height is None:
            return replace(self, width=int(width), height=int(height))
        if (self.width, self.height) == (width, height):
            return self
        sx, sy = width / self.width, height / self.height
        if abs(sx - sy) > 0.01 * max(sx, sy):
            raise ValueError(f"the images are {width}x{height} px but {self.source or 'the calibration'} is for "
                             f"{self.width}x{self.height} (another aspect ratio); give the calibration of these images")
        return replace(self.scaled(sx), width=int(width), height=int(height))

    def to_dict(self) -> dict:
        return {"fx": self.fx, "fy": self.fy, "cx": self.cx, "cy": self.cy, "baseline_m": self.baseline_m,
                "doffs_px": self.doffs_px, "width": self.width, "height": self.height, "ndisp": self.ndisp,
                "source": self.source}

    @classmethod
    def load(cls, path: Path | str) -> "RectifiedStereo":
        """Read a Middlebury calib.txt or a percept stereo_calib.json (see the module docstring). ValueError, naming
        the file and what to do, when it is missing, unreadable, of another format or has no baseline."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise ValueError(f"calibration file {path} does not exist") from None
        except IsADirectoryError:
            raise ValueError(f"calibration {path} is a folder; give its calib.txt or stereo_calib.json") from None
        except (OSError, UnicodeDecodeError) as e:
            raise ValueError(f"cannot read calibration file {path} ({getattr(e, 'strerror', None) or e})") from None
        try:
            if text.lstrip().startswith("{"):
                return _from_json(json.loads(text), str(path))
            return _from_calib_txt(text, str(path))
        except json.JSONDecodeError as e:
            raise ValueError(f"{path} is not valid JSON ({e.msg} at line {e.lineno})") from None
        except (KeyError, TypeError, IndexError) as e:
            raise ValueError(f"{path} is not a percept stereo_calib.json nor a Middlebury calib.txt ({e!r})") from None
        except ValueError as e:  # a value out of range: say which file holds it
            raise ValueError(str(e) if str(e).startswith(str(path)) else f"{path}: {e}") from None


def _no_baseline(source: str, what: str) -> ValueError:
    return ValueError(f"{source} has no baseline ({what}); give a stereo calibration: Middlebury's calib.txt "
                      f"(baseline=... in mm) or `percept calibrate DIR --stereo`'s stereo_calib.json")


def _from_json(d: dict, source: str) -> RectifiedStereo:
    if not isinstance(d, dict):
        raise TypeError("the JSON is not an object")
    if "P2" not in d:
        what = "a single-camera calibration" if "fx" in d else "no rectified projection P2"
        raise _no_baseline(source, what)
    p1, p2 = np.asarray(d["P1"], dtype=float), np.asarray(d["P2"], dtype=float)
    if p1.shape != (3, 4) or p2.shape != (3, 4):
        raise ValueError(f"{source}: P1 and P2 must be 3x4 matrices, got {p1.shape} and {p2.shape}")
    if abs(p2[1, 3]) > 1e-9 * max(1.0, abs(p2[0, 3])):
        raise ValueError(f"{source} rectifies a vertical rig (P2[1,3] != 0); only side-by-side pairs are supported")
    # P2 = [f 0 cx2 -f b; 0 f cy 0; 0 0 1 0]  =>  b = -P2[0,3] / P2[0,0]
    baseline = -p2[0, 3] / p2[0, 0]
    if not (math.isfinite(baseline) and baseline > 0):
        raise _no_baseline(source, f"P2 gives {baseline:g}")
    left = d.get("left", {})
    w, h = left.get("width"), left.get("height")
    return RectifiedStereo(float(p1[0, 0]), float(p1[1, 1]), float(p1[0, 2]), float(p1[1, 2]), float(baseline),
                           float(p2[0, 2] - p1[0, 2]), None if w is None else int(w), None if h is None else int(h),
                           None, source)


def _parse_pairs(text: str) -> dict[str, list[float]]:
    """``key=value`` or ``key value`` lines (``#`` starts a comment) -> key (lower case) -> the numbers in value."""
    out: dict[str, list[float]] = {}
    for line in text.splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        key, _, value = line.partition("=") if "=" in line else line.partition(" ")
        out[key.strip().lower()] = [float(x) for x in _NUMBER.findall(value)]
    return out


def _one(kv: dict[str, list[float]], *keys: str) -> Optional[float]:
    for k in keys:
        if kv.get(k):
            return kv[k][0]
    return None


def _from_calib_txt(text: str, source: str) -> RectifiedStereo:
    kv = _parse_pairs(text)
    cam0, cam1 = kv.get("cam0", []), kv.get("cam1", [])
    if len(cam0) == 9:
        # cam0 = [fx 0 cx; 0 fy cy; 0 0 1]
        fx, cx, fy, cy = cam0[0], cam0[2], cam0[4], cam0[5]
    else:
        fx = _one(kv, "focal_px", "fx_px", "fx", "f")
        fy = _one(kv, "fy_px", "fy") or fx
        cx, cy = _one(kv, "cx_px", "cx"), _one(kv, "cy_px", "cy")
    if fx is None or cx is None or cy is None:
        raise ValueError(f"{source} is neither a Middlebury calib.txt (cam0=[f 0 cx; 0 f cy; 0 0 1], doffs, baseline) "
                         "nor a percept stereo_calib.json; give one of those")
    doffs = _one(kv, "doffs", "doffs_px")
    if doffs is None:
        # doffs = cx_right - cx_left
        doffs = cam1[2] - cx if len(cam1) == 9 else 0.0
    mm = _one(kv, "baseline", "baseline_mm")
    baseline = mm / 1000.0 if mm is not None else _one(kv, "baseline_m")
    if baseline is None or not (math.isfinite(baseline) and baseline > 0):
        raise _no_baseline(source, "no positive baseline= line" if baseline is None else f"baseline {baseline:g}")
    ints = {k: (None if _one(kv, k) is None else int(_one(kv, k))) for k in ("width", "height", "ndisp")}
    return RectifiedStereo(fx, fy, cx, cy, baseline, doffs, source=source, **ints)


def read_disparity(path: Path | str) -> np.ndarray:
    """A disparity map [px] as float32 (H, W), NaN where it holds none (inf, NaN or <= 0: Middlebury's "unknown"):
    a .npz with one array (or a ``disparity`` entry), a .npy, or a .pfm (Middlebury's disp0.pfm). ValueError when
    the file is missing, unreadable or not a 2-D map."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"disparity file {path} {'is a folder' if path.is_dir() else 'does not exist'}")
    suffix = path.suffix.lower()
    try:
        if suffix == ".npz":
            with np.load(path, allow_pickle=False) as z:
                keys = list(z.keys())
                if "disparity" not in keys and len(keys) != 1:
                    raise ValueError(f"holds {len(keys)} arrays ({', '.join(keys[:5])}); keep one or name it "
                                     "'disparity'")
                d = z["disparity" if "disparity" in keys else keys[0]]
        elif suffix == ".npy":
            with open(path, "rb") as f:  # anything else np.load would try to unpickle, and refuse in those words
                if f.read(6) != b"\x93NUMPY":
                    raise ValueError("not a NumPy .npy array (np.save writes one)")
            d = np.load(path, allow_pickle=False)
        elif suffix == ".pfm":
            try:
                d = decode_image(path, cv2.IMREAD_UNCHANGED)
            except ValueError:
                raise ValueError("not a whole PFM image this OpenCV can decode") from None
        else:
            raise ValueError("unknown kind; give a .npz, .npy or .pfm disparity map")
    except ValueError as e:
        raise ValueError(f"cannot read disparity file {path}: {e}") from None
    except (OSError, EOFError, zipfile.BadZipFile) as e:
        raise ValueError(f"cannot read disparity file {path} ({e})") from None
    d = np.asarray(d)
    if d.ndim != 2 or not np.issubdtype(d.dtype, np.number):
        raise ValueError(f"disparity file {path} holds a {d.dtype} array of shape {d.shape}, not a 2-D map")
    d = d.astype(np.float32)
    d[~(np.isfinite(d) & (d > 0))] = np.nan
    return d


def resize_disparity(disparity_px: np.ndarray, width: int, height: int) -> np.ndarray:
    """A disparity map resampled to ``width`` x ``height`` px (nearest neighbour: no value is mixed with an unknown
    one) and its values scaled by width ratio (disparities are horizontal pixel distances)."""
    h, w = disparity_px.shape
    if (w, h) == (width, height):
        return disparity_px
    out = cv2.resize(disparity_px, (int(width), int(height)), interpolation=cv2.INTER_NEAREST)
    return out * np.float32(width / w)
