"""Evaluation reports a person reads: ``summary.csv`` (every metric per scenario x condition: runs, mean, p95 and
worst), ``summary.md`` (safety counts, the headline metrics, the runs that failed or were unsafe with the command
that reproduces each) and the list ``--strict`` acts on.

"Worst" is the maximum of a metric where lower is better (errors, counts, times) and the minimum where higher is
better (``higher_is_better``); p95 is the 95th percentile towards the worse side (the 5th where higher is better).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from percept.outputs import write_text_atomic

from .environment import environments
from .metrics import RUN_HEADLINES, UNSAFE, higher_is_better, run_metrics, safety_counts


def _stat_row(name: str, values: list[float], up: bool, total: bool) -> dict:
    """One metric's row of the long table; ``up``: higher is better; ``total``: a count, summed too."""
    a = np.asarray(values, dtype=float)
    return {"metric": name, "runs": len(a), "mean": float(a.mean()),
            "p95": float(np.percentile(a, 5 if up else 95)), "worst": float(a.min() if up else a.max()),
            "total": float(a.sum()) if total else None, "better": "higher" if up else "lower"}


def metric_rows(plan, results: list[dict], tasks) -> list[dict]:
    """Long table: one row per scenario x condition x metric some run has (runs, mean, p95, worst, total)."""
    rows, safety, up = [], {k for k, _ in safety_counts(tasks)}, higher_is_better(tasks)
    for sc in plan.scenarios:
        for c in plan.conditions:
            ok = [run_metrics(r, tasks) for r in results
                  if r.get("scenario") == sc and r.get("condition") == c and "error" not in r]
            names = sorted({k for m in ok for k in m}, key=lambda k: (k not in safety, k))
            for name in names:
                vals = [m[name] for m in ok if name in m]
                rows.append({"scenario": sc, "condition": c, **_stat_row(name, vals, name in up, name in safety)})
    return rows


def reproduce_command(run: dict, settings: dict) -> str:
    """The ``percept drive`` command that drives this run again with the batch's settings (``percept eval`` of that
    one run when another driver than percept's was in the ego's place)."""
    cmd = ["percept drive", f"--scenario {run['scenario']}", f"--seed {run['seed']}",
           f"--condition {run['condition']}"]
    # every slot is on vision unless told otherwise: --privileged when none is, else each privileged slot
    slots = settings.get("slots", {})
    if slots and all(src == "privileged" for src in slots.values()):
        cmd.append("--privileged")
    else:
        cmd += [f"--{task} privileged" for task, src in slots.items() if src == "privileged"]
    if settings.get("duration_s") is not None:
        cmd.append(f"--duration {settings['duration_s']:g}")
    if settings.get("detector") not in (None, "sim"):
        cmd.append(f"--detector {settings['detector']}")
    if settings.get("rear") is not None:
        cmd.append("--rear" if settings["rear"] else "--no-rear")
    if not settings.get("lane_changes", False):  # on by default; a batch that predates the option kept its lane
        cmd.append("--lane-changes off")
    if settings.get("ego", "percept") != "percept":  # another driver: only evaluation puts it in the ego's place
        cmd = [f"percept eval --ego {settings['ego']}", f"--scenario {run['scenario']}", f"--seeds {run['seed']}",
               f"--condition {run['condition']}"] + cmd[4:]
    return " ".join(cmd)


def _runs_with(results: list[dict], counts) -> list[tuple[dict, str]]:
    """Finished runs, in job order, with any of ``counts(run)`` (name -> value) non-zero: (run, what happened)."""
    out = []
    for r in sorted((r for r in results if "error" not in r), key=lambda r: (r["scenario"], r["condition"],
                                                                              r["seed"])):
        what = [f"{v} {k.replace('_', ' ')}" for k, v in counts(r).items() if v]
        if what:
            out.append((r, ", ".join(what)))
    return out


def unsafe_runs(results: list[dict]) -> list[tuple[dict, str]]:
    """Runs with a collision, a pedestrian collision or a lane departure: (run, what happened)."""
    return _runs_with(results, lambda r: {k: r.get(k) for k in UNSAFE})


def listed_runs(results: list[dict], tasks) -> list[tuple[dict, str]]:
    """Runs with any of the tasks' listed counts (``Count.listed``: a stop nothing called for, a hard braking for no
    one): (run, what happened). Not unsafe by ``--strict``'s rule, but worth a look."""
    return _runs_with(results, lambda r: {c.label: (r.get(t.name) or {}).get(c.key)
                                          for t in tasks for c in t.counts if c.listed})


CSV_FIELDS = ("scenario", "condition", "metric", "runs", "mean", "p95", "worst", "total", "better")
"""The columns of summary.csv."""
MD_TITLE = "# Evaluation: "
"""How summary.md begins (then the number of runs)."""
SUMMARY_STARTS = {"summary.json": b'{\n  "settings"', "summary.md": MD_TITLE.encode(),
                  "summary.csv": ",".join(CSV_FIELDS).encode()}
"""How each summary eval writes begins (summary.json: ``batch.evaluate`` writes its settings first): a file of that
name that begins otherwise is not eval's, and is not replaced."""


def written_by_eval(path: Path) -> bool:
    """Whether ``path`` (a summary.json, .md or .csv that exists) begins as eval writes it."""
    return path.read_bytes().startswith(SUMMARY_STARTS[path.name])


def summary_csv(rows: list[dict]) -> str:
    """The long table (``metric_rows``) as CSV, numbers to 6 significant digits."""
    buf = io.StringIO()
    fields = list(CSV_FIELDS)
    w = csv.DictWriter(buf, fieldnames=fields, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if r[k] is None else f"{r[k]:.6g}" if isinstance(r[k], float) else r[k]) for k in fields})
    return buf.getvalue()


