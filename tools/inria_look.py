"""INRIA detectMultiScale recall on rendered crossing pedestrians: seeds, every 3rd frame, 100-250 px, visible>=0.5.

The ground truth's ``visible`` counts the frame border (a person half out of the frame is half visible), so the
sample includes people the border cuts. Those are hard for any sliding window (it cannot centre on them), so the
recall on people wholly inside the frame is printed too: tight box at least 5 px from the image border, as
in the Caltech pedestrian benchmark's evaluation (Dollar et al., PAMI 2012; 'xRng', [5 635], 'yRng', [5 475] in
its toolbox). OpenCV pads the image by ``padding`` pixels (of each pyramid level) so that windows may reach past
its border; 8 px is what the bench's peer uses, 32 px lets a window centre on people cut by the border.
usage: inria_look.py [SEEDS, default 0,...,7] [PADDING_PX, default 8]
"""
import sys
import time

import cv2
import numpy as np

from percept.training.samples import for_each_frame
from percept.sensors import ObjectKind

cv2.setNumThreads(1)
BORDER_PX = 5
seeds = [int(s) for s in sys.argv[1].split(",")] if len(sys.argv) > 1 else list(range(8))
pad = int(sys.argv[2]) if len(sys.argv) > 2 else 8
hog = cv2.HOGDescriptor()
hog.setSVMDetector(cv2.HOGDescriptor_getDefaultPeopleDetector())


def win(b):
    """Tight box -> the detector's 1:2 window in which the person fills the middle 3/4 of the height."""
    u0, v0, u1, v1 = b
    h = (v1 - v0) / 0.75
    cu, cv = (u0 + u1) / 2, (v0 + v1) / 2
    return cu - h / 4, cv - h / 2, cu + h / 4, cv + h / 2


def iou(a, b):
    """Intersection over union of two (u0, v0, u1, v1) boxes."""
    iw = max(0, min(a[2], b[2]) - max(a[0], b[0]))
    ih = max(0, min(a[3], b[3]) - max(a[1], b[1]))
    i = iw * ih
    return i / ((a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - i)


def in_frame(b, shape):
    """Whether box ``b`` lies at least BORDER_PX inside an image of ``shape``."""
    h, w = shape[:2]
    return b[0] >= BORDER_PX and b[1] >= BORDER_PX and b[2] <= w - BORDER_PX and b[3] <= h - BORDER_PX


found = {True: 0, False: 0}  # in the frame or cut by its border -> found
miss = {True: [], False: []}


def fn(seed, frame, gt):
    """Tally the frame's people 100-250 px tall and at least half visible: found by detectMultiScale or missed."""
    peds = [o for o in gt.objects if o.kind is ObjectKind.PEDESTRIAN and o.box_px and o.visible >= 0.5
            and 100 <= o.box_px[3] - o.box_px[1] <= 250]
    if not peds:
        return
    rects, _ = hog.detectMultiScale(frame.left, winStride=(8, 8), padding=(pad, pad), scale=1.05)
    dets = [(x, y, x + w, y + h) for x, y, w, h in np.asarray(rects).reshape(-1, 4)]
    for o in peds:
        inside = in_frame(o.box_px, frame.left.shape)
        best = max((iou(win(o.box_px), d) for d in dets), default=0)
        if best >= 0.5:
            found[inside] += 1
        else:
            miss[inside].append((seed, frame.index, o.obj_id, o.box_px[3] - o.box_px[1], round(float(best), 2)))


t = time.time()
for_each_frame("crossing", seeds, fn, every=3)
n_in = found[True] + len(miss[True])
n_all = n_in + found[False] + len(miss[False])
print(f"seeds {seeds}, padding {pad} px")
print(f"in the frame: found {found[True]}/{n_in} = {found[True] / max(n_in, 1):.3f}  ({time.time() - t:.0f} s)")
print(f"everyone at least half visible (also people the frame border cuts): found {found[True] + found[False]}/"
      f"{n_all} = {(found[True] + found[False]) / max(n_all, 1):.3f}")
for m in miss[True]:
    print("miss", m)
print(f"cut by the border: found {found[False]}/{found[False] + len(miss[False])}")
