"""Scoring the neighbours task: its tracks against the true vehicles in the ego lane and the lanes either side.

Each frame the estimated tracks are matched one to one to the true vehicles (``truth_neighbours``, bumper gaps to
``MATCH_RANGE_M``) by the Hungarian method on along-lane position and lateral position from the ego lane's centre,
gated by |dx| <= max(4 m, 0.1 |x|) (for a track no rig measured this frame, held by prediction, also up to three
sigma of its own position: it says a vehicle may be anywhere there) and |dy| <= 1.8 m. Recall per zone and lane:
ahead and behind, of the vehicles within ``RECALL_GAP_M`` at least half visible in the rig facing them; beside, of
every vehicle there in a lane beside the ego's that a rig has seen on its way there. Over the matched pairs: lane
accuracy; of those ahead and behind that recall counts (what a rig measures), the median |gap_est - gap_true| /
gap_true ahead and behind (within ``GAP_ERR_M``, and by bin of the true gap) and the median relative speed error.
A metric with no sample is None.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from percept.longitudinal.metrics import range_abs_rel_err, range_abs_rel_err_by_bin
from percept.sensors import Zone

from .neighbours_events import CollisionRecorder, CutInEvents
from .neighbours_truth import truth_neighbours
from .rows import Rows

MATCH_RANGE_M = 100.0
"""True vehicles within this bumper gap ahead or behind are matched to the tracks [m]."""
RECALL_GAP_M = 60.0
"""Recall ahead and behind counts the vehicles within this bumper gap [m]."""
GAP_ERR_M = 40.0
"""The gap errors ``gap_abs_rel_err_ahead`` and ``_behind`` are medians over true gaps up to this [m]."""
GATE_X_M = 4.0
"""A track matches a vehicle within max(this, GATE_X_SHARE |x|) along the lane [m]..."""
GATE_X_SHARE = 0.1
"""... a share of the vehicle's distance (stereo range error grows with range)."""
GATE_Y_M = 1.8
"""... and within this across [m]."""
LANES = (-1, 0, 1)
"""The lanes scored, relative to the ego's."""


def match_tracks(tracks, truth, width_m: float) -> list[tuple[int, int]]:
    """One-to-one (track index, truth index) pairs of ``Neighbour``s within the gate (see the module docstring), at
    least total cost, the cost of a pair (dx / gate_x)^2 + (dy / gate_y)^2; a track's lateral position is
    lane * ``width_m`` + lateral_m."""
    if not tracks or not truth:
        return []
    pos = np.array([[n.x_m, n.lane * width_m + n.lateral_m] for n in tracks])
    ref = np.array([[n.x_m, n.lane * width_m + n.lateral_m] for n in truth])
    d = np.abs(pos[:, None, :] - ref[None, :, :])
    # gate_x = max(4 m, 0.1 |x_true|, 3 sigma_x of a predicted track)
    spread = np.array([3 * n.sigma_x_m if n.predicted else 0.0 for n in tracks])[:, None]
    gate_x = np.maximum(np.maximum(GATE_X_M, GATE_X_SHARE * np.abs(ref[:, 0]))[None, :], spread)
    inside = (d[..., 0] <= gate_x) & (d[..., 1] <= GATE_Y_M)
    cost = np.where(inside, (d[..., 0] / gate_x) ** 2 + (d[..., 1] / GATE_Y_M) ** 2, 1e6)
    rows, cols = linear_sum_assignment(cost)
    return [(int(r), int(c)) for r, c in zip(rows, cols) if inside[r, c]]


def recall_eligible(n, seen: set = frozenset()) -> bool:
    """Whether recall counts a true ``Neighbour``: beside in a lane beside the ego's once a rig has seen it (``seen``:
    the ids of the vehicles at least half visible in a rig so far; one that has been beside the ego since the run
    began, unseen, cannot be known), or ahead (behind) within RECALL_GAP_M seen by the forward (rear) rig."""
    if n.zone is Zone.BESIDE:
        return n.lane != 0 and n.track_id in seen
    facing = "front" if n.zone is Zone.AHEAD else "rear"
    return n.gap_m <= RECALL_GAP_M and n.camera == facing


class _Recall:
    """Matched and eligible counts per zone and lane."""

    def __init__(self):
        self.hits = {(z, k): [0, 0] for z in Zone for k in LANES}

    def add(self, zone: Zone, lane: int, matched: bool) -> None:
        """One eligible true vehicle of ``zone`` and ``lane``, found or not."""
        c = self.hits[(zone, lane)]
        c[0] += int(matched)
        c[1] += 1

    def rate(self, zone: Zone, lanes=LANES) -> float | None:
        """matched / eligible over ``lanes`` of ``zone``; None without an eligible vehicle."""
        m, n = (sum(self.hits[(zone, k)][i] for k in lanes) for i in (0, 1))
        return m / n if n else None

    def result(self) -> dict:
        """recall_<zone>, recall_<zone>_by_lane (beside: lanes -1 and +1 only) and the counts."""
        out = {}
        for z in Zone:
            lanes = (-1, 1) if z is Zone.BESIDE else LANES
            out[f"recall_{z.value}"] = self.rate(z)
            out[f"recall_{z.value}_by_lane"] = {str(k): self.rate(z, (k,)) for k in lanes}
        # the counts behind the rates, so that a batch can pool its runs' frames
        out["counts"] = {z.value: {"matched": sum(self.hits[(z, k)][0] for k in LANES),
                                   "eligible": sum(self.hits[(z, k)][1] for k in LANES)} for z in Zone}
        return out


