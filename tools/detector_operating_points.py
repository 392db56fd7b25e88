"""Window-level operating points of people models on the far field: over ``crossing`` frames (every 3rd, all the
constrained search's scales, the truth's ego path), the best window score on each true person 24-40 px tall and at
least half visible (a window at IoU >= 0.5 with the person's window), and the scores of the windows touching no
person. Printed per model and threshold: the share of far people found and the windows kept off people, so that two
models are compared at the same false positives, not only at the threshold each was trained for. A cascade (such as
``sim``) is scored by its first stage's windows.
usage: detector_operating_points.py CONDITION SEEDS(a,b,c) MODEL [MODEL ...]   (MODEL: sim, inria or a .npz file)
"""
import sys

import cv2
import numpy as np

from percept.detection import ConstrainedSearch, LinearModel, SearchConfig, iou_matrix, window_of
from percept.sensors import ObjectKind, StereoRig
from percept.training.people import truth_path
from percept.training.samples import for_each_frame

cv2.setNumThreads(1)
THRESHOLDS = (-0.4, -0.2, 0.0, 0.25)

cond, seeds, models = sys.argv[1], [int(s) for s in sys.argv[2].split(",")], sys.argv[3:]
searches = {m: ConstrainedSearch(StereoRig(), LinearModel.named(m), SearchConfig(threshold=min(THRESHOLDS)))
            for m in models}
best = {m: [] for m in models}
off = {m: [] for m in models}


def score_frame(seed, frame, gt):
    """Each model's best window score on each far person and the scores of the windows touching no person."""
    people = [o for o in gt.objects if o.kind is ObjectKind.PEDESTRIAN and o.box_px is not None]
    far = [o for o in people if 24 <= o.box_px[3] - o.box_px[1] < 40 and o.visible >= 0.5]
    taboo = np.array([window_of(o.box_px) for o in people]).reshape(-1, 4)
    for m, search in searches.items():
        boxes, scores, _ = search.windows(frame.left, truth_path(gt))
        corners = np.column_stack([boxes[:, :2], boxes[:, :2] + boxes[:, 2:]])
        for o in far:
            hit = iou_matrix(corners, np.array([window_of(o.box_px)]))[:, 0] >= 0.5 if len(corners) else []
            best[m].append(float(scores[hit].max()) if np.any(hit) else -np.inf)
        free = (iou_matrix(corners, taboo).max(axis=1) < 0.05 if len(taboo) and len(corners)
                else np.ones(len(corners), bool))
        off[m] += scores[free].tolist()


for_each_frame("crossing", seeds, score_frame, every=3, condition=cond)
for m in models:
    b, g = np.array(best[m]), np.array(off[m])
    print(f"{m}: {len(b)} far people")
    for t in THRESHOLDS:
        print(f"  threshold {t:+.2f}: far people found {np.mean(b >= t):.3f}, windows off people {int(np.sum(g >= t))}")
