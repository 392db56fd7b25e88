"""What a batch is: its scenarios, conditions and seeds (``parse_seeds``), the slots and options every run shares, and
the jobs it expands to; validated before any run starts."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

from percept.drive.config import DriveConfig
from percept.drive.limits import MAX_SEED
from percept.sensors import Source
from percept.sims import WorldConfig

MAX_SEEDS = 10_000
"""Most seeds one batch takes; a range is counted before it is expanded, so '0-99999999999' is refused at once."""


class Engine(str, Enum):
    """Where a batch's runs go: worker processes on this machine, or a Ray cluster."""

    LOCAL = "local"
    RAY = "ray"


def parse_seeds(text: str, option: str = "--seeds") -> list[int]:
    """"A-B" (inclusive), "A,B,C" or "N" -> sorted unique seeds, each 0 to MAX_SEED and at most MAX_SEEDS of
    them; ValueError with the expected forms otherwise (naming ``option``)."""
    spans = []
    try:
        for part in text.split(","):
            a, sep, b = part.strip().partition("-")
            lo, hi = int(a), int(b) if sep else int(a)
            if lo < 0 or hi < lo:
                raise ValueError
            spans.append((lo, hi))
    except ValueError:
        raise ValueError(f"{option} must look like 0-9, 3 or 1,4,7 (non-negative, A <= B), got '{text}'") from None
    if (top := max(hi for _, hi in spans)) > MAX_SEED:
        raise ValueError(f"{option} go from 0 to {MAX_SEED}, got {top}")
    count, end = 0, -1  # seeds covered by the spans, overlaps counted once
    for lo, hi in sorted(spans):
        count += max(0, hi - max(lo, end + 1) + 1)
        end = max(end, hi)
    if count > MAX_SEEDS:
        raise ValueError(f"{option} '{text}' names {count} seeds; a batch takes at most {MAX_SEEDS} (split it)")
    return sorted({s for lo, hi in spans for s in range(lo, hi + 1)})


EGOS = ("percept", "mobil")
"""Who may drive a batch's runs (``EvalPlan.ego``)."""


@dataclass(frozen=True)
class Job:
    """One run of the batch."""

    scenario: str  # scenario name
    condition: str  # condition name
    seed: int  # the run's seed

    @property
    def name(self) -> str:
        """``<scenario>-<condition>-<seed>``: the run file's name."""
        return f"{self.scenario}-{self.condition}-{self.seed}"


@dataclass(frozen=True)
class EvalPlan:
    """A batch, validated on construction: a bad name, condition or slot raises ValueError before any run starts."""

    scenarios: tuple[str, ...]  # scenario names
    conditions: tuple[str, ...]  # condition names
    seeds: tuple[int, ...]  # the seeds of every (scenario, condition)
    slots: dict = field(default_factory=dict)  # task name -> Source, for the tasks not on ``default``
    duration_s: float | None = None  # simulated length of each run [s] (None: each scenario's own)
    detector: str = "sim"  # people model of the vision pedestrian slot
    default: Source = Source.VISION  # the source of a task not in slots (as in DriveConfig)
    rear: bool | None = None  # the rear stereo rig: True on, False off, None each scenario's default (DriveConfig.rear)
    lane_changes: bool = True  # the car changes lanes (DriveConfig.lane_changes)
    ego: str = "percept"  # who drives: "percept" (its agent) or "mobil" (highway-env's IDM with MOBIL lane changes in
    # the ego's place, every slot privileged: the anchor for progress)

    def __post_init__(self) -> None:
        if not self.scenarios or not self.conditions or not self.seeds:
            raise ValueError("a batch needs at least one scenario, one condition and one seed")
        if self.ego not in EGOS:
            raise ValueError(f"--ego must be {' or '.join(EGOS)}, got '{self.ego}'")
        for sc in self.scenarios:
            for c in self.conditions:
                # builds and validates the whole configuration of one run (names, condition, slots, duration)
                self.config(Job(sc, c, self.seeds[0]))

    def config(self, job: Job) -> DriveConfig:
        """The drive configuration of one job."""
        mobil = self.ego == "mobil"
        world = WorldConfig(scenario=job.scenario, seed=job.seed, condition=job.condition, autopilot=mobil,
                            autopilot_lane_changes=mobil)
        return DriveConfig(world, self.duration_s, {} if mobil else dict(self.slots), detector=self.detector,
                           default=Source.PRIVILEGED if mobil else self.default, rear=self.rear,
                           lane_changes=self.lane_changes and not mobil)

    @property
    def tasks(self) -> tuple:
        """The slot table the runs are driven with."""
        return self.config(self.jobs[0]).tasks

    @property
    def jobs(self) -> list[Job]:
        """Every run of the batch: scenario by scenario, condition by condition, seed by seed."""
        return [Job(sc, c, s) for sc in self.scenarios for c in self.conditions for s in self.seeds]
