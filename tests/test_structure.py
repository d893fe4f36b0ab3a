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
