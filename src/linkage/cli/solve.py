"""linkage solve."""

from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ..errors import InputError
from ..methods import METHODS
from ..solve.system import SYSTEM_METHODS
from .options import (
    PICTURES,
    AccelOpt,
    ColumnsOpt,
    DigitsOpt,
    FormatOpt,
    GravityOpt,
    LoadOpt,
    OutputOpt,
    SetOpt,
    SpeedOpt,
    TableOpt,
    TorqueOpt,
    check_paths,
    choose_format,
    emit_report,
)
from .root import app
from .solve_file import convergence_plot, solve_file


@app.command(
    epilog="Examples:  linkage solve  |  linkage solve --method all  |  "
    "linkage solve --method bisection --alpha 40  |  "
    "linkage solve --equation 'x**2 - 4*x + 1' --x0 5 --format csv",
)
def solve(
    file: Annotated[Optional[Path], typer.Argument(
        metavar="[FILE]", help="A mechanism file (TOML, see sample_inputs/; - reads standard input): "
        "solve its loop-closure equations.", show_default=False)] = None,
    *,
    method: Annotated[str, typer.Option("--method", "-m", help=f"{', '.join(METHODS)}, several of them "
                      f"separated by commas, or all; with FILE: {', '.join(SYSTEM_METHODS)}.")] = "newton",
    alpha: Annotated[Optional[float], typer.Option(help="Four-bar input angle alpha (deg); "
                     "default 70.")] = None,
    r1: Annotated[Optional[str], typer.Option("--r1", help="R1 (default 5/3).")] = None,
    r2: Annotated[Optional[str], typer.Option("--r2", help="R2 (default 5/2).")] = None,
    r3: Annotated[Optional[str], typer.Option("--r3", help="R3 (default 11/6).")] = None,
    links: Annotated[Optional[tuple[str, str, str, str]], typer.Option(
        metavar="A B C D", help="Link lengths: input, coupler, output, ground (sets R1, R2, R3).")] = None,
    equation: Annotated[Optional[str], typer.Option("--equation", "-e", help="Solve this "
                        "equation in x instead, e.g. 'x**2 - 4*x + 1'.")] = None,
    g: Annotated[Optional[str], typer.Option("--g", help="Iteration function for "
                 "fixed-point on --equation: x = g(x).")] = None,
    x0: Annotated[Optional[float], typer.Option(help="Starting point (deg for the four-bar).")] = None,
    x1: Annotated[Optional[float], typer.Option(help="Second starting point (secant).")] = None,
    bracket: Annotated[Optional[tuple[float, float]], typer.Option(
        metavar="A B", help="Bracket A B with a sign change (bisection, regula-falsi, hybrid).")] = None,
    tol: Annotated[float, typer.Option(help="Step tolerance epsilon_s (absolute).")] = 1e-6,
    rtol: Annotated[float, typer.Option(help="Relative step tolerance.")] = 0.0,
    ftol: Annotated[Optional[float], typer.Option(help="Residual tolerance epsilon_e "
                    "(off unless given).")] = None,
    max_iter: Annotated[Optional[int], typer.Option("--max-iter", help="Iteration cap (default 100; "
                        "50 with FILE).")] = None,
    set_: SetOpt = None,
    guess: Annotated[Optional[list[str]], typer.Option(metavar="NAME=VALUE", help="With FILE: initial guess "
                     "name=value in the file's units (repeatable).")] = None,
    show_jacobian: Annotated[bool, typer.Option("--show-jacobian", help="With FILE: add the "
                             "Jacobian entries (with units) to the table.")] = False,
    fd_step: Annotated[Optional[float], typer.Option(help="With FILE and newton-fd: the "
                       "finite-difference step h (rad or length units; default "
                       "sqrt(eps)*max(1,|q|)).")] = None,
    damped: Annotated[bool, typer.Option("--damped/--plain", help="With FILE: globalised Newton "
                      "(default: the full step when it lowers the residual, else a shorter or "
                      "damped one) or the textbook iteration (--plain).")] = True,
    plot: Annotated[Optional[Path], typer.Option(help="Also plot log10 error against iteration "
                    "for the method(s) run (.png, .svg or .pdf; needs matplotlib).")] = None,
    branch: Annotated[Optional[str], typer.Option(help="With FILE (one whose loops have a closed "
                      "form: the header says): the assembly to solve for, by name (open or crossed per "
                      "four-bar or slider-crank loop, e.g. open/crossed for a six-bar; a rocker-driven "
                      "four-bar's second assembly of one name: 'open (mirror)') or by signs: + or - "
                      "for the root taken in each closed-form step with two, in loop order (e.g. +- "
                      "for a six-bar). Its closed form is the start.")] = None,
    speed: SpeedOpt = None,
    accel: AccelOpt = None,
    load: LoadOpt = None,
    torque: TorqueOpt = None,
    gravity: GravityOpt = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    digits: DigitsOpt = 12,
    columns: ColumnsOpt = None,
    table: TableOpt = None,
) -> None:
    """Solve an equation, or a mechanism's loop equations, and print every iteration.

    Without options: Newton's method on the four-bar input-output equation (the course
    notes' example, alpha = 70 deg) from phi = 50 deg. With FILE (or - for standard
    input): Newton-Raphson on the mechanism's loop equations. Its header says which loops
    also have an exact closed form ("loops 1, 2 (stepwise)": loop 1 solved first, then loop 2
    with its answers) and which are coupled (Newton only); with one, the table has the
    iterates' true error and the answer its closed-form value beside it.

    Example: linkage solve --method secant --x0 50 --x1 60

    Example: linkage solve sample_inputs/fourbar_me581.toml --set theta2=80
    """
    from ..analysis.convergence import analyze
    from ..arguments import check_method_list, check_number
    from ..methods import BRACKETING, SCALAR_METHODS
    from ..problems.seed_equation import applicable, fourbar_coefficients, fourbar_info, scalar_problem
    from ..solve import check_criteria, solve_scalar

    out_fmt = choose_format(fmt, output)
    check_paths([file], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    # the cap's default depends on FILE: None until here, so "--max-iter 100" given is kept
    file_cap, max_iter = (50, 100) if max_iter is None else (max_iter, max_iter)
    check_criteria(tol, rtol, ftol, max_iter)
    scalar_only = {"--alpha": alpha, "--r1": r1, "--r2": r2, "--r3": r3, "--links": links,
                   "--equation": equation, "--g": g, "--x0": x0, "--x1": x1, "--bracket": bracket}
    system_only = {"--set": set_, "--guess": guess, "--fd-step": fd_step, "--speed": speed, "--accel": accel,
                   "--branch": branch, "--load": load, "--torque": torque, "--gravity": gravity,
                   "--show-jacobian": show_jacobian or None, "--plain": (not damped) or None}
    if file is not None:
        given = [k for k, v in scalar_only.items() if v is not None]
        if given:
            raise InputError(f"{', '.join(given)} apply to a single equation, not to a mechanism file")
        solve_file(file, method, set_ or [], guess or [], tol, rtol, ftol,
                    file_cap, fd_step, damped, show_jacobian,
                    out_fmt, output, digits, plot, (speed, accel), branch, columns,
                    (load or [], torque or [], gravity), table)
        return
    given = [k for k, v in system_only.items() if v is not None]
    if given:
        raise InputError(f"{', '.join(given)} apply to a mechanism FILE")
    for name, v in (("x0", x0), ("x1", x1), ("alpha", alpha)):
        if v is not None:
            check_number(name, v)
    if bracket is not None:
        check_number("bracket start", bracket[0])
        check_number("bracket end", bracket[1])
    problem = scalar_problem(equation, g, alpha, r1, r2, r3, links, refuse_unassembled=True)
    summary = method == "all" or "," in method  # several methods: one summary row each
    if method == "all":
        names = [m for m in SCALAR_METHODS if applicable(m, problem, equation, x0, x1, bracket)]
        if not names:
            raise InputError("no method applies: give --x0 (newton), --x0 and --x1 (secant), "
                             "--bracket (bracketing) or --g with --x0 (fixed-point)")
    else:
        names = check_method_list("--method", method, SCALAR_METHODS)

    if summary:
        from ..measure.timing import time_per_solve
    runs = []
    for name in names:
        kwargs: dict[str, Any] = dict(method=name, tol=tol, rtol=rtol, ftol=ftol, max_iter=max_iter)
        if name in BRACKETING:
            kwargs["bracket"] = bracket
        else:
            kwargs["x0"], kwargs["x1"] = x0, x1
        result = solve_scalar(problem, **kwargs)
        if result.status.value == "invalid_bracket" and len(names) == 1:
            raise InputError(result.detail)
        conv = analyze(result, problem)
        seconds = time_per_solve(problem, kwargs) if summary else None
        runs.append((result, conv, seconds))

    from ..render.scalar import scalar_report, summary_report
    from .options import note_exit_reasons

    fourbar = None
    if equation is None and not summary:
        fourbar = fourbar_info(alpha, r1, r2, r3, links, runs[0][0])
    elif equation is None:  # the summary's title: alpha and R1, R2, R3
        fourbar = {"alpha": 70.0 if alpha is None else alpha,
                   "R": list(fourbar_coefficients(r1, r2, r3, links)[0])}
    report = scalar_report(problem, *runs[0][:2], digits, fourbar) if not summary else \
        summary_report(problem, runs, digits, fourbar)
    emit_report(report, out_fmt, output, columns=columns, table=table)
    if plot is not None:
        convergence_plot([r for r, _, _ in runs], plot, report.title, problem.unit)
    if not all(r.converged for r, _, _ in runs):
        note_exit_reasons(out_fmt, (f"{r.method}: {r.status.value}: {r.message}" for r, _, _ in runs
                                    if not r.converged))
        raise typer.Exit(1)
