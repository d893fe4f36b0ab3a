"""Report blocks for loop-closure solves: P3's table, the solution with units, the check."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..analysis.convergence import Convergence
from ..problems.closed_form import MIRROR
from ..problems.system import SystemProblem
from ..result import Result
from .report import Block, Text, fmt, history_blocks
from .scalar import convergence_blocks


def system_solution(problem: SystemProblem, result: Result) -> dict[str, float]:
    return dict(zip(problem.names, problem.to_display(result.x)))


def system_blocks(problem: SystemProblem, result: Result, conv: Convergence | None, digits: int,
                  branch: str | None, fourbars: Sequence[dict[str, Any]] = ()) -> list[Block]:
    """The solve of a mechanism: its header (with the ``closed_form`` summary of the
    problem's meta: which loops are closed-form, which coupled), the iteration table, the
    solution beside the closed form on its branch, and a line per four-bar loop
    (:func:`~linkage.problems.closed_form.fourbar_facts`)."""
    meta = result.meta or {}
    blocks: list[Block] = [
        Text(problem.title, "bold"),
        Text(f"method: {result.method}, start: "
             + ", ".join(f"{n} = {fmt(v, digits)} {problem.unit(i)}".rstrip()
                         for i, (n, v) in enumerate(zip(problem.names, problem.to_display(problem.x0 or ()))))
             + f", tol = {fmt(meta.get('tol'), 3)} (step), {fmt(meta.get('ftol'), 3)} (residual)"),
        Text("equations: " + ", ".join(f"Phi{i + 1} = {e}" for i, e in enumerate(problem.equation_names))
             + " (x and y of each vector loop)"),
    ]
    if meta.get("closed_form"):
        blocks.append(Text(meta["closed_form"]))
    blocks.append(Text(""))
    h = result.history
    blocks.extend(history_blocks(h, digits))
    blocks.append(Text(result.message, "green" if result.converged else "red"))
    solution = system_solution(problem, result)
    ref = (meta.get("reference") or {}).get(branch) if branch else None
    if not result.converged:
        blocks.append(Text("last iterate (not a solution):"))
    for i, (name, value) in enumerate(solution.items()):
        line = f"{name} = {fmt(value, max(digits, 15))} {problem.unit(i)}".rstrip()
        if not result.converged:
            line = "  " + line
        if ref is not None:
            shown = _turn_of(ref[name], value, problem.kinds[i])
            line += f"   (closed form, {branch} branch: {fmt(shown, max(digits, 15))})"
        blocks.append(Text(line, "bold"))
    blocks.append(Text(f"{_count(result.iterations, 'iteration')}, "
                       f"{_count(result.nfev, 'residual evaluation')}, "
                       f"{_count(result.njev, 'Jacobian evaluation')}, max|Phi| at the "
                       f"{'solution' if result.converged else 'last iterate'} = "
                       f"{fmt(result.residual, 3)} {problem.length_unit}".rstrip()))
    blocks.extend(Text(fourbar_line(fact, digits)) for fact in fourbars)
    if conv is not None and len(conv.rows) >= 2:
        blocks.append(Text(""))
        blocks.extend(convergence_blocks(conv, "", digits, result.converged))
    return blocks


def _turn_of(ref: float, value: float, kind: str) -> float:
    """An angle of the closed form (deg, in (-180, 180]) in the turn of the solution it is
    shown beside: -171.24 beside 188.76 reads 188.76 (the true error brings their
    difference within a turn too). Unchanged when within half a turn already."""
    if kind != "angle" or abs(ref - value) <= 180.0:
        return ref
    from ..problems.closed_form import wrap_degrees

    return value + wrap_degrees(ref - value)


def _count(n: int, noun: str) -> str:
    """'1 iteration', '4 iterations' (--branch starts on the closed form: often 1)."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def fourbar_line(fact: dict[str, Any], digits: int) -> str:
    """A four-bar loop's facts in one line: its Grashof class and transmission angle."""
    line = f"four-bar loop {fact['loop']}: {fact['type']}"
    if fact.get("transmission_deg") is not None:
        line += f", transmission angle {fmt(fact['transmission_deg'], min(digits, 8))} deg"
    return line


def branch_label(problem: SystemProblem, result: Result) -> str | None:
    from ..solve import nearest_branch

    return nearest_branch(problem, (result.meta or {}).get("reference"), result.x)


def system_extra(problem: SystemProblem, result: Result, branch: str | None) -> dict[str, Any]:
    meta = result.meta or {}
    return {
        "problem": problem.title,
        "units": {n: problem.unit(i) for i, n in enumerate(problem.names)},
        "driver": {"name": meta.get("driver"), "value": meta.get("driver_value"),
                   "unit": meta.get("driver_unit")},
        # the configuration's label; the reference key may add " (mirror)" (theta4 driving)
        "branch": branch.removesuffix(MIRROR) if branch else branch,
        "reference": meta.get("reference"),
        "closed_form": meta.get("closed_form"),
    }
