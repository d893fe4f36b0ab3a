"""Report blocks for loop-closure solves: P3's table, the solution with units, the check."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..analysis.convergence import Convergence
from ..problems.closed_form import MIRROR, TRANSMISSION
from ..problems.system import SystemProblem
from ..result import Result
from .data import DataTable, Report, column
from .report import Block, Text, fmt, history_blocks
from .scalar import convergence_blocks, iterations_table, outcome_table


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
        Text(system_title(problem, digits), "bold"),
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
        blocks.extend(convergence_blocks(conv, step_units(problem), digits, result.converged))
    return blocks


def step_units(problem: SystemProblem) -> str:
    """The unit of a step's size max|dq| (rad, a length unit, or both for a slider)."""
    return ", ".join(sorted({problem.step_unit(i) for i in range(problem.n)} - {""}))


def system_title(problem: SystemProblem, digits: int) -> str:
    """``name: driver = value unit`` with the driver's value to ``digits`` (the problem's
    own title rounds it to 6, as ``:g`` does)."""
    meta = problem.meta or {}
    if "mechanism" not in meta or meta.get("driver_value") is None:
        return problem.title
    return (f"{meta['mechanism']}: {meta['driver']} = {fmt(float(meta['driver_value']), digits)} "
            f"{meta.get('driver_unit') or ''}").rstrip()


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
        line += f", {TRANSMISSION} = {fmt(fact['transmission_deg'], min(digits, 8))} deg"
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


# --- the report: every quantity of a solve in every format -----------------------------------

def system_report(problem: SystemProblem, result: Result, conv: Convergence | None, digits: int,
                  branch: str | None, fourbars: Sequence[dict[str, Any]] = (), rates: Any = None,
                  motion: tuple[float, float] | None = None, driver_kind: str = "angle",
                  origin: tuple[float, float] = (0.0, 0.0)) -> Report:
    """``solve FILE``: the tables ``iterations`` (the history, each column with its unit)
    and, when it converged, ``unknowns`` (each unknown's value with its unit; with a driver
    speed, ``motion`` = (speed, accel) in internal units, its velocity and acceleration
    with their units and error bounds, and the rates' status) and ``joints`` (each joint
    and point's x and y; with a speed their velocities, accelerations and bounds). The
    JSON document is today's (``solution``, ``velocities``, ``joints``, ...); the display
    is the iteration table, the answer, the convergence analysis and the rate tables."""
    from .export import result_dict
    from .rates import rate_units_dict, rates_blocks, rates_dict

    L = problem.length_unit
    units = sorted({problem.step_unit(i) for i in range(problem.n)} - {""})
    tables = [iterations_table(result)]
    if result.converged:
        tables.append(unknowns_table(problem, result, branch, rates, motion is not None))
        if rates is not None:
            tables.append(joints_table(rates, L, motion is not None))
    tables.append(outcome_table(result, conv, units[0] if len(units) == 1 else ""))

    def blocks() -> list[Block]:
        out = system_blocks(problem, result, conv, digits, branch, fourbars)
        if rates is not None:
            more = rates_blocks(rates, problem.names, problem.kinds, L, digits, origin)
            if more:  # a blank line after the convergence summary, as between the other blocks
                out.append(Text(""))
            out += more
            if rates.status != "ok":
                why = ("velocities and accelerations are undefined here: the Jacobian is singular "
                       "(a toggle or dead-centre position)" if rates.status == "undefined" else
                       f"ill-conditioned here (near a toggle or limit): {', '.join(rates.ill_conditioned)} "
                       "shown with the digits their error bounds leave")
                out.append(Text(why, "red"))
        return out

    def document() -> dict[str, Any]:
        extra = system_extra(problem, result, branch)
        extra["fourbars"] = list(fourbars)
        if rates is not None:
            extra.update(rates_dict(rates))
            if motion is not None:
                extra["driver"].update(speed=motion[0], accel=motion[1])
                extra["rate_units"] = rate_units_dict(problem.names, problem.kinds, L, driver_kind)
        return result_dict(result, system_solution(problem, result), conv.as_dict() if conv else None, extra)

    return Report(system_title(problem, digits), tuple(tables), blocks, document)


def unknowns_table(problem: SystemProblem, result: Result, branch: str | None, rates: Any,
                   motion: bool) -> DataTable:
    """One row per unknown: its value and unit (the closed form's on the branch beside it,
    where there is one); with a driver speed its velocity and acceleration, each with its
    unit and absolute error bound, and the rates' status (ok, ill_conditioned, undefined)."""
    from .rates import rate_units

    names = list(problem.names)
    values = problem.to_display(result.x)
    cols = [column("unknown", "", names, "text"), column("value", "", [float(v) for v in values]),
            column("unit", "", [problem.unit(i) for i in range(problem.n)], "text")]
    ref = ((result.meta or {}).get("reference") or {}).get(branch) if branch else None
    if ref is not None:
        cols.append(column("closed form", "", [float(_turn_of(ref[n], v, k))
                                               for n, v, k in zip(names, values, problem.kinds)]))
    if motion:
        have = rates is not None and bool(rates.velocities)
        units = [rate_units(k, problem.length_unit) for k in problem.kinds]

        def of(d: Any) -> list[Any]:
            return [d.get(n) if have else None for n in names]

        cols += [column("velocity", "", of(rates.velocities if have else {})),
                 column("velocity unit", "", [u[0] for u in units], "text"),
                 column("velocity bound", "", of(rates.velocity_bounds if have else {})),
                 column("acceleration", "", of(rates.accelerations if have else {})),
                 column("acceleration unit", "", [u[1] for u in units], "text"),
                 column("acceleration bound", "", of(rates.acceleration_bounds if have else {})),
                 column("rates status", "", [getattr(rates, "status", None)] * len(names), "text")]
    return DataTable("unknowns", tuple(cols))


def joints_table(rates: Any, length_unit: str, motion: bool) -> DataTable:
    """One row per joint and point: x and y; with a driver speed vx, vy, ax, ay and the
    error bounds of the velocity and the acceleration (None where undefined)."""
    L = length_unit
    names = list(rates.joints)
    xy = [rates.joints[j] for j in names]
    cols = [column("joint", "", names, "text"), column("x", L, [float(p[0]) for p in xy]),
            column("y", L, [float(p[1]) for p in xy])]
    if motion:
        def part(d: Any, i: int) -> list[Any]:
            return [float(d[j][i]) if d.get(j) else None for j in names]

        v, a = rates.joint_velocities, rates.joint_accelerations
        cols += [column("vx", f"{L}/s", part(v, 0)), column("vy", f"{L}/s", part(v, 1)),
                 column("v bound", f"{L}/s", [rates.joint_velocity_bounds.get(j) for j in names]),
                 column("ax", f"{L}/s^2", part(a, 0)), column("ay", f"{L}/s^2", part(a, 1)),
                 column("a bound", f"{L}/s^2", [rates.joint_acceleration_bounds.get(j) for j in names])]
    return DataTable("joints", tuple(cols))
