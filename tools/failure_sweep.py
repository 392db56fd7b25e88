"""The failure contract, swept over every command: bad files, absurd numbers, unwritable outputs, interrupts.

Each case runs ``percept`` in a subprocess inside a scratch folder that holds one finished result of every kind
(``existing.json``, ``existing.rrd``, a folder of two good images) and checks the contract (docs/design.md, "The
outputs promise"): the expected exit code (2 for bad input, 130 for Ctrl-C), one ``error:`` line and no traceback,
every file that was there unchanged, and no temporary or ``.part`` file left. Writes a Markdown table.

    python tools/failure_sweep.py --out docs/failure-contract.md
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from failure_cases import CASES, Case

EXE = [sys.executable, "-m", "percept"]
STOP_S = 2.5
"""Ctrl-C must end a command this soon [s] (the contract's 2 s, and the signal's delivery)."""


@dataclass
class Outcome:
    """What one case did, and whether it kept the contract."""

    case: Case
    code: int
    last_line: str
    seconds: float
    problems: list


def scratch(root: Path) -> Path:
    """A folder with one finished result of each kind, and good and bad inputs, for the cases to aim at."""
    root.mkdir(parents=True, exist_ok=True)
    good = np.full((96, 128, 3), 90, np.uint8)
    cv2.line(good, (10, 95), (60, 40), (255, 255, 255), 3)
    (root / "images").mkdir()
    for k in range(2):
        cv2.imwrite(str(root / "images" / f"{k}.png"), good)
    cv2.imwrite(str(root / "good.png"), good)
    (root / "mixed").mkdir()
    cv2.imwrite(str(root / "mixed" / "0.png"), good)
    (root / "mixed" / "1.png").write_bytes(b"")
    (root / "empty.png").write_bytes(b"")
    (root / "text.png").write_text("not an image\n")
    (root / "truncated.png").write_bytes((root / "good.png").read_bytes()[:200])
    (root / "garbage.npz").write_bytes(os.urandom(512))
    (root / "empty.npz").write_bytes(b"")
    np.savez(root / "keyless.npz", other=np.zeros(3))
    (root / "existing.json").write_text('{"kept": true}\n')
    (root / "existing.rrd").write_bytes(b"a finished recording")
    (root / "calib.txt").write_text("cam0=[100 0 64; 0 100 48; 0 0 1]\ncam1=[100 0 64; 0 100 48; 0 0 1]\n"
                                    "doffs=0\nbaseline=100\nwidth=128\nheight=96\nndisp=32\n")
    (root / "a_file").write_text("x")
    return root


def digest(root: Path) -> dict:
    """Every file under ``root`` -> the hash of its bytes."""
    return {p.relative_to(root): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def own_folder(folder: Path, host: str) -> None:
    """Make ``folder`` look written by a live process: this sweep on this host, or one on ``host``."""
    folder.mkdir(exist_ok=True)
    owner = {"pid": os.getpid(), "host": host or socket.gethostname(), "command": "percept eval",
             "started": "now"}
    (folder / ".percept-lock").write_text(json.dumps(owner))


def run_case(case: Case, root: Path) -> Outcome:
    """Run ``case`` in ``root``; interrupt it after ``case.interrupt_s`` when it names one."""
    if case.lock_host is not None:
        own_folder(root / case.args[case.args.index("--out") + 1], case.lock_host)
    before = digest(root)
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "COLUMNS": "100", "RERUN_ANALYTICS": "0"}
    t0 = time.perf_counter()
    p = subprocess.Popen(EXE + case.args, cwd=root, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         text=True, start_new_session=True)
    if case.interrupt_s is not None:
        time.sleep(case.interrupt_s)
        p.send_signal(signal.SIGINT)
    try:
        out, _ = p.communicate(timeout=case.timeout_s)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, _ = p.communicate()
        return Outcome(case, -9, "(killed: no answer in time)", time.perf_counter() - t0, ["hung"])
    seconds = time.perf_counter() - t0
    lines = [line for line in out.strip().splitlines() if line.strip()]
    problems = _problems(case, p.returncode, out, before, digest(root), root, seconds)
    return Outcome(case, p.returncode, lines[-1] if lines else "", seconds, problems)


def _problems(case: Case, code: int, out: str, before: dict, after: dict, root: Path, seconds: float) -> list:
    """How the case broke the contract (empty when it kept it)."""
    problems = []
    if code != case.expect:
        problems.append(f"exit {code}, expected {case.expect}")
    if "Traceback" in out:
        problems.append("traceback")
    if case.expect == 2 and sum("error:" in line for line in out.splitlines()) != 1:
        problems.append("not one error line")
    changed = [str(k) for k, h in before.items() if after.get(k) != h]
    if changed:
        problems.append(f"changed or removed: {', '.join(changed[:3])}")
    left = [str(p.relative_to(root)) for p in root.rglob("*")
            if ".tmp" in p.name or p.name.endswith(".part")]
    if left:
        problems.append(f"left behind: {', '.join(left[:3])}")
    if case.interrupt_s is not None and code == 130 and seconds - case.interrupt_s > STOP_S:
        problems.append(f"stopped {seconds - case.interrupt_s:.1f} s after Ctrl-C")
    return problems


def table(outcomes: list[Outcome]) -> str:
    """The sweep as Markdown: a summary line, then one row a case."""
    kept = sum(not o.problems for o in outcomes)
    rows = ["# The failure contract, swept", "",
            f"{len(outcomes)} cases over every command, each run by `python tools/failure_sweep.py`: **{kept} kept "
            f"the contract**, {len(outcomes) - kept} did not. A case keeps it when it exits with the expected code "
            "(2 for bad input, 130 for Ctrl-C), prints one `error:` line and no traceback, changes no file that "
            "was there and leaves no temporary behind.", "",
            "| # | kind | command | exit | what it said | kept |", "|---|---|---|---|---|---|"]
    for k, o in enumerate(outcomes, 1):
        said = o.last_line.replace("|", "\\|")[:140]
        cmd = " ".join(o.case.args).replace("|", "\\|")
        rows.append(f"| {k} | {o.case.kind} | `percept {cmd}` | {o.code} | {said} | "
                    f"{'yes' if not o.problems else 'NO: ' + '; '.join(o.problems)} |")
    return "\n".join(rows) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/failure-contract.md"))
    parser.add_argument("--only", default="", help="run only the cases whose kind contains this text")
    args = parser.parse_args()
    outcomes = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, case in enumerate(c for c in CASES if args.only in c.kind):
            root = scratch(Path(tmp) / f"case{k}")
            outcomes.append(run_case(case, root))
            o = outcomes[-1]
            print(f"{k + 1:3d} {'ok ' if not o.problems else 'BAD'} {o.code:4d} {' '.join(case.args)[:70]}"
                  f"  {'; '.join(o.problems)}", flush=True)
            shutil.rmtree(root, ignore_errors=True)
    args.out.write_text(table(outcomes))
    print(f"{sum(not o.problems for o in outcomes)} of {len(outcomes)} kept the contract; {args.out}")


if __name__ == "__main__":
    main()
