"""The slot table: a task added through the table alone runs, is timed, scored, recorded, benchmarked and offered
on the CLI; the agent feeds each law by record type; behaviour pinned."""

import json
import subprocess
from dataclasses import dataclass

import numpy as np
import pytest
import rerun as rr

from percept.cli.view_cmd import rerun_executable
from percept.drive import TASKS, DriveConfig, Headline, Source, Task, run_drive, task_order
from percept.review import RunRecorder
from percept.sensors import EgoPath, PoseEstimate
from percept.sims import WorldConfig


@dataclass(frozen=True)
class FrameCount:
    """The fifth task's record: how many frames its slot has seen."""

    frames: int


class CountingSlot:
    """A fifth slot: counts frames and checks that it reads the ego path, by its record type."""

    def __init__(self, ctx):
        self.frames = 0

    def reset(self) -> None:
        self.frames = 0

    def step(self, frame, upstream):
        assert isinstance(upstream[EgoPath], EgoPath)
        self.frames += 1
        return FrameCount(self.frames), {"left_mean": float(frame.left.mean())}


class CountingScorer:
    def __init__(self, ctx):
        self.ctx, self.seen = ctx, 0

    def update(self, estimate, debug, step):
        self.seen = estimate.frames

    def result(self):
        return {"frames_seen": self.seen, "scored_as_vision": self.ctx.vision}


def log_counter(rec, ctx, estimate, debug, truth):
    rec.log("counter/frames/estimate", rr.Scalars(estimate.frames))


FAKE = Task("counter", FrameCount, CountingSlot, CountingScorer, vision=CountingSlot, recorder=log_counter,
            reads=(EgoPath,), headline=(Headline("frames seen", "frames_seen", "{}"),), help="counts frames")


def test_a_fifth_task_added_through_the_table_alone_runs_is_timed_scored_and_recorded(tmp_path):
    tasks = TASKS + (FAKE,)
    cfg = DriveConfig(WorldConfig("highway", 0, scenery=False), 1.0, {"counter": "vision"}, tasks=tasks,
                      default="privileged")
    rrd = tmp_path / "five.rrd"

    def recorder(world):
        lines = [s.left for s in world.road_geometry.strips]
        return RunRecorder(rrd, world.cfg.rig, lines, tasks)

    holder = {}
    r = run_drive(cfg, recorder_factory=lambda w: holder.setdefault("r", recorder(w)))
    holder["r"].close()
    assert r["counter"] == {"frames_seen": 15, "scored_as_vision": True}
    assert r["slots"]["counter"] == "vision" and r["timing_ms"]["counter"] > 0
    assert r["timing_ms"]["perception_total"] == r["timing_ms"]["counter"]
    p = subprocess.run([rerun_executable(), "rrd", "print", str(rrd)], capture_output=True, text=True,
                       env={"RERUN_ANALYTICS": "0", "PATH": ""})
    assert p.returncode == 0 and "counter/frames/estimate" in p.stdout


@pytest.mark.slow
def test_a_fifth_task_added_to_the_table_is_offered_on_the_cli_and_benchmarked(tmp_path, monkeypatch):
    import typer
    from typer.testing import CliRunner

    from percept.bench.stages import bench_task
    from percept.cli import drive_cmd, eval_cmd, options
    from percept.drive import tasks as table

    monkeypatch.setattr(table, "TASKS", TASKS + (FAKE,))
    app = typer.Typer()
    app.command("drive")(options.with_task_options(drive_cmd.drive))
    app.command("eval")(options.with_task_options(eval_cmd.eval_))
    runner = CliRunner()
    assert "--counter" in runner.invoke(app, ["drive", "--help"], env={"COLUMNS": "200"}).output
    out = tmp_path / "run.json"
    r = runner.invoke(app, ["drive", "--privileged", "--counter", "vision", "--duration", "0.5", "--no-record",
                            "--json", str(out)])
    assert r.exit_code == 0, r.output
    assert "frames seen" in r.output  # its headline in the drive's table
    run = json.loads(out.read_text())
    assert run["counter"]["frames_seen"] == 8 and run["slots"]["counter"] == "vision"
    r = runner.invoke(app, ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "0.5", "--privileged",
                            "--counter", "vision", "--out", str(tmp_path / "ev")])
    assert r.exit_code == 0, r.output
    summary = json.loads((tmp_path / "ev" / "summary.json").read_text())
    assert summary["groups"][0]["counter"]["frames_seen"]["mean"] == 8
    assert "counter.frames_seen" in (tmp_path / "ev" / "summary.csv").read_text()
    stage = bench_task(FAKE, table.TASKS, frames=2)
    assert stage.stage == "counter" and stage.ms > 0 and stage.peer is None


