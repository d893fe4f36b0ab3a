"""The package's shape (issue 18): no import cycles and no private name imported across
modules, so that a rule has one home and every engine reaches it through its public name."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "linkage"


def _modules() -> dict[str, Path]:
    out = {}
    for p in SRC.rglob("*.py"):
        parts = p.relative_to(SRC.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = p
    return out


def _imports() -> tuple[dict[str, set[str]], list[tuple[str, str, str]]]:
    """Module -> the package modules it imports (anywhere in it: functions and typing-only
    imports count too, as the layout reads them), and
    every (importer, module, name) whose name is private."""
    mods = _modules()
    edges: dict[str, set[str]] = {}
    private = []
    for name, path in mods.items():
        tree = ast.parse(path.read_text())
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(tree):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("linkage"):
                continue
            for alias in node.names:
                full = f"{target}.{alias.name}"
                module = full if full in mods else target
                if module != name:
                    edges.setdefault(name, set()).add(module)
                is_dunder = alias.name.startswith("__") and alias.name.endswith("__")
                if alias.name.startswith("_") and not is_dunder and module != name:
                    private.append((name, target, alias.name))
    return edges, private


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Every strongly connected component of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
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
                out.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles():
    """Cycles were batch <-> sweep and closed_form <-> loops (issue 18)."""
    edges, _ = _imports()
    assert _cycles(edges) == []


def test_the_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_no_private_name_is_imported_across_modules():
    """batch imported _Solver, _continue, _solve_position and _classify_gap from sweep;
    solve imported _newton_2x2 (issue 18). A name another module needs is public."""
    _, private = _imports()
    assert private == []


def test_the_sweep_is_split_by_what_it_does():
    """The public sweep API, the continuation, limits, angles and the engines each have a
    module of their own (issue 18: kinematics/sweep.py was 908 lines of all of them)."""
    for name in ("sweep", "positions", "continuation", "limits", "angles", "stepwise", "batch", "designs",
                 "rates"):
        assert (SRC / "kinematics" / f"{name}.py").is_file(), name
    assert len((SRC / "kinematics" / "sweep.py").read_text().splitlines()) < 200


# --- issue 33: layers, sizes, private attributes ------------------------------------------

LAYERS: tuple[frozenset[str], ...] = (
    frozenset({"errors", "numbers", "units", "result", "files", "samples", "arguments", "rules", "linalg",
               "records", "version"}),
    frozenset({"problems", "codegen"}),
    frozenset({"methods", "iterate", "analysis", "kernel"}),
    frozenset({"solve", "homotopy"}),
    frozenset({"kinematics"}),
    frozenset({"scan", "synthesis"}),
    frozenset({"render"}),
    frozenset({"measure", "bench", "stress", "mgh_table", "cli"}),
    frozenset({"linkage", "__main__"}),
)
"""Lowest first. A module imports from its own layer or lower ones (the layout of
../STYLE.md as README "Documentation" links it: base, problems, methods, solve,
kinematics, scan and synthesis, render, cli)."""

MAX_MODULE_LINES = 600
MAX_FUNCTION_BODY_LINES = 80
DATA_TABLES = {
    "linkage.problems.classic._aps_cases": "the APS test problems, one literal table of cases",
}
"""Exempt by name: a function that is one literal table of data, not logic."""

PENDING: set[str] = set()
"""What issue 33's split had not yet reached while it landed (46 entries at first), now
none: a new entry needs a reason; the test fails when an entry is fixed and still listed."""


def layer_of(module: str) -> int:
    parts = module.split(".")
    head = parts[1] if len(parts) > 1 else parts[0]
    for i, names in enumerate(LAYERS):
        if head in names:
            return i
    raise AssertionError(f"{module} has no layer: add its package to LAYERS")


def _upward() -> list[str]:
    edges, _ = _imports()
    return sorted(f"upward import: {a} -> {b}" for a, bs in edges.items() for b in bs
                  if layer_of(b) > layer_of(a))


def _body_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    body = node.body
    first = body[0]
    if (len(body) > 1 and isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
            and isinstance(first.value.value, str)):
        first = body[1]
    return (node.end_lineno or node.lineno) - first.lineno + 1


def _sizes() -> list[str]:
    out = []
    for name, path in sorted(_modules().items()):
        text = path.read_text()
        if len(text.splitlines()) > MAX_MODULE_LINES:
            out.append(f"module over {MAX_MODULE_LINES} lines: {name}")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                qual = f"{name}.{node.name}"
                if qual not in DATA_TABLES and _body_lines(node) > MAX_FUNCTION_BODY_LINES:
                    out.append(f"function over {MAX_FUNCTION_BODY_LINES} lines: {qual}")
    return out


def _private_attributes() -> list[str]:
    """``dyads._cdiv`` from derive.py: a module imported from the package, then a private
    attribute of it read."""
    mods = _modules()
    out = []
    for name, path in sorted(mods.items()):
        tree = ast.parse(path.read_text())
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        bound: set[str] = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = package.split(".")
                if node.level:
                    base = base[: len(base) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                for alias in node.names:
                    if f"{target}.{alias.name}" in mods and f"{target}.{alias.name}" != name:
                        bound.add(alias.asname or alias.name)
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name.startswith("linkage") and alias.asname:
                        bound.add(alias.asname)
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in bound and node.attr.startswith("_")
                    and not (node.attr.startswith("__") and node.attr.endswith("__"))):
                out.append(f"private attribute: {name} uses {node.value.id}.{node.attr}")
    return sorted(set(out))


def _violations() -> set[str]:
    return set(_upward()) | set(_sizes()) | set(_private_attributes())


def test_no_upward_import_no_oversized_module_or_function_no_private_attribute():
    """Issue 33: problems/ imported kinematics, solve and methods; dyads._cdiv was read 8
    times from derive.py; synthesis.py was 1,567 lines."""
    found = _violations()
    assert sorted(found - PENDING) == []
    assert sorted(PENDING - found) == [], "fixed: remove from PENDING"


def test_the_structure_checks_catch_what_they_name(tmp_path):
    """Each check fails on a planted case (so the test above cannot pass vacuously)."""
    assert layer_of("linkage.problems.loops") < layer_of("linkage.kinematics.sweep")
    assert layer_of("linkage.render.writers") > layer_of("linkage.scan")
    fake = tmp_path / "linkage"
    (fake / "problems").mkdir(parents=True)
    (fake / "kinematics").mkdir()
    (fake / "__init__.py").write_text("")
    (fake / "problems" / "__init__.py").write_text("")
    (fake / "kinematics" / "__init__.py").write_text("")
    (fake / "kinematics" / "sweep.py").write_text("def _hidden():\n    return 1\n")
    long_body = "\n".join(f"    x{i} = {i}" for i in range(81))
    (fake / "problems" / "loops.py").write_text(
        "from ..kinematics import sweep\n\n\ndef f():\n    \"\"\"doc\"\"\"\n" + long_body + "\n"
        + "\n" * 600 + "y = sweep._hidden()\n")
    global SRC
    saved = SRC
    SRC = fake
    try:
        found = _violations()
    finally:
        SRC = saved
    assert "upward import: linkage.problems.loops -> linkage.kinematics.sweep" in found
    assert "module over 600 lines: linkage.problems.loops" in found
    assert "function over 80 lines: linkage.problems.loops.f" in found
    assert "private attribute: linkage.problems.loops uses sweep._hidden" in found
