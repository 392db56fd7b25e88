"""What one drive run is: the world, its length and where each task's estimate comes from."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from percept.sensors import Source
from percept.sims import WorldConfig, with_rear

from . import tasks as tasks_module
from .limits import MAX_DURATION_S
from .tasks import Task


@dataclass(frozen=True)
class DriveConfig:
    """One drive run, validated on construction (ValueError naming the bad value)."""

    world: WorldConfig = field(default_factory=WorldConfig)  # scenario, seed, condition, rig
    duration_s: float | None = None  # simulated length [s] (None: the scenario's own)
    sources: dict = field(default_factory=dict)  # task name -> Source, for the tasks not on ``default``
    tasks: tuple[Task, ...] = field(default_factory=lambda: tasks_module.TASKS)  # the slot table
    detector: str = "sim"  # people model of the vision pedestrian slot: "sim", "inria" or a model file
    default: Source = Source.VISION  # the source of a task not in sources (privileged where it has no vision slot)
    # the rear stereo rig (``percept.sensors.rear_rig`` of the world's rig): True on, False off, None the scenario's
    # default (on where its traffic changes lanes, or as ``world.rear_rig`` says); resolved to True or False, and
    # ``world.rear_rig`` set to match
    rear: bool | None = None
    lane_changes: bool = True  # the car changes lanes when MOBIL favours it, and swerves into a free lane when braking
    # alone falls short (control.LaneChange; without a view behind it never does either); False: it keeps its lane

    def __post_init__(self) -> None:
        object.__setattr__(self, "world", with_rear(self.world, self.rear))
        object.__setattr__(self, "rear", self.world.rear_rig is not None)
        d = self.duration_s
        if d is not None and not (isinstance(d, (int, float)) and math.isfinite(d) and 0 < d <= MAX_DURATION_S):
            raise ValueError(f"--duration must be a finite number of seconds between 0 and {MAX_DURATION_S:g}, "
                             f"got {d}")
        names = {t.name: t for t in self.tasks}
        clean = {}
        for name, src in dict(self.sources).items():
            if name not in names:
                raise ValueError(f"unknown task '{name}'; the tasks are: {', '.join(names)}")
            try:
                clean[name] = Source(src)
            except ValueError:
                raise ValueError(f"--{name} must be vision or privileged, got '{src}'") from None
            if clean[name] is Source.VISION and names[name].vision is None:
                raise ValueError(f"the {name} slot has no vision implementation yet; use --{name} privileged")
        default = Source(self.default)
        object.__setattr__(self, "default", default)
        object.__setattr__(self, "sources", {t.name: clean.get(t.name, default if t.vision else Source.PRIVILEGED)
                                             for t in self.tasks})
        from percept.detection import LinearModel

        path = LinearModel.file_of(self.detector)
        if path is not None and not path.is_file():
            raise ValueError(f"--detector must be sim, inria or a model file, got '{self.detector}'")
        if path is not None:
            try:  # the whole model is read now, so that a bad file stops the command before any run
                LinearModel.load(path)
            except ValueError as e:
                raise ValueError(f"--detector: {e}") from None

    def source(self, task: str) -> Source:
        """Where ``task``'s estimate comes from."""
        return self.sources[task]

    @property
    def uses_detector(self) -> bool:
        """Whether a vision slot reads the people model (``detector``), so that it changes the results."""
        return any("detector" in t.slot_options and self.sources[t.name] is Source.VISION for t in self.tasks)

    @property
    def needs_cameras(self) -> bool:
        """Whether any slot reads the camera images (every vision slot does)."""
        return any(s is Source.VISION for s in self.sources.values())