class NeighbourScorer:
    """The neighbours task's JSON group: recall, lane accuracy, gap and relative speed errors, beside-absent frames
    and warnings (the vision slot's estimate only), true cut-ins and collisions (every run)."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.recall = _Recall()
        self.lanes_agree = Rows(1)  # 1 where a matched pair's lanes agree
        self.gaps = Rows(3)  # zone (+1 ahead, -1 behind), estimated gap [m], true gap [m]
        self.rel_speed_err = Rows(1)  # |rel speed est - true| [m/s]
        self.beside_absent = 0
        self.seen: set[int] = set()  # ids of the true vehicles a rig has seen at least half so far
        self.cut_ins = CutInEvents(ctx.vision)
        self.collisions = CollisionRecorder()
        self.frames = 0
        self._times = [None, None]  # first and last frame times [s]

    def update(self, estimate, debug, step) -> None:
        """One frame: ``estimate`` the slot's ``Neighbours`` (or None), ``step`` its ``StepTruth``."""
        gt = step.truth
        self.frames += 1
        self._times = [gt.time_s if self._times[0] is None else self._times[0], gt.time_s]
        truth = truth_neighbours(gt, MATCH_RANGE_M, MATCH_RANGE_M).tracks
        tracks = estimate.tracks if estimate is not None else ()
        pairs = match_tracks(tracks, truth, gt.lane.width_m) if self.ctx.vision else []
        if self.ctx.vision:
            self._score_pairs(tracks, truth, pairs)
        matched = {tracks[i].track_id: truth[j].track_id for i, j in pairs}
        self.cut_ins.update(gt, {n.track_id: n for n in truth}, tracks, matched)
        self.collisions.update(gt)

    def _score_pairs(self, tracks, truth, pairs) -> None:
        """Recall, beside-absent frames and the matched pairs' errors of one frame."""
        found = {j for _, j in pairs}
        self.seen.update(n.track_id for n in truth if n.camera is not None)
        beside_missed = False
        for j, n in enumerate(truth):
            if recall_eligible(n, self.seen):
                self.recall.add(n.zone, n.lane, j in found)
                beside_missed |= n.zone is Zone.BESIDE and j not in found
        self.beside_absent += int(beside_missed)
        for i, j in pairs:
            est, tru = tracks[i], truth[j]
            self.lanes_agree.append((float(est.lane == tru.lane),))
            # gaps and speeds are what a rig measures: of the vehicles ahead and behind it sees at least half of
            if tru.zone is Zone.BESIDE or not recall_eligible(tru):
                continue
            # |v_rel_est - v_rel_true|
            self.rel_speed_err.append((abs(est.rel_speed_mps - tru.rel_speed_mps),))
            self.gaps.append((1.0 if tru.zone is Zone.AHEAD else -1.0, est.gap_m, tru.gap_m))

    def _minutes(self) -> float | None:
        """The run's length [min]: its frames times the frame period (from the first and last frame times)."""
        t0, t1 = self._times
        if self.frames < 2 or t1 <= t0:
            return None
        # T = n (t_last - t_first) / (n - 1)
        return self.frames * (t1 - t0) / (self.frames - 1) / 60.0

    def _gap_errors(self) -> dict:
        """The gap errors ahead and behind: medians within GAP_ERR_M, and by bin of the true gap."""
        g = self.gaps.values()
        out, bins = {}, {}
        for name, code in (("ahead", 1.0), ("behind", -1.0)):
            est, true = g[g[:, 0] == code, 1], g[g[:, 0] == code, 2]
            near = true <= GAP_ERR_M
            out[f"gap_abs_rel_err_{name}"] = range_abs_rel_err(est[near], true[near])
            bins[name] = range_abs_rel_err_by_bin(est, true)
        return out | {"gap_abs_rel_err_by_bin": bins}

    def result(self) -> dict:
        """The JSON group (docs/design.md, "Scoring definitions", Neighbours)."""
        out: dict = {}
        if self.ctx.vision:
            lanes, err = self.lanes_agree.values()[:, 0], self.rel_speed_err.values()[:, 0]
            out |= self.recall.result()
            out |= {"lane_accuracy": float(lanes.mean()) if len(lanes) else None, **self._gap_errors(),
                    "rel_speed_abs_err_mps": float(np.median(err)) if len(err) else None,
                    "beside_absent_frames": self.beside_absent}
        else:
            keys = [f"recall_{z.value}{s}" for z in Zone for s in ("", "_by_lane")]
            out |= dict.fromkeys(keys + ["counts", "lane_accuracy", "gap_abs_rel_err_ahead", "gap_abs_rel_err_behind",
                                         "gap_abs_rel_err_by_bin", "rel_speed_abs_err_mps", "beside_absent_frames"])
        out |= self.cut_ins.result(self._minutes())
        return out | {"collisions": self.collisions.records, "frames": self.frames}
