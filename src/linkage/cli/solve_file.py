"""linkage solve FILE: a mechanism's loop equations."""

from pathlib import Path
from typing import Any

import typer

from .options import emit_report, note_closed_form, parse_assignments


def solve_file(file: Path, method: str, set_: list[str], guess: list[str], tol: float, rtol: float,
                ftol: float | None, max_iter: int, fd_step: float | None, damped: bool,
                show_jacobian: bool, out_fmt: str, output: Path | None, digits: int,
                plot: Path | None = None, motion: tuple[str | None, str | None] = (None, None),
                branch_wanted: str | None = None, columns: str | None = None,
                loads_given: tuple[list[str], list[str], str | None] = ([], [], None),
                table: str | None = None) -> None:
    import dataclasses

    from ..analysis.convergence import analyze
    from ..arguments import check_fd_step, check_method, parse_motion
    from ..kinematics.loading import load
    from ..problems.closed_form import fourbar_facts
    from ..problems.start import start_on_branch
    from ..render.system import branch_label, system_report
    from ..solve import SYSTEM_METHODS, solve_system
    from ..solve.system import check_assembles

    check_method("--method", method, SYSTEM_METHODS, "for a mechanism file")
    if fd_step is not None:
        fd_step = check_fd_step("--fd-step", fd_step)  # named as the command line names it
    mechanism = load(file).with_values(parse_assignments("--set", set_),
                                       parse_assignments("--guess", guess))
    note_closed_form(mechanism)
    if branch_wanted is not None:
        mechanism = start_on_branch(mechanism, branch_wanted, bool(guess))
    speed, accel = parse_motion(*motion, mechanism)
    from ..kinematics.bodies import command_loads

    loads = command_loads(mechanism, *loads_given)
    problem = mechanism.problem()
    check_assembles(problem, str(file))
    # the header says which loops are closed-form and which coupled (solve_system copies meta)
    problem = dataclasses.replace(problem, meta={**problem.meta, "closed_form": mechanism.derivation.summary})
    result = solve_system(problem, method=method, tol=tol, rtol=rtol, ftol=ftol, max_iter=max_iter,
                          fd_step=fd_step, damped=damped, show_jacobian=show_jacobian)
    conv = analyze(result)
    branch = branch_label(problem, result) if result.converged else None
    fourbars = fourbar_facts(mechanism, result.x if result.converged else None)
    rates = None
    if result.converged:
        from ..kinematics.rates import position_rates

        rates = position_rates(mechanism.model, result.x, mechanism.driver.value, speed, accel)
    report = system_report(problem, result, conv, digits, branch, fourbars, rates,
                           (speed, accel) if speed is not None else None, mechanism.driver.kind,
                           origin=mechanism.origin)
    if result.converged and (not loads.empty or loads.gravity is not None):
        report = _with_forces(report, mechanism, result.x, loads, speed, accel, digits)
    emit_report(report, out_fmt, output, columns=columns, table=table)
    if plot is not None:
        convergence_plot([result], plot, report.title,
                          ", ".join(sorted({problem.step_unit(i) for i in range(problem.n)} - {""})))
    if not result.converged:
        raise typer.Exit(1)


def convergence_plot(results: list[Any], path: Path, title: str, unit: str = "") -> None:
    from ..render.plots import convergence_plot as plot
    from ..render.plots import error_series

    plot(error_series(results), path, title, unit)
    typer.echo(f"wrote {path}", err=True)


def _with_forces(report: Any, mechanism: Any, q: Any, loads: Any, speed: float | None, accel: float | None,
                 digits: int) -> Any:
    """The solve's report with the loads answer added (kinematics.forces)."""
    from ..kinematics.forces import forces_at
    from ..problems.loads import applied_rows
    from ..render.data import Report
    from ..render.forces import applied_document, force_blocks, force_document, force_tables

    f = forces_at(mechanism, q, loads, speed=speed or 0.0, accel=accel or 0.0)
    applied = applied_rows(loads, mechanism.extra["drawing"])
    if loads.gravity is not None and not loads.masses:
        from .options import NOTED

        NOTED.append("--gravity acts on the [mass] links, and this file gives none")
    document = report.document

    def doc() -> Any:
        d = document() if document is not None else {}
        forces = {**force_document(f), "applied": applied_document(applied)}
        return {**d, "forces": forces} if isinstance(d, dict) else d

    return Report(report.title, (*report.tables, *force_tables(f)),
                  lambda: [*report.blocks(), *force_blocks(f, digits, applied)], doc)
