"""Training the sim people model on rendered frames (``percept train-detector``).

Positives: pedestrians in the rendered ``crossing`` frames (at least ``min_person_px`` tall and 80 % visible),
their window crops, a jittered copy (the search's stride and scale step) and the mirror images of both.
Negatives: random windows where the constrained search looks (its levels and corridor) that touch no person,
then hard negatives: the first model's false positives over the same frames, searched as the slot searches, and
optionally over frames of traffic scenarios (``negative_scenarios``, none by default), whose vehicles' corners (a
tail light over a wheel) the first model takes for people 30-45 m ahead (Dalal & Triggs 2005, sec. 4: hard
negatives are mined from the images the detector will search). A model trained with traffic negatives loses recall
on far people, so the shipped model uses one only as the second stage of a cascade (``LinearModel.second``: it
confirms what a model trained without them finds). Seeds are disjoint from every evaluation seed (0-19 closed
loop, 100-119 detection); the conditions rotate over them so that the model sees day, night and rain.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Callable

import numpy as np

from percept.detection import ConstrainedSearch, LinearModel, SearchConfig, iou_matrix, window_of
from percept.detection.training import features, hard_negatives, train_linear_svm, window_crop
from percept.sensors import EgoPath, LaneEstimate, ObjectKind, StereoRig
from percept.sims.world import check_condition, check_scenario

from .samples import for_each_frame

EVALUATION_SEEDS = frozenset(range(0, 20)) | frozenset(range(100, 120))
"""Seeds the evaluations use (0-19 closed loop, 100-119 detection): no training run may use one."""


@dataclass(frozen=True)
class TrainPlan:
    """What ``train_people_model`` renders and how it trains, validated on construction (ValueError)."""

    scenario: str = "crossing"  # the scenario whose people are the positives
    seeds: tuple[int, ...] = tuple(range(1000, 1010))  # training seeds (none may be an evaluation seed)
    conditions: tuple[str, ...] = ("clear", "night", "rain")  # rotated over the seeds
    every: int = 3  # sample every this many frames
    duration_s: float | None = None  # simulated length of each run [s] (None: the scenario's own)
    min_person_px: float = 30.0  # smallest positive, the person's box height [px]
    negatives_per_frame: int = 8  # random negative windows drawn per frame
    hard_per_frame: int = 10  # most hard negatives kept per frame (the highest scores)
    c: float = 0.01  # the linear SVM's C
    jitter_seed: int = 7  # seed of the random generator (jitter and random negatives)
    search: SearchConfig = field(default_factory=SearchConfig)  # the constrained search the windows come from
    negative_scenarios: tuple[str, ...] = ()  # traffic scenarios whose frames give hard negatives too
    negative_seeds: tuple[int, ...] = tuple(range(1000, 1005))  # their seeds (conditions rotated the same way)
    traffic_hard_per_frame: int = 3  # most hard negatives kept per frame of those scenarios

    def __post_init__(self) -> None:
        clash = sorted((set(self.seeds) | set(self.negative_seeds)) & EVALUATION_SEEDS)
        if clash:
            raise ValueError(f"training seeds {clash} are evaluation seeds (0-19, 100-119); choose others")
        if not self.seeds:
            raise ValueError("give at least one training seed")
        if self.negative_scenarios and not self.negative_seeds:
            raise ValueError("give at least one seed for the traffic scenarios' negatives")
        for name in self.conditions:
            check_condition(name)
        for name in self.negative_scenarios:
            check_scenario(name)


def truth_path(gt) -> EgoPath:
    """The ego path as the ground truth has it (the lane's true geometry, full confidence, the true speed)."""
    lane = gt.lane
    return EgoPath(LaneEstimate(lane.offset_m, lane.heading_rad, lane.curvature_1pm, lane.width_m, 1.0), gt.speed_mps)


def _people(gt) -> list:
    """The ground truth's pedestrians with a box on the image."""
    return [o for o in gt.objects if o.kind is ObjectKind.PEDESTRIAN and o.box_px is not None]


class _Collector:
    """Per frame: positive crops and random negative crops (pass 1), or hard negatives of a model (pass 2)."""

    def __init__(self, plan: TrainPlan, rig: StereoRig, model: LinearModel | None, tick: Callable[[], None],
                 keep_per_frame: int | None = None):
        self.plan, self.rng, self.tick = plan, np.random.default_rng(plan.jitter_seed), tick
        self.search = ConstrainedSearch(rig, model or LinearModel.inria(), plan.search)
        self.mining = model is not None
        self.keep_per_frame = plan.hard_per_frame if keep_per_frame is None else keep_per_frame
        self.pos: list[np.ndarray] = []
        self.neg: list[np.ndarray] = []

    def __call__(self, seed: int, frame, gt) -> None:
        people = _people(gt)
        # windows that touch a person, even a hidden one, are neither positives nor negatives
        taboo = np.array([window_of(o.box_px) for o in people]).reshape(-1, 4)
        if self.mining:
            self._mine(frame.left, gt, taboo)
        else:
            self._positives(frame.left, people)
            self._negatives(frame.left, gt, taboo)
        self.tick()

    def _positives(self, image, people) -> None:
        for o in people:
            h = o.box_px[3] - o.box_px[1]
            if h < self.plan.min_person_px or o.visible < 0.8:
                continue
            w = window_of(o.box_px)
            hw = w[3] - w[1]
            # a copy moved by up to a stride and resized by up to half the search's scale step
            half_step = (self.plan.search.step - 1.0) / 2
            d = self.rng.uniform(-1.0, 1.0, 3) * np.array([0.04, 0.04, half_step / 2]) * hw
            for win in (w, (w[0] + d[0] - d[2] / 2, w[1] + d[1] - d[2], w[2] + d[0] + d[2] / 2, w[3] + d[1] + d[2])):
                crop = window_crop(image, win)
                if crop is not None:
                    self.pos.append(crop)

    def _free(self, boxes: np.ndarray, taboo: np.ndarray) -> np.ndarray:
        """Which windows (N, 4) as (u0, v0, u1, v1) overlap no person's window."""
        if not len(taboo) or not len(boxes):
            return np.ones(len(boxes), bool)
        return iou_matrix(boxes, taboo).max(axis=1) < 0.05

    def _negatives(self, image, gt, taboo) -> None:
        path, s = truth_path(gt), self.search
        for _ in range(self.plan.negatives_per_frame):
            k = int(self.rng.integers(len(s.scales)))
            r = s.region(k, path)
            if r is None:
                continue
            wh = np.array([64, 128]) * s.scales[k]
            u = self.rng.uniform(r[0], max(r[2] - wh[0], r[0]))
            v = self.rng.uniform(r[1], max(r[3] - wh[1], r[1]))
            box = np.array([[u, v, u + wh[0], v + wh[1]]])
            if self._free(box, taboo)[0] and (crop := window_crop(image, tuple(box[0]))) is not None:
                self.neg.append(crop)

    def _mine(self, image, gt, taboo) -> None:
        boxes, scores, _ = self.search.windows(image, truth_path(gt))
        if not len(boxes):
            return
        corners = np.column_stack([boxes[:, :2], boxes[:, :2] + boxes[:, 2:]])
        free = np.flatnonzero(self._free(corners, taboo))
        for i in free[np.argsort(-scores[free])][:self.keep_per_frame]:
            if (crop := window_crop(image, tuple(corners[i]))) is not None:
                self.neg.append(crop)


def _drive(plan: TrainPlan, collector: _Collector, scenario: str | None = None,
           seeds: tuple[int, ...] | None = None) -> None:
    """Every sampled frame of ``scenario`` (default: the plan's) over ``seeds`` (default: the plan's) to the
    collector, the plan's conditions rotated over the seeds."""
    for i, seed in enumerate(plan.seeds if seeds is None else seeds):
        cond = plan.conditions[i % len(plan.conditions)]
        for_each_frame(scenario or plan.scenario, [seed], collector, every=plan.every, condition=cond,
                       duration_s=plan.duration_s)


def frames_to_sample(plan: TrainPlan) -> int:
    """How many frames the two passes sample in all (for a progress bar): the plan's scenario twice, then the
    traffic scenarios once."""
    from percept.sims import SCENARIOS
    from percept.sensors.frame import FRAME_RATE_HZ

    def frames(scenario: str) -> int:
        duration = plan.duration_s if plan.duration_s is not None else SCENARIOS[scenario].duration_s
        return len(range(0, max(int(round(duration * FRAME_RATE_HZ)), 1), plan.every))

    return (2 * len(plan.seeds) * frames(plan.scenario)
            + len(plan.negative_seeds) * sum(frames(s) for s in plan.negative_scenarios))


def train_people_model(plan: TrainPlan = TrainPlan(),
                       tick: Callable[[], None] = lambda: None) -> tuple[LinearModel, dict]:
    """Two passes over the training frames (positives and random negatives; then hard negatives of the first
    model): the final model and a record of what it was trained on. ValueError when the frames hold no
    positives."""
    rig = StereoRig()
    first = _Collector(plan, rig, None, tick)
    _drive(plan, first)
    if not first.pos:
        raise ValueError(f"no pedestrian of at least {plan.min_person_px:g} px was seen in {plan.scenario} "
                         f"(seeds {list(plan.seeds)}): give more seeds or a longer duration")
    pos = np.vstack([features(first.pos), features(first.pos, mirror=True)])
    neg = features(first.neg)
    model0 = train_linear_svm(pos, neg, plan.c)
    mining = _Collector(plan, rig, model0, tick)
    _drive(plan, mining)
    traffic = _Collector(plan, rig, model0, tick, keep_per_frame=plan.traffic_hard_per_frame)
    for scenario in plan.negative_scenarios:
        _drive(plan, traffic, scenario, plan.negative_seeds)
    own = hard_negatives(model0, features(mining.neg), limit=len(mining.neg)) if mining.neg else neg[:0]
    others = hard_negatives(model0, features(traffic.neg), limit=len(traffic.neg)) if traffic.neg else neg[:0]
    hard = np.vstack([own, others])
    model = train_linear_svm(pos, np.vstack([neg, hard]), plan.c)
    record = {"plan": {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(plan).items()},
              "positives": int(len(pos)), "random_negatives": int(len(neg)), "hard_negatives": int(len(hard)),
              "hard_negatives_traffic": int(len(others)),
              "train_recall": float(np.mean(pos @ model.weights + model.bias >= 0)),
              "train_false_positive_rate": float(np.mean(np.vstack([neg, hard]) @ model.weights + model.bias >= 0))}
    return model, record
