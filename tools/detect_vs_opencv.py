"""percept's unconstrained people search against OpenCV's own ``detectMultiScale`` on a video, frame by frame: how
many of each one's detections the other matches at IoU >= 0.5, and the time each takes (one thread each, the two
alternated on every frame).

    python tools/detect_vs_opencv.py VIDEO [--every 5] [--model inria]

Both use the same people detector (the INRIA one unless ``--model`` names another; of a cascade such as ``sim``,
its first stage, since ``detectMultiScale`` takes one linear model) and scale step (1.05); ``detectMultiScale``
runs with its defaults, as ``tests/detection/test_hog.py`` calls it.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
from threadpoolctl import threadpool_limits

from percept.detection import LinearModel, detect_multiscale, iou


def frames(path: Path, every: int):
    cap = cv2.VideoCapture(str(path))
    if not cap.isOpened():
        sys.exit(f"cannot read the video {path}")
    k = 0
    while True:
        ok, frame = cap.read()
        if not ok:
            return
        if k % every == 0:
            yield frame
        k += 1


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("video", type=Path)
    ap.add_argument("--every", type=int, default=5, help="use every N-th frame (default 5)")
    ap.add_argument("--model", default="inria", help="inria, sim or a model file (default inria)")
    args = ap.parse_args()
    cv2.setNumThreads(1)
    try:
        # detectMultiScale takes one linear model: a cascade's first stage on both sides
        model = replace(LinearModel.named(args.model), second=None)
    except ValueError as e:
        sys.exit(str(e))
    hog = cv2.HOGDescriptor()
    hog.setSVMDetector(model.opencv_detector())
    ours_ms, theirs_ms = [], []
    n_ours = n_theirs = ours_hit = theirs_hit = 0
    with threadpool_limits(1):
        for frame in frames(args.video, max(args.every, 1)):
            t0 = time.perf_counter()
            ours = [d.box_px for d in detect_multiscale(frame, model)]
            t1 = time.perf_counter()
            rects, _ = hog.detectMultiScale(frame)
            t2 = time.perf_counter()
            ours_ms.append((t1 - t0) * 1e3)
            theirs_ms.append((t2 - t1) * 1e3)
            theirs = [(x, y, x + w, y + h) for x, y, w, h in np.asarray(rects).reshape(-1, 4)]
            n_ours, n_theirs = n_ours + len(ours), n_theirs + len(theirs)
            theirs_hit += sum(any(iou(t, o) >= 0.5 for o in ours) for t in theirs)
            ours_hit += sum(any(iou(o, t) >= 0.5 for t in theirs) for o in ours)
    if not ours_ms:
        sys.exit(f"no frames in {args.video}")
    print(f"{len(ours_ms)} frames, model {model.name}: detectMultiScale {n_theirs} detections, {theirs_hit} matched "
          f"by percept's; percept {n_ours}, {ours_hit} matched by detectMultiScale's")
    print(f"ms a frame (mean / median): percept {np.mean(ours_ms):.1f} / {np.median(ours_ms):.1f}, detectMultiScale "
          f"{np.mean(theirs_ms):.1f} / {np.median(theirs_ms):.1f}; percept "
          f"{np.mean(theirs_ms) / np.mean(ours_ms):.2f}x as fast")


if __name__ == "__main__":
    main()
