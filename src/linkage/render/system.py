"""Report blocks for loop-closure solves: P3's table, the solution with units, the check."""

from __future__ import annotations

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
                  branch: str | None) -> list[Block]:
    meta = result.meta or {}
    blocks: list[Block] = [
        Text(problem.title, "bold"),
        Text(f"method: {result.method}, start: "
             + ", ".join(f"{n} = {fmt(v, digits)} {problem.unit(i)}".rstrip()
                         for i, (n, v) in enumerate(zip(problem.names, problem.to_display(problem.x0 or ()))))
             + f", tol = {fmt(meta.get('tol'), 3)} (step), {fmt(meta.get('ftol'), 3)} (residual)"),
        Text("equations: " + ", ".join(f"Phi{i + 1} = {e}" for i, e in enumerate(problem.equation_names))
             + " (x and y of each vector loop)"),
        Text(""),
    ]
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
            line += f"   (closed form, {branch} branch: {fmt(ref[name], max(digits, 15))})"
        blocks.append(Text(line, "bold"))
    blocks.append(Text(f"{result.iterations} iterations, {result.nfev} residual evaluations, "
                       f"{result.njev} Jacobian evaluations, max|Phi| at the "
                       f"{'solution' if result.converged else 'last iterate'} = "
                       f"{fmt(result.residual, 3)} {problem.length_unit}".rstrip()))
    if conv is not None and len(conv.rows) >= 2:
        blocks.append(Text(""))
        blocks.extend(convergence_blocks(conv, "", digits, result.converged))
    return blocks


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
    }
