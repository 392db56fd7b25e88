"""The repository's shape, checked: small modules and functions, no import cycle between modules, perception
packages that import only what docs/design.md allows, and task names only in the slot table."""

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "percept"
PERCEPTION = ("lanes", "longitudinal", "detection", "odometry", "neighbours")
MAX_FUNCTION_LINES = 60
MAX_FILE_LINES = 300


def _sources(*roots: Path) -> list[Path]:
    return sorted(p for r in roots for p in r.rglob("*.py") if "__pycache__" not in p.parts)


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def test_no_file_over_300_lines_and_no_function_over_60():
    long_files, long_functions = [], []
    for path in _sources(PACKAGE, ROOT / "tests", ROOT / "tools"):
        text = path.read_text()
        if text.count("\n") > MAX_FILE_LINES:
            long_files.append(f"{path.relative_to(ROOT)}: {text.count(chr(10))} lines")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    long_functions.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}: {n} lines")
    assert long_files == [] and long_functions == []


def _imports(path: Path, modules: set[str]) -> set[str]:
    """The percept modules ``path`` imports, at its top or inside a function (a package's own ``__init__`` aside)."""
    me = _module_name(path)
    package = me if path.name == "__init__.py" else me.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1] + ([base] if base else []))
            names = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]
        else:
            continue
        for name in names:
            while name and name not in modules:
                name = name.rpartition(".")[0]
            if name and name != me and not me.startswith(name + "."):
                out.add(name)
    return out


def test_no_import_cycle_between_modules():
    paths = {_module_name(p): p for p in _sources(PACKAGE)}
    graph = {m: _imports(p, set(paths)) for m, p in paths.items()}
    # Tarjan's strongly connected components: a component of more than one module is a cycle
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    assert cycles == []


@pytest.mark.parametrize("package", PERCEPTION)
def test_perception_packages_import_neither_each_other_nor_the_simulator_nor_the_tools(package):
    forbidden = {f"percept.{p}" for p in PERCEPTION if p != package} | {
        "percept.sims", "percept.drive", "percept.evaluate", "percept.bench", "percept.training", "percept.review",
        "percept.cli", "rerun", "typer"}
    bad = []
    for path in _sources(PACKAGE / package):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
            bad += [f"{path.relative_to(ROOT)}: {n}" for n in names
                    if any(n == f or n.startswith(f + ".") for f in forbidden)]
    assert bad == []


def test_task_names_are_string_literals_only_in_the_slot_table():
    from percept.drive.tasks import TASKS

    names = "|".join(re.escape(t.name) for t in TASKS)
    literal = re.compile(rf"""["']({names})["']""")
    # the same words naming other things, as the table's docstring says: the footage commands `percept lanes`
    # and `percept odometry` (their names and their overlays' suffix) and the TuSimple format's "lanes" key
    allowed = {"percept/cli/lanes_cmd.py", "percept/cli/app.py", "percept/lanes/tusimple.py",
               "percept/lanes/realworld.py"}
    found = [f"{p.relative_to(ROOT)}:{i}" for p in _sources(PACKAGE)
             if str(p.relative_to(ROOT)) not in allowed | {"percept/drive/tasks.py"}
             for i, line in enumerate(p.read_text().splitlines(), 1) if literal.search(line)]
    assert found == []
