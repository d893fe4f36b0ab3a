"""Report blocks for scalar solves: the iteration table, the outcome, the convergence analysis."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..analysis.convergence import Convergence
from ..problems.scalar import ScalarProblem
from ..result import Result
from .data import DataTable, Report, from_history, from_rows, split_header
from .report import Block, Table, Text, fmt, history_blocks, table

_CONSTANT_HEADER = {
    "newton": "e_k+1/e_k^2",
    "secant": "e_k+1/e_k^1.618",
    "regula-falsi": "e_k+1/e_k^1.442",
    "hybrid": "e_k+1/e_k^1.839",
}


def _with_unit(v: Any, unit: str, digits: int) -> str:
    return f"{fmt(v, digits)} {unit}".rstrip()


def scalar_title(problem: ScalarProblem, digits: int, fourbar: dict[str, Any] | None = None) -> str:
    """The problem's title line; the four-bar's alpha and R1, R2, R3 to ``digits`` (--digits
    reaches the header, not only the table)."""
    if not fourbar or "alpha" not in fourbar or "R" not in fourbar:
        return problem.title
    r1, r2, r3 = fourbar["R"]
    return (f"four-bar input-output equation, alpha = {fmt(float(fourbar['alpha']), digits)} deg, "
            f"R1 = {fmt(float(r1), digits)}, R2 = {fmt(float(r2), digits)}, R3 = {fmt(float(r3), digits)}")


def scalar_blocks(problem: ScalarProblem, result: Result, conv: Convergence | None,
                  digits: int, fourbar: dict[str, Any] | None = None) -> list[Block]:
    var, unit = problem.var, problem.unit
    start = {k: v for k, v in (result.meta or {}).items() if k in ("x0", "x1", "bracket")}
    start_text = ", ".join(
        f"{k} = [{fmt(v[0], digits)}, {fmt(v[1], digits)}]" if k == "bracket" else f"{k} = {fmt(v, digits)}"
        for k, v in start.items())
    blocks: list[Block] = [
        Text(scalar_title(problem, digits, fourbar), "bold"),
        Text(f"method: {result.method}" + (f", {start_text}" if start_text else "")
             + f", tol = {fmt((result.meta or {}).get('tol'), 3)}"
             + (f" {unit}" if unit else "")),
        Text(""),
    ]
    h = result.history
    blocks.extend(history_blocks(h, digits))
    style = "green" if result.converged else "red"
    blocks.append(Text(result.message, style))
    answer = var if result.converged else f"last iterate (not a root): {var}"
    blocks.append(Text(
        f"{answer} = {_with_unit(result.x, unit, max(digits, 15))}   ({result.iterations} iterations, "
        f"{result.nfev} evaluations, f({var}) = {fmt(result.residual, 3)})", "bold"))
    if conv is not None and len(conv.rows) >= 2:
        blocks.append(Text(""))
        blocks.extend(convergence_blocks(conv, unit, digits, result.converged))
    return blocks


def convergence_blocks(conv: Convergence, unit: str, digits: int, converged: bool = True) -> list[Block]:
    c_head = _CONSTANT_HEADER.get(conv.method)
    headers = ["i", f"error e_k ({unit})" if unit else "error e_k", "e_k+1/e_k", "order q_k"]
    if c_head:
        headers.append(c_head)
    rows = []
    for r in conv.rows:
        row = [r.index, r.error, r.ratio, r.order]
        if c_head:
            row.append(r.constant)
        rows.append(tuple(fmt(v, 6) for v in row) + (("rounding",) if r.rounding else ("",)))
    headers.append("note")
    t = Table("Convergence", tuple(headers), tuple(rows))
    lines = [t, Text(_summary_line(conv))]
    if not converged:
        lines.append(Text("the run did not converge: these figures describe its steps, "
                          "not convergence to a root"))
    lines.extend(Text(n) for n in conv.notes)
    return lines


def _summary_line(conv: Convergence) -> str:
    th = conv.theory
    parts = [f"estimated order {fmt(conv.order, 4)} (theory {fmt(conv.theory_order, 4)})"]
    if conv.theory_order == 1.0 or conv.method in ("bisection", "fixed-point"):
        parts.append(f"rate e_k+1/e_k = {fmt(conv.rate, 5)} (theory {fmt(th.get('rate'), 5)})")
    elif conv.constant is not None:
        parts.append(f"constant {fmt(conv.constant, 5)} (theory {fmt(th.get('constant'), 5)})")
    return "; ".join(parts)


SUMMARY_HEADERS = ("method", "status", "iterations", "evaluations", "root", "final error",
                   "residual", "order", "time per solve (us)")


def summary_blocks(problem: ScalarProblem, runs: Sequence[tuple[Result, Convergence | None, float | None]],
                   digits: int, fourbar: dict[str, Any] | None = None
                   ) -> tuple[list[Block], tuple[tuple[str, ...], list[tuple[Any, ...]]]]:
    unit = problem.unit
    headers = list(SUMMARY_HEADERS)
    if unit:
        headers[4] = f"{problem.var} ({unit})"
        headers[5] = f"final error ({unit})"
    rows = []
    for r, c, s in runs:
        # a failed method has no root to show: its last iterate is in the JSON
        rows.append((r.method, r.status.value, r.iterations, r.nfev, r.x if r.converged else None, r.error,
                     r.residual, c.order if c else None, s * 1e6 if s is not None else None))
    blocks: list[Block] = [
        Text(scalar_title(problem, digits, fourbar), "bold"),
        Text("one row per method, side by side (time: median per solve, history off)"),
        Text(""),
        table("", headers, [(*row[:5], fmt(row[5], 3), fmt(row[6], 3), fmt(row[7], 4),
                             fmt(row[8], 4)) for row in rows], digits),
    ]
    return blocks, (tuple(headers), rows)


# --- reports: one per solve, every quantity in every format -----------------------------------

def iterations_table(result: Result) -> DataTable:
    """The recorded history as a table: each column named and with its unit (``phi_i (deg)``
    -> name ``phi_i``, unit ``deg``), full precision."""
    h = result.history
    if h is None or not h.rows:
        return DataTable("iterations", ())
    t = from_history("iterations", h.columns, h.rows)
    seen: set[str] = set()
    cols = []
    for c, label in zip(t.columns, h.columns):
        name, unit = history_name(label)
        if name in seen:  # a step in rad and again in deg: dtheta3 (rad), dtheta3_deg (deg)
            name = f"{name}_{unit}"
        seen.add(name)
        cols.append(c._replace(name=name, unit=unit))
    return t._replace(columns=tuple(cols))


def history_name(label: str) -> tuple[str, str]:
    """A history column's (name, unit): ``phi_i (deg)`` -> (phi_i, deg); a unit inside the
    label, ``true error (deg) vs open`` -> (true error vs open, deg); ``f(phi_i)`` has none."""
    import re

    m = re.fullmatch(r"(.*?) \(([^()]*)\)(.*)", label)
    return (m.group(1) + m.group(3), m.group(2)) if m else (label, "")


def scalar_report(problem: ScalarProblem, result: Result, conv: Convergence | None, digits: int,
                  fourbar: dict[str, Any] | None = None) -> Report:
    """One method on one equation: the iteration table; the display adds the outcome, the
    convergence analysis and (the four-bar's) both closed-form roots; the JSON document is
    :func:`~.export.result_dict`'s contract (``iterations`` as row objects, ``convergence``)."""
    from .export import result_dict

    def blocks() -> list[Block]:
        out = scalar_blocks(problem, result, conv, digits, fourbar)
        if fourbar is not None:
            out += fourbar_blocks(fourbar, digits)
        return out

    def document() -> dict[str, Any]:
        extra: dict[str, Any] = {"problem": problem.title, "units": {problem.var: problem.unit}}
        if fourbar is not None:
            extra["fourbar"] = fourbar
        return result_dict(result, {problem.var: result.x}, conv.as_dict() if conv else None, extra)

    # the iteration table alone: a spreadsheet or a script reads the CSV as it is (the
    # outcome is the exit code; the convergence analysis is in the display and JSON)
    return Report(scalar_title(problem, digits, fourbar), (iterations_table(result),), blocks, document)


def outcome_table(result: Result, conv: Convergence | None, error_unit: str) -> DataTable:
    """One row: how the run ended (method, status, converged, message), its counts, the
    last step and residual, and the estimated order of convergence with its rate and
    constant: what the display's lines say, for the files (a run that did not converge
    says so in every format)."""
    c = conv.as_dict() if conv is not None else {}
    spec = [("method", "", "text"), ("status", "", "text"), ("converged", "", "bool"),
            ("message", "", "text"), ("iterations", "", "int"), ("evaluations", "", "int"),
            ("jacobians", "", "int"), ("last step", error_unit, "number"), ("residual", "", "number"),
            ("order", "", "number"), ("rate", "", "number"), ("constant", "", "number")]

    def number(v: Any) -> float | None:
        return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None

    row = (result.method, result.status.value, result.converged, result.message, result.iterations,
           result.nfev, result.njev, number(result.error), number(result.residual),
           number(c.get("order")), number(c.get("rate")), number(c.get("constant")))
    return from_rows("outcome", spec, [row])


SUMMARY_KINDS = ("text", "text", "int", "int", "number", "number", "number", "number", "number")


def summary_report(problem: ScalarProblem, runs: Sequence[tuple[Result, Convergence | None, float | None]],
                   digits: int, fourbar: dict[str, Any] | None = None) -> Report:
    """--method all: one row per method (the summary table, each column with its unit); the
    JSON document is ``{"problem", "units", "runs": [one solve's document per method]}``
    (a document is an object, so the writer can add its ``tables``)."""
    from .export import result_dict

    shown, (headers, rows) = summary_blocks(problem, runs, digits, fourbar)
    # the headers carry the units (phi (deg), final error (deg), time per solve (us))
    spec = [(*split_header(h), k) for h, k in zip(headers, SUMMARY_KINDS)]

    def document() -> dict[str, Any]:
        return {"problem": problem.title, "units": {problem.var: problem.unit},
                "runs": [result_dict(r, {problem.var: r.x}, c.as_dict() if c else None,
                                     {"problem": problem.title, "units": {problem.var: problem.unit},
                                      "seconds_per_solve": s}) for r, c, s in runs]}

    return Report(scalar_title(problem, digits, fourbar), (from_rows("summary", spec, rows),),
                  lambda: shown, document)


def fourbar_blocks(info: dict[str, Any], digits: int) -> list[Any]:
    d = max(digits, 12)
    out: list[Any] = [Text("")]
    roots = info["roots"]
    out.append(Text("both roots (closed form): " + (", ".join(f"phi = {fmt(r, d)} deg" for r in roots)
                                                     or "none: the linkage cannot be assembled here")))
    fc = info.get("file_convention")
    if fc:
        other = info.get("other_assembly")
        out.append(Text(f"in the mechanism-file convention (ground O2 -> O4 along +x, angles from +x): "
                        f"theta2 = {fmt(fc['theta2'], d)}, theta3 = {fmt(fc['theta3'], d)}, "
                        f"theta4 = {fmt(fc['theta4'], d)} deg ({fc['branch']} branch)"
                        + (f"; other assembly theta3 = {fmt(other['theta3'], d)}, theta4 = "
                           f"{fmt(other['theta4'], d)} deg ({other['branch']})" if other else "")))
        out.append(Text("(alpha and phi are measured from the line O4 -> O2, so theta2 = alpha + 180 "
                        "and theta4 = phi + 180: see the README's angle conventions)"))
    return out