def _fmt(v, spec: str = "{:.3g}") -> str:
    return "—" if v is None else spec.format(v)


def _environment_lines(results: list[dict]) -> list[str]:
    """Where the runs were driven (``environment.environments``): the same code gives other numbers, slightly, with
    other numeric libraries or CPU code paths."""
    lines = []
    for env in environments(results):
        if "numpy" in env:
            lines.append(f"Driven on {env['cpu']} ({env['machine']}): Python {env['python']}, numpy {env['numpy']}, "
                         f"OpenCV {env['opencv']}, numba {env['numba']}, BLAS {env['blas']}; OpenCV's CPU features "
                         f"{env['opencv_cpu']}: {env['runs']} runs.")
        else:
            lines.append(f"Environment not recorded: {env['runs']} runs (made by an older percept).")
    return lines + [""] if lines else []


def summary_md(plan, results: list[dict], rows: list[dict], settings: dict, tasks, plots: list[str]) -> str:
    """The evaluation as Markdown: settings, safety, headline metrics (``rows`` from ``metric_rows``), failures
    with reproduction commands."""
    rows = {(r["scenario"], r["condition"], r["metric"]): r for r in rows}
    ok, safety = [r for r in results if "error" not in r], safety_counts(tasks)
    slots = ", ".join(f"{k} {v}" for k, v in settings.get("slots", {}).items())
    lines = [f"{MD_TITLE}{len(ok)} runs", "",
             f"Scenarios {', '.join(plan.scenarios)}; conditions {', '.join(plan.conditions)}; seeds "
             f"{_seed_text(plan.seeds)}; slots: {slots}; percept {settings.get('percept')}.", "",
             *_environment_lines(results),
             "## Safety (totals over the seeds)", "",
             "| scenario | condition | runs | failed | " + " | ".join(label for _, label in safety) + " |",
             "|---|---|---|---|" + "---|" * len(safety)]
    for sc in plan.scenarios:
        for c in plan.conditions:
            n = sum(1 for r in ok if r["scenario"] == sc and r["condition"] == c)
            failed = sum(1 for r in results if "error" in r and r.get("scenario") == sc and r.get("condition") == c)
            cells = [_fmt((rows.get((sc, c, k)) or {}).get("total"), "{:.0f}") for k, _ in safety]
            lines.append(f"| {sc} | {c} | {n} | {failed} | " + " | ".join(cells) + " |")
    lines += ["", "## Headline metrics (mean / p95 / worst over the seeds)", ""]
    heads = [(k, label) for k, label, _ in RUN_HEADLINES] + [(f"{t.name}.{h.key}", f"{t.name}: {h.label}")
                                                            for t in tasks for h in t.headline]
    heads = [(k, label) for k, label in heads if any(key[2] == k for key in rows)]
    if heads:
        lines += ["| scenario | condition | " + " | ".join(label for _, label in heads) + " |",
                  "|---|---|" + "---|" * len(heads)]
        for sc in plan.scenarios:
            for c in plan.conditions:
                cells = [" / ".join(_fmt(rows[(sc, c, k)][s]) for s in ("mean", "p95", "worst"))
                         if (sc, c, k) in rows else "—" for k, _ in heads]
                lines.append(f"| {sc} | {c} | " + " | ".join(cells) + " |")
    lines += ["", "Every metric, with p95 and worst: `summary.csv`.", ""]
    lines += _problems_md(results, settings, tasks)
    if plots:
        lines += ["## Plots", ""] + [f"![{Path(p).stem}]({p})" for p in plots] + [""]
    return "\n".join(lines)


def _problems_md(results: list[dict], settings: dict, tasks) -> list[str]:
    """The "Runs to look at" section: unsafe, listed and failed runs, each with its reproduce command."""
    bad = unsafe_runs(results) + listed_runs(results, tasks)
    errors = [r for r in results if "error" in r]
    if not bad and not errors:
        looked = [k.replace("_", " ") for k in UNSAFE] + [c.label for t in tasks for c in t.counts if c.listed]
        return [f"No run had any {', '.join(looked)}, and none failed.", ""]
    lines = ["## Runs to look at", ""]
    lines += [f"- {r['scenario']} / {r['condition']} / seed {r['seed']}: {what} — `{reproduce_command(r, settings)}`"
              for r, what in bad]
    lines += [f"- {r['scenario']} / {r['condition']} / seed {r['seed']}: failed ({r['error']}) — "
              f"`{reproduce_command(r, settings)}`" for r in errors]
    return lines + [""]


def _seed_text(seeds) -> str:
    """Seeds as the report prints them: "0–19" for a run of consecutive seeds, else listed."""
    s = sorted(seeds)
    return f"{s[0]}–{s[-1]}" if s == list(range(s[0], s[-1] + 1)) and len(s) > 1 else ", ".join(map(str, s))


def write_reports(plan, results: list[dict], settings: dict, out_dir: Path, tasks) -> list[Path]:
    """summary.csv, plots/*.png and summary.md in ``out_dir`` (each written atomically); the paths written."""
    from .plots import write_plots

    out_dir = Path(out_dir)
    plots = write_plots(plan, results, out_dir / "plots", tasks)
    rows = metric_rows(plan, results, tasks)
    write_text_atomic(out_dir / "summary.csv", summary_csv(rows))
    rel = [str(p.relative_to(out_dir)) for p in plots]
    write_text_atomic(out_dir / "summary.md", summary_md(plan, results, rows, settings, tasks, rel))
    return [out_dir / "summary.csv", out_dir / "summary.md", *plots]
