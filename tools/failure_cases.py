"""The cases ``failure_sweep.py`` runs: every command with bad files, absurd numbers, unwritable outputs and Ctrl-C.

Paths are relative to the sweep's scratch folder (``failure_sweep.scratch``): ``good.png``, ``empty.png``,
``text.png``, ``truncated.png``, ``images/`` (two good images), ``mixed/`` (a good and an empty image),
``garbage.npz``, ``empty.npz``, ``keyless.npz``, ``calib.txt``, ``a_file``, ``existing.json``, ``existing.rrd``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
KITTI = str(DATA / "kitti-odometry-seq")
VIDEO = str(next((DATA / "udacity-lanelines-p1" / "test_videos").glob("*.mp4"), DATA / "missing.mp4"))


@dataclass(frozen=True)
class Case:
    """One command line and what the contract expects of it."""

    kind: str  # what is wrong: "file", "number", "output", "interrupt"
    args: list  # the arguments after `percept`
    expect: int = 2  # the exit code the contract asks for
    interrupt_s: float | None = None  # send Ctrl-C this long after the start [s]
    timeout_s: float = 90.0  # a case still running this long is a hang [s]
    lock_host: str | None = None  # before the run, a writer on this host ("" = this one) owns the folder --out names


BAD_IMAGES = ("empty.png", "text.png", "truncated.png", "missing.png", "mixed")
BAD_MODELS = ("garbage.npz", "empty.npz", "keyless.npz", "missing.npz", "text.png")
QUICK_DRIVE = ["drive", "--duration", "0.5", "--no-record"]
QUICK_EVAL = ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "0.5", "--out", "ev"]


def file_cases() -> list[Case]:
    """Corrupt, empty, truncated, wrong-format and missing files, and folders where files belong."""
    c = [Case("file", ["stereo", bad, "good.png", "--calib", "calib.txt"]) for bad in BAD_IMAGES[:4]]
    c += [Case("file", ["stereo", "good.png", "good.png", "--calib", bad]) for bad in ("empty.png", "text.png",
                                                                                      "missing.txt", "images")]
    c.append(Case("file", ["stereo", "good.png", "good.png", "--calib", "calib.txt", "--gt", "garbage.npz"]))
    c += [Case("file", ["lanes", bad]) for bad in BAD_IMAGES[:4]]
    # a folder with one unreadable image: the others are fitted, the bad one named on a warning line (exit 0)
    c.append(Case("file", ["lanes", "mixed"], expect=0))
    c += [Case("file", ["lanes", "good.png", "--calib", bad]) for bad in ("empty.png", "text.png", "missing.json")]
    c += [Case("file", ["detect", bad]) for bad in BAD_IMAGES]
    c += [Case("file", ["detect", "good.png", "--model", bad]) for bad in BAD_MODELS]
    c += [Case("file", ["calibrate", bad, "--pattern", "9x6"]) for bad in ("images", "missing", "a_file", "mixed")]
    c += [Case("file", ["calibrate", "images", "--pattern", "9x6", "--stereo"])]
    c += [Case("file", ["odometry", bad]) for bad in ("missing", "a_file", "images", "mixed")]
    c += [Case("file", ["view", bad]) for bad in ("existing.rrd", "empty.png", "missing.rrd", "images")]
    c += [Case("file", QUICK_DRIVE + ["--detector", bad]) for bad in BAD_MODELS]
    c += [Case("file", QUICK_EVAL + ["--detector", bad]) for bad in BAD_MODELS]
    c += [Case("file", ["train-detector", "--out", "m.npz", "--first-stage", bad]) for bad in BAD_MODELS]
    return c


def _numbers(prefix: list, option: str, values) -> list[Case]:
    return [Case("number", prefix + [option, str(v)]) for v in values]


def number_cases() -> list[Case]:
    """Absurd numbers and names for every option that takes one."""
    c = _numbers(QUICK_DRIVE, "--seed", (-1, 2**31, "nan", "abc"))
    c += _numbers(QUICK_DRIVE[:1], "--duration", (0, -1, "nan", "inf", 1e12))
    for option, values in (("--camera-hz", (0, -1, "nan", 1e9)), ("--camera-quality", (0, 101)),
                           ("--camera-scale", (0, 2, "nan"))):
        c += _numbers(["drive", "--duration", "0.5", "--record", "r.rrd"], option, values)
    c += _numbers(QUICK_DRIVE, "--scenario", ("moon", ""))
    c += _numbers(QUICK_DRIVE, "--condition", ("fog",))
    c += _numbers(QUICK_DRIVE, "--lanes", ("magic",))
    for option, values in (("--seeds", ("5-1", "a", "-3", "0-99999999999", "")), ("--workers", (0, -1, 100000)),
                           ("--duration", (0, "nan")), ("--engine", ("spark",)), ("--scenario", ("moon",)),
                           ("--condition", ("fog",))):
        c += _numbers(QUICK_EVAL, option, values)
    for option, values in (("--frames", (0, -1, "x")), ("--seed", (-1,)), ("--scenario", ("moon",)),
                           ("--condition", ("fog",))):
        c += _numbers(["render", "--frames", "1", "--out", "r"], option, values)
    for option, values in (("--frames", (0, -1, 100000)), ("--seconds", (0, 1e9)), ("--repeats", (0, 100)),
                           ("--soak-minutes", (-1, 1e9))):
        c += _numbers(["bench"], option, values)
    c += _numbers(["bench", "--stack"], "--scenario", ("moon",))
    stereo = ["stereo", "good.png", "good.png", "--calib", "calib.txt"]
    for option, values in (("--scale", (0, -1, 100)), ("--num-disparities", (0, 17, 4096, -16)),
                           ("--block-size", (0, 2, 99))):
        c += _numbers(stereo, option, values)
    for option, values in (("--mount-height", (-1, 0, 1e9)), ("--lane-width", (0, 100)), ("--hfov", (0, 180, "nan")),
                           ("--speed", (-1, 1e9)), ("--max-frames", (0,))):
        c += _numbers(["lanes", "good.png"], option, values)
    for option, values in (("--scale-step", (1, 0, 3)), ("--threshold", ("nan",)), ("--max-frames", (0,))):
        c += _numbers(["detect", "good.png"], option, values)
    c += _numbers(["odometry", KITTI], "--camera-height", (0, -1, "nan"))
    c += _numbers(["calibrate", "images", "--pattern", "9x6"], "--square", (0, -1, 1e9))
    c += _numbers(["calibrate", "images"], "--pattern", ("0x0", "abc", "1x1", "9x"))
    for option, values in (("--every", (0, 1000)), ("--c", (0, 100)), ("--seeds", ("0-5", "x")),
                           ("--second-threshold", (99,))):
        c += _numbers(["train-detector", "--out", "m.npz"], option, values)
    return c


def output_cases() -> list[Case]:
    """Outputs that cannot be written: under a file, a folder where a file goes, a file where a folder goes, /proc;
    and a refused run whose outputs already exist (they must stay as they were)."""
    c = [Case("output", QUICK_DRIVE + ["--json", j]) for j in ("a_file/x.json", "images", "/proc/x.json")]
    c += [Case("output", ["drive", "--duration", "0.5", "--record", r]) for r in ("a_file/x.rrd", "images")]
    c += [Case("output", ["eval", "--scenario", "highway", "--seeds", "0", "--duration", "0.5", "--out", o])
          for o in ("a_file", "/proc/x")]
    c += [Case("output", ["render", "--frames", "1", "--out", o]) for o in ("a_file", "/proc/x")]
    stereo = ["stereo", "good.png", "good.png", "--calib", "calib.txt"]
    c += [Case("output", stereo + ["--out", "a_file"]), Case("output", stereo + ["--json", "images"])]
    c += [Case("output", ["lanes", "good.png", "--out", "a_file"]),
          Case("output", ["lanes", "good.png", "--json", "images"]),
          Case("output", ["detect", "good.png", "--out", "a_file"]),
          Case("output", ["odometry", KITTI, "--poses-out", "images"]),
          Case("output", ["odometry", KITTI, "--json", "a_file/x.json"]),
          Case("output", ["calibrate", "images", "--pattern", "9x6", "--out", "images"]),
          Case("output", ["bench", "--frames", "1", "--json", "images"]),
          Case("output", ["scenarios", "--json", "a_file/x.json"]),
          Case("output", ["drive", "--seed", "-1", "--json", "existing.json", "--record", "existing.rrd"]),
          Case("output", ["train-detector", "--out", "a_file/m.npz"])]
    return c


def interrupt_cases() -> list[Case]:
    """Ctrl-C a few seconds into each long command: exit 130 within 2 s, nothing half-written left."""
    return [Case("interrupt", args, 130, interrupt_s=s) for args, s in (
        (["drive", "--duration", "60", "--record", "r.rrd", "--json", "r.json"], 6.0),
        (["eval", "--scenario", "highway", "--seeds", "0-3", "--duration", "20", "--workers", "2", "--out", "ev"],
         8.0),
        (["render", "--frames", "300", "--out", "r"], 6.0),
        (["bench", "--frames", "30"], 6.0),
        (["lanes", VIDEO, "--out", "o", "--json", "l.json"], 4.0),
        (["train-detector", "--out", "m.npz", "--seeds", "1000-1001"], 6.0))]


def concurrent_cases() -> list[Case]:
    """A second writer into a folder another process is writing (a live owner here, or one on another host)."""
    out = ["--scenario", "highway", "--seeds", "0", "--duration", "0.5", "--out", "ev"]
    return [Case("concurrent", ["eval", *out], lock_host=""), Case("concurrent", ["eval", *out], lock_host="far"),
            Case("concurrent", ["eval", *out, "--privileged"], lock_host="")]


CASES = file_cases() + number_cases() + output_cases() + interrupt_cases() + concurrent_cases()