def test_the_table_runs_readers_after_providers_and_rejects_cycles_and_unknown_records():
    order = [t.name for t in task_order(TASKS + (FAKE,))]
    assert order.index("lanes") < order.index("counter")
    assert order.index("lanes") < order.index("longitudinal") < order.index("odometry")

    @dataclass(frozen=True)
    class A:
        pass

    @dataclass(frozen=True)
    class B:
        pass

    loop = Task("a", A, CountingSlot, CountingScorer, reads=(B,))
    with pytest.raises(ValueError, match="task a reads B, which no task provides"):
        task_order((loop,))
    with pytest.raises(ValueError, match="cycle"):
        task_order((loop, Task("b", B, CountingSlot, CountingScorer, reads=(A,))))
    with pytest.raises(ValueError, match="both provide A"):
        task_order((loop, Task("c", A, CountingSlot, CountingScorer)))


def test_the_agent_needs_a_task_for_the_ego_path_and_the_pose():
    from percept.drive import Agent, SlotContext, TruthFeed
    from percept.sensors import StereoRig

    no_pose = tuple(t for t in TASKS if t.provides is not PoseEstimate)
    with pytest.raises(ValueError, match="no task provides PoseEstimate"):
        Agent(no_pose, {t.name: Source.PRIVILEGED for t in no_pose}, SlotContext(StereoRig(), 1 / 15, None,
                                                                                  TruthFeed()), 20.0)


def test_drive_config_names_the_bad_task_or_source():
    with pytest.raises(ValueError, match="unknown task 'steering'"):
        DriveConfig(sources={"steering": "vision"})
    with pytest.raises(ValueError, match="--odometry must be vision or privileged"):
        DriveConfig(sources={"odometry": "magic"})
    assert DriveConfig(sources={"lanes": "vision"}).source("lanes") is Source.VISION
    unbuilt = Task("counter", FrameCount, CountingSlot, CountingScorer)
    with pytest.raises(ValueError, match="the counter slot has no vision implementation yet; use --counter privileged"):
        DriveConfig(sources={"counter": "vision"}, tasks=TASKS + (unbuilt,))


@pytest.mark.parametrize("scenario, seed, group, key, value", [
    # the privileged closed loop's metrics with the car keeping its lane, pinned: any change of behaviour must be
    # deliberate
    ("lead-brake", 0, "longitudinal", "time_gap_min_s", 1.5985146569594249),
    ("lead-brake", 0, "longitudinal", "time_gap_steady_s", 1.8062480963572944),
    ("cut-in", 1, "longitudinal", "time_gap_min_s", 0.5011582284823995),
    ("cut-in", 1, "longitudinal", "time_gap_steady_s", 1.7979860088948512),
    pytest.param("curves", 0, "lanes", "centering_rms_m", 0.04248752073421511, marks=pytest.mark.slow),
    ("crossing", 2, "pedestrians", "stops", [True, True, True]),
])
def test_privileged_metrics_are_pinned(scenario, seed, group, key, value):
    r = run_drive(DriveConfig(WorldConfig(scenario, seed), default="privileged", lane_changes=False), render=False)
    # to a millionth: numpy picks its SIMD kernels by the CPU, so sums round differently on another machine (in the
    # 16th digit); a change of behaviour moves these figures by far more
    assert r[group][key] == (pytest.approx(value, rel=1e-6, abs=0) if isinstance(value, float) else value)
    assert r["collisions"] == 0 and r["lane_departures"] == 0


def test_the_bench_times_a_slot_from_reset_as_the_median_of_its_passes_each_on_fresh_frames():
    from percept.bench.stages import SLOT_PASSES, slot_ms
    from percept.sensors import Frame, ImuSample

    class Slot:
        def __init__(self):
            self.resets, self.steps, self.since_reset, self.grey_ready = 0, 0, [], []

        def reset(self):
            self.resets += 1
            self.since_reset.append(0)

        def step(self, frame, upstream):
            self.steps += 1
            self.since_reset[-1] += 1
            # what a frame converts once for every slot must be converted again in every pass, as in the loop
            self.grey_ready.append("left_gray" in vars(frame))
            assert frame.left_gray.shape == (4, 6)

    image = np.zeros((4, 6, 3), np.uint8)
    shot = (Frame(0, 0.0, image, image, ImuSample(np.zeros(3), np.zeros(3)), 0.0), {})
    slot, ticks = Slot(), []
    ms = slot_ms(slot, [shot] * 4, progress=lambda: ticks.append(1))
    assert ms > 0
    # a warm-up pass, then the timed ones, each from a reset over every shot
    assert slot.resets == SLOT_PASSES + 1 and slot.since_reset == [4] * (SLOT_PASSES + 1)
    assert len(ticks) == slot.steps == 4 * (SLOT_PASSES + 1)
    assert not any(slot.grey_ready) and "left_gray" not in vars(shot[0])
