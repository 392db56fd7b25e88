"""`percept train-detector`: train the sim people model on rendered pedestrians (HOG + linear SVM)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from . import options as opt
from .common import check_outputs, console, fail, on_interrupt, progress_bar, write_error, write_json

SECOND_THRESHOLD = -0.5
"""The second stage's score a detection needs on one of its windows, unless --second-threshold says otherwise."""


def train_detector(
    out: Annotated[Path, typer.Option("--out", dir_okay=False, help="Model file to write (.npz); its training "
                                      "record goes beside it as the same name with .json.")] = Path("people_sim.npz"),
    seeds: Annotated[str, typer.Option("--seeds", help="Training seeds of the crossing scenario (A-B, N or "
                                       "A,B,C); none may be an evaluation seed (0-19, 100-119).")] = "1000-1009",
    every: Annotated[int, typer.Option("--every", help="Sample every N-th frame, 1 to 100.")] = 3,
    duration: opt.Duration = None,
    c: Annotated[float, typer.Option("--c", help="The linear SVM's C (regularisation), 1e-5 to 10.")] = 0.01,
    condition: Annotated[list[str] | None, typer.Option(
        "--condition", help="Conditions rotated over the seeds, in order (repeat the option; a condition may "
        "repeat to weight it). Default: clear, night, rain.")] = None,
    negatives_from: Annotated[list[str] | None, typer.Option(
        "--negatives-from", help="Scenarios whose frames give hard negatives too, such as the traffic scenarios, "
        "whose vehicles' corners the first model takes for people (repeat the option). Default: none.")] = None,
    negative_seeds: Annotated[str, typer.Option("--negative-seeds", help="Seeds of the --negatives-from scenarios "
                                                "(A-B, N or A,B,C); none may be an evaluation seed.")] = "1000-1004",
    first_stage: Annotated[str | None, typer.Option(
        "--first-stage", help="Write a two-stage cascade: this model (sim, inria or a .npz file; of a cascade, its "
        "first stage) finds the people and the model trained here confirms them. Default: none (one model).")] = None,
    second_threshold: Annotated[float | None, typer.Option(
        "--second-threshold", help=f"With --first-stage: the second stage's score a detection needs on one of its "
        f"windows, -5 to 5 (default {SECOND_THRESHOLD:g}).", show_default=False)] = None,
):
    """Render pedestrians and backgrounds, cut 64x128 windows (as the constrained search sees them, 4-pixel cells),
    train a linear SVM with OpenCV's cv2.ml, mine hard negatives with it (on the same frames, and on those of the
    `--negatives-from` scenarios) and train again.

    The conditions rotate over the seeds (by default clear, night, rain). The model is selected with `--model FILE` in
    `percept detect` and `--detector FILE` in `percept drive` and `percept eval`. With `--first-stage MODEL` the model
    trained here becomes the second stage of a cascade: MODEL finds the people, this one confirms them. The model
    shipped in the package (`sim`) is such a cascade: its first stage is this command's defaults, its second
    `--negatives-from highway --negatives-from curves --negatives-from cut-in --negatives-from loop --first-stage sim`.
    """
    from percept.detection import LinearModel
    from percept.training.people import frames_to_sample, train_people_model

    opt.check_number("--every", every, 1, 100)
    opt.check_number("--c", c, 1e-5, 10.0)
    first, second_threshold, first_record = _first_stage(first_stage, second_threshold)
    try:
        plan = _plan(seeds, every, duration, c, condition, negatives_from, negative_seeds)
    except ValueError as e:
        fail(str(e))
    record_path = out.with_suffix(".json")
    check_outputs([out, record_path], [None if first_stage is None else LinearModel.file_of(first_stage)])
    on_interrupt("nothing: the model is written only when training ends")
    with progress_bar() as bar:
        task = bar.add_task("rendering and training", total=frames_to_sample(plan))
        try:
            model, record = train_people_model(plan, tick=lambda: bar.advance(task))
        except ValueError as e:
            fail(str(e))
    _save(model, record, plan, out, record_path, seeds, negative_seeds, first, first_stage, second_threshold,
          first_record)


def _first_stage(name: str | None, threshold: float | None) -> tuple:
    """The cascade's first stage as (its model without a second stage, the second stage's threshold, its training
    record), or (None, SECOND_THRESHOLD, None) without one; a one-line exit 2 on a bad option."""
    from percept.detection import LinearModel

    if name is None:
        if threshold is not None:
            fail("--second-threshold is the second stage's: give it with --first-stage")
        return None, SECOND_THRESHOLD, None
    threshold = SECOND_THRESHOLD if threshold is None else threshold
    opt.check_number("--second-threshold", threshold, -5.0, 5.0)
    try:
        first = replace(LinearModel.named(name), second=None)
    except ValueError as e:
        fail(f"--first-stage: {e}")
    # the first stage's record is read with its model, not after the training
    return first, threshold, _first_stage_record(name)


def _plan(seeds: str, every: int, duration, c: float, condition, negatives_from, negative_seeds: str):
    """The TrainPlan the options describe; ValueError naming the bad one."""
    from percept.evaluate.plan import parse_seeds
    from percept.training.people import TrainPlan

    conditions = {"conditions": tuple(condition)} if condition else {}
    if negatives_from:
        conditions["negative_scenarios"] = tuple(negatives_from)
    return TrainPlan(seeds=tuple(parse_seeds(seeds)), every=every, duration_s=duration, c=c,
                     negative_seeds=tuple(parse_seeds(negative_seeds, "--negative-seeds")), **conditions)


def _save(model, record: dict, plan, out: Path, record_path: Path, seeds: str, negative_seeds: str, first,
          first_stage: str | None, second_threshold: float, first_record: dict | None) -> None:
    """Write the model (as a cascade's second stage behind ``first`` when given, ``first_record`` the first stage's
    training record) and its training record; say what was trained."""
    traffic = (f"; hard negatives also from {', '.join(plan.negative_scenarios)} seeds {negative_seeds}"
               if plan.negative_scenarios else "")
    meta = {"trained_on": f"{plan.scenario} seeds {seeds}, conditions {', '.join(plan.conditions)}, every "
                          f"{plan.every} frames{traffic}"}
    if first is not None:
        meta["cascade"] = f"second stage of {first_stage} (its first stage), at a score of {second_threshold:g}"
        model = replace(first, second=model, second_threshold=second_threshold)
        record["first_stage_record"] = first_record
    try:
        model.save(out, **meta)
    except OSError as e:
        fail(write_error(out, e))
    write_json(record_path, {**record, **meta, "model": str(out)})
    others = f" ({record['hard_negatives_traffic']} from {', '.join(plan.negative_scenarios)})" if traffic else ""
    console.print(f"{record['positives']} positives, {record['random_negatives']} random and "
                  f"{record['hard_negatives']} hard negatives{others}; on its training windows: recall "
                  f"{record['train_recall']:.3f}, false positives {record['train_false_positive_rate']:.4f}")
    console.print(f"wrote {out} and {record_path}")


def _first_stage_record(name: str) -> dict | None:
    """The training record of a cascade's first stage: the record beside its model file (of a cascade, that
    record's own first stage's); None for OpenCV's model or a file without one."""
    import json

    from percept.detection import LinearModel

    model = LinearModel.file_of(name)
    path = None if model is None else model.with_suffix(".json")
    try:
        record = json.loads(path.read_text()) if path is not None else None
    except (OSError, ValueError):
        return None
    return record.get("first_stage_record", record) if isinstance(record, dict) else None
