"""The ``linkage`` command line: parses, calls the engine, renders. No numerics here.

Exit codes: 0 converged, 1 ran but did not converge (the rows are still shown),
2 bad input (one line on stderr, never a traceback).
"""


import contextlib
import copy
import math
import sys
import time
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from .errors import InputError, LinkageError
from .numbers import parse_number

app = typer.Typer(
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
    epilog="Example: linkage solve --method all",
)


def _version(value: bool) -> None:
    if value:
        from . import __version__

        typer.echo(f"linkage {__version__}")
        raise typer.Exit(0)


@app.callback()
def _root(
    version: Annotated[bool, typer.Option("--version", callback=_version, is_eager=True,
                                          help="Print the version and exit.")] = False,
) -> None:
    """Kinematics of planar mechanisms by numerical root finding: solve one equation or a
    mechanism's loop equations, sweep a whole cycle, with every iteration shown.

    Example: linkage solve --method all
    """


# --- output options, shared by every command ---------------------------------------------

FormatOpt = Annotated[
    Optional[str],
    typer.Option("--format", "-f", help="table (rich, default on a terminal), plain (default "
                 "when piped), csv, json, or any tabulate format (github, grid, latex, ...)."),
]
OutputOpt = Annotated[
    Optional[Path],
    typer.Option("--output", "-o", help="Write to this file instead of standard output; "
                 "the format follows the suffix (.csv, .json) unless --format is given."),
]
MechanismFile = Annotated[
    Path, typer.Argument(metavar="FILE", help="A mechanism file (TOML, see `linkage samples`).",
                         show_default=False)
]
SetOpt = Annotated[
    Optional[list[str]],
    typer.Option("--set", metavar="NAME=VALUE", help="Override a parameter or the driver, in "
                 "the file's units (repeatable)."),
]
ColumnsOpt = Annotated[
    Optional[str],
    typer.Option("--columns", metavar="NAMES", help="Show only these columns of the tables and "
                 "the CSV: comma-separated names or their beginnings, e.g. theta3,theta4,det "
                 "(the first column always stays)."),
]
def _digits(value: int) -> int:
    """--digits: checked here, not by a click range, whose "<int range> [3<=x<=17]" label
    widened every help page's type column until the help text wrapped at 23 characters."""
    if not 3 <= value <= 17:
        raise typer.BadParameter(f"{value} is not from 3 to 17")
    return value


DigitsOpt = Annotated[
    int, typer.Option("--digits", metavar="N", callback=_digits,
                      help="Significant digits printed in tables (3 to 17).")
]


SpeedOpt = Annotated[
    Optional[str],
    typer.Option("--speed", metavar="SPEED", help="Driver speed, for velocities and "
                 "accelerations of every unknown, joint and point: a number in rad/s (or the "
                 "file's length unit per second for a sliding driver), or with a unit: 600rpm, "
                 "10rad/s, 90deg/s, 250mm/s. Every rate has an error bound: near a toggle or "
                 "limit a rate is ill_conditioned (printed to the digits its bound leaves), at "
                 "one undefined (no number)."),
]
AccelOpt = Annotated[
    Optional[str],
    typer.Option("--accel", metavar="ACCEL", help="Driver acceleration (with --speed; "
                 "default 0): rad/s^2, or 5rad/s^2, 90deg/s^2, 100rpm/s, 20mm/s^2."),
]

def choose_format(fmt: str | None, output: Path | None) -> str:
    from .render.report import FORMATS_OWN, tabulate_formats

    if output is not None and str(output) == "-":
        output = None  # -o - is standard output
    if fmt is None:
        if output is not None:
            return {".csv": "csv", ".json": "json"}.get(output.suffix.lower(), "plain")
        return "table" if sys.stdout.isatty() else "plain"
    if fmt in FORMATS_OWN or fmt in tabulate_formats():
        return fmt
    raise InputError(f"unknown format {fmt!r}; use table, plain, csv, json or a tabulate format "
                     f"({', '.join(tabulate_formats()[:8])}, ...)")


def emit(fmt: str, output: Path | None, *, blocks: Any, json_obj: Any,
         csv_table: tuple[Any, Any], columns: str | None = None) -> None:
    """Write one command's output in the chosen format, to stdout or ``output``;
    ``columns`` (comma-separated name prefixes) keeps only those table and CSV columns."""
    from .render.export import to_csv, to_json
    from .render.report import pick_columns, print_rich, render_text

    if columns:
        blocks, csv_table = pick_columns(blocks, csv_table, columns)

    if fmt == "json":
        text = to_json(json_obj)
    elif fmt == "csv":
        text = to_csv(*csv_table)
    elif fmt == "table":
        if output is None or str(output) == "-":
            with _stdout_errors():
                print_rich(blocks)
            return
        text = render_text(blocks, "simple")
    else:
        text = render_text(blocks, fmt)
    if output is None or str(output) == "-":
        with _stdout_errors():
            sys.stdout.write(text)
            sys.stdout.flush()
        return
    from .files import write_atomic

    write_atomic(output, text)
    typer.echo(f"wrote {output}", err=True)


class _stdout_errors:
    """A failed write to standard output (full disk, closed pipe) becomes one error line."""

    def __enter__(self) -> None:
        return None

    def __exit__(self, kind: Any, exc: Any, tb: Any) -> bool:
        if isinstance(exc, OSError):
            from .errors import OutputError

            raise OutputError(f"cannot write to standard output: {exc.strerror or exc}") from None
        return False


PICTURES = (".png", ".svg", ".pdf")


def check_paths(inputs: list[Path | None], outputs: list[tuple[str, Path | None]],
                pictures: dict[str, tuple[Path | None, tuple[str, ...]]] | None = None) -> None:
    """Every output path checked before any work: not an input, not shared, its folder
    exists; pictures have a suffix the plotter can write."""
    from .files import check_outputs

    for opt, (path, suffixes) in (pictures or {}).items():
        if path is not None and path.suffix.lower() not in suffixes:
            raise InputError(f"{opt} {path}: use one of {', '.join(suffixes)} for the picture")
    check_outputs(inputs, outputs)


# --- solve ----------------------------------------------------------------------------------

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
    method: Annotated[str, typer.Option("--method", "-m", help="bisection, regula-falsi, "
                      "hybrid, secant, newton, fixed-point, or all; with FILE: newton, "
                      "newton-fd, lm.")] = "newton",
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
    max_iter: Annotated[int, typer.Option("--max-iter", help="Iteration cap.")] = 100,
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
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    digits: DigitsOpt = 12,
    columns: ColumnsOpt = None,
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
    from .analysis.convergence import analyze
    from .methods import BRACKETING, SCALAR_METHODS
    from .render.export import result_dict
    from .solve import check_criteria, check_number, solve_scalar

    out_fmt = choose_format(fmt, output)
    check_paths([file], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    check_criteria(tol, rtol, ftol, max_iter)
    scalar_only = {"--alpha": alpha, "--r1": r1, "--r2": r2, "--r3": r3, "--links": links,
                   "--equation": equation, "--g": g, "--x0": x0, "--x1": x1, "--bracket": bracket}
    system_only = {"--set": set_, "--guess": guess, "--fd-step": fd_step, "--speed": speed, "--accel": accel,
                   "--branch": branch,
                   "--show-jacobian": show_jacobian or None, "--plain": (not damped) or None}
    if file is not None:
        given = [k for k, v in scalar_only.items() if v is not None]
        if given:
            raise InputError(f"{', '.join(given)} apply to a single equation, not to a mechanism file")
        _solve_file(file, method, set_ or [], guess or [], tol, rtol, ftol,
                    max_iter if max_iter != 100 else 50, fd_step, damped, show_jacobian,
                    out_fmt, output, digits, plot, (speed, accel), branch, columns)
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
    problem = _scalar_problem(equation, g, alpha, r1, r2, r3, links)
    if method == "all":
        names = [m for m in SCALAR_METHODS if _applicable(m, problem, equation, x0, x1, bracket)]
        if not names:
            raise InputError("no method applies: give --x0 (newton), --x0 and --x1 (secant), "
                             "--bracket (bracketing) or --g with --x0 (fixed-point)")
    elif method in SCALAR_METHODS:
        names = [method]
    else:
        raise InputError(f"unknown method {method!r}; choose from {', '.join(SCALAR_METHODS)}, all")

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
        seconds = _time_solve(problem, kwargs) if method == "all" else None
        runs.append((result, conv, seconds))

    from .render.scalar import scalar_blocks, summary_blocks

    var = problem.var
    if method != "all":
        result, conv, _ = runs[0]
        blocks = scalar_blocks(problem, result, conv, digits)
        extra: dict[str, Any] = {"problem": problem.title, "units": {var: problem.unit}}
        if equation is None:
            info = _fourbar_info(alpha, r1, r2, r3, links, result)
            extra["fourbar"] = info
            blocks += _fourbar_blocks(info, digits)
        json_obj: Any = result_dict(result, {var: result.x}, conv.as_dict() if conv else None, extra)
        h = result.history
        csv_table = (h.columns, h.rows) if h is not None else ((), ())
    else:
        blocks, csv_table = summary_blocks(problem, runs, digits)
        json_obj = [result_dict(r, {var: r.x}, c.as_dict() if c else None,
                                {"problem": problem.title, "units": {var: problem.unit},
                                 "seconds_per_solve": s})
                    for r, c, s in runs]
    emit(out_fmt, output, blocks=blocks, json_obj=json_obj, csv_table=csv_table, columns=columns)
    if plot is not None:
        _convergence_plot([r for r, _, _ in runs], plot, problem.title, problem.unit)
    if not all(r.converged for r, _, _ in runs):
        raise typer.Exit(1)


def _convergence_plot(results: list[Any], path: Path, title: str, unit: str = "") -> None:
    from .render.plots import convergence_plot

    series = []
    for r in results:
        errors = [abs(e) if isinstance(e, (int, float)) else None for e in r.history.errors()] \
            if r.history is not None else []
        series.append((f"{r.method} ({r.status.value})", errors))
    convergence_plot(series, path, title, unit)
    typer.echo(f"wrote {path}", err=True)


def parse_motion(speed: str | None, accel: str | None, mechanism: Any) -> tuple[float | None, float]:
    """--speed and --accel in internal units (rad/s, rad/s^2, or length/s, length/s^2)."""
    import re

    from .arguments import MAX_RATE, MIN_RATE, rate_in_range

    if speed is None:
        if accel is not None:
            raise InputError("--accel needs --speed (the driver's velocity)")
        return None, 0.0
    angle = mechanism.driver.kind == "angle"
    unit = mechanism.length_unit
    tables = (
        {"": 1.0, "rad/s": 1.0, "deg/s": math.pi / 180.0, "rpm": math.pi / 30.0} if angle
        else {"": 1.0, f"{unit}/s": 1.0},
        {"": 1.0, "rad/s^2": 1.0, "rad/s2": 1.0, "deg/s^2": math.pi / 180.0, "deg/s2": math.pi / 180.0,
         "rpm/s": math.pi / 30.0} if angle else {"": 1.0, f"{unit}/s^2": 1.0, f"{unit}/s2": 1.0},
    )
    out = []
    accel = "0" if accel is None else accel  # an empty --accel '' is refused, not taken as 0
    for option, text, units in (("--speed", speed, tables[0]), ("--accel", accel, tables[1])):
        m = re.fullmatch(r"\s*([-+]?[0-9.]+(?:[eE][-+]?[0-9]+)?)\s*(\S*)\s*", text)
        if m is None or m.group(2) not in units:
            known = ", ".join(u for u in units if u) or "none"
            raise InputError(f"{option} {text!r}: give a number, optionally with one of these units: {known}")
        value = parse_number(option, m.group(1)) * units[m.group(2)]
        if not rate_in_range(value):
            raise InputError(f"{option} {text!r} is out of range "
                             f"(0, or {MIN_RATE:g} to {MAX_RATE:g} in size)")
        out.append(value)
    return out[0], out[1]


def parse_assignments(option: str, items: list[str]) -> dict[str, float]:
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise InputError(f"{option} expects name=value, got {item!r}")
        out[name.strip()] = parse_number(f"{option} {name.strip()}", value)
    return out


def _solve_file(file: Path, method: str, set_: list[str], guess: list[str], tol: float, rtol: float,
                ftol: float | None, max_iter: int, fd_step: float | None, damped: bool,
                show_jacobian: bool, out_fmt: str, output: Path | None, digits: int,
                plot: Path | None = None, motion: tuple[str | None, str | None] = (None, None),
                branch_wanted: str | None = None, columns: str | None = None) -> None:
    import dataclasses

    from .analysis.convergence import analyze
    from .problems.closed_form import fourbar_facts
    from .problems.loops import load
    from .render.export import result_dict
    from .render.system import branch_label, system_blocks, system_extra, system_solution
    from .solve import SYSTEM_METHODS, solve_system

    if method not in SYSTEM_METHODS:
        raise InputError(f"unknown method {method!r} for a mechanism file; choose from "
                         f"{', '.join(SYSTEM_METHODS)}")
    mechanism = load(file).with_values(parse_assignments("--set", set_),
                                       parse_assignments("--guess", guess))
    note_closed_form(mechanism)
    if branch_wanted is not None:
        mechanism = _start_on_branch(mechanism, branch_wanted, bool(guess))
    speed, accel = parse_motion(*motion, mechanism)
    problem = mechanism.problem()
    # the header says which loops are closed-form and which coupled (solve_system copies meta)
    problem = dataclasses.replace(problem, meta={**problem.meta, "closed_form": mechanism.derivation.summary})
    result = solve_system(problem, method=method, tol=tol, rtol=rtol, ftol=ftol, max_iter=max_iter,
                          fd_step=fd_step, damped=damped, show_jacobian=show_jacobian)
    conv = analyze(result)
    branch = branch_label(problem, result) if result.converged else None
    fourbars = fourbar_facts(mechanism, result.x if result.converged else None)
    blocks = system_blocks(problem, result, conv, digits, branch, fourbars)
    extra = system_extra(problem, result, branch)
    extra["fourbars"] = fourbars
    if result.converged:
        from .kinematics.rates import position_rates
        from .render.rates import rates_blocks, rates_dict

        rates = position_rates(mechanism.model, result.x, mechanism.driver.value, speed, accel)
        extra.update(rates_dict(rates))
        if speed is not None:
            from .render.rates import rate_units_dict

            extra["driver"].update(speed=speed, accel=accel)
            extra["rate_units"] = rate_units_dict(problem.names, problem.kinds, mechanism.length_unit,
                                                  mechanism.driver.kind)
        blocks += rates_blocks(rates, problem.names, problem.kinds, mechanism.length_unit, digits)
        if rates.status != "ok":
            from .render.report import Text

            why = ("velocities and accelerations are undefined here: the Jacobian is singular "
                   "(a toggle or dead-centre position)" if rates.status == "undefined" else
                   f"ill-conditioned here (near a toggle or limit): {', '.join(rates.ill_conditioned)} "
                   "shown with the digits their error bounds leave")
            blocks.append(Text(why, "red"))
    json_obj = result_dict(result, system_solution(problem, result), conv.as_dict() if conv else None,
                           extra)
    h = result.history
    emit(out_fmt, output, blocks=blocks, json_obj=json_obj,
         csv_table=(h.columns, h.rows) if h is not None else ((), ()), columns=columns)
    if plot is not None:
        _convergence_plot([result], plot, problem.title,
                          ", ".join(sorted({problem.step_unit(i) for i in range(problem.n)} - {""})))
    if not result.converged:
        raise typer.Exit(1)


def _start_on_branch(mechanism: Any, branch: str, guessed: bool) -> Any:
    """The mechanism with its guess replaced by the closed form's solution on ``branch``:
    a name at the driver's value (open, crossed, open/crossed, a rocker-driven four-bar's
    second assembly of one name 'open (mirror)') or the signs of the two-way steps (+-),
    as :meth:`~linkage.problems.derive.Derivation.branch_signs` reads them."""
    from .problems.derive import Indeterminate, read_branch, sign_text
    from .problems.loops import ANGLE_UNITS

    if guessed:
        raise InputError("give --branch or --guess, not both")
    derivation = mechanism.derivation
    refusal = derivation.branch_refusal(mechanism.source)
    if refusal:
        hint = "" if derivation.complete else "; choose its assembly with --guess"
        raise InputError(refusal + hint)
    driver = mechanism.driver.value
    at = f"{mechanism.driver.name} = {mechanism.problem().meta['driver_value']:g} {mechanism.driver.unit}"
    try:
        try:
            signs = derivation.branch_signs(branch, driver)
        except Indeterminate:
            raise
        except ValueError:
            signs = None
        q = derivation.solve(driver, signs) if signs is not None else None
        if q is None:
            named = derivation.named_solutions(driver)
    except Indeterminate as exc:
        raise InputError(f"--branch: the closed form is indeterminate at {at} (a change point: {exc}); "
                         "give --guess instead") from None
    if q is None:
        what = f"{branch!r}"
        if signs is not None and branch != sign_text(signs):
            what += f" ({sign_text(signs)})"
        there = (f"assemblies: {', '.join(named)}; or their signs, one per closed-form step with two roots: "
                 f"{', '.join(sign_text(s) for s, _ in named.values())}" if named else
                 "assemblies: none: it cannot be assembled there")
        try:
            read_branch(derivation, branch)
        except ValueError:
            # not a name or sign string of this mechanism at all: not "no such assembly here"
            raise InputError(f"--branch {what} is not a branch of this mechanism "
                             f"(at {at}, {there})") from None
        raise InputError(f"--branch {what}: no such assembly at {at} ({there})")
    return mechanism.with_values({}, {u.name: v / ANGLE_UNITS[u.unit] if u.kind == "angle" else v
                                      for u, v in zip(mechanism.unknowns, q)})


def note_closed_form(mechanism: Any) -> None:
    """Once per command, a one-line note on standard error for a file that still says
    ``closed_form = ...`` (read and checked, but derived from the loops now): kept here,
    printed by :func:`run_cli` when the command ends."""
    note = mechanism.closed_form_note
    if note is not None and note not in _NOTED:
        _NOTED.append(note)


_NOTED: list[str] = []
"""The notes of this command, printed by :func:`run_cli` after its output (emptied as each
command starts: tests run many commands in one process)."""


def _fourbar_coefficients(r1: str | None, r2: str | None, r3: str | None,
                          links: tuple[str, ...] | None) -> tuple[tuple[float, float, float], Any]:
    """(R1, R2, R3) and the link lengths (given, or derived for a unit ground)."""
    from .problems.freudenstein import SEED_R, coefficients_from_links, links_of

    if links is not None:
        if any(v is not None for v in (r1, r2, r3)):
            raise InputError("give either --links or --r1/--r2/--r3, not both")
        lengths = tuple(parse_number(f"link {n}", t) for n, t in zip("abcd", links))
        c = coefficients_from_links(*lengths)
        return (c.r1, c.r2, c.r3), lengths
    rs = tuple(parse_number(n, t) if t is not None else d
               for n, t, d in (("R1", r1, SEED_R[0]), ("R2", r2, SEED_R[1]), ("R3", r3, SEED_R[2])))
    return rs, links_of(*rs)  # type: ignore[arg-type]


def _fourbar_info(alpha: float | None, r1: str | None, r2: str | None, r3: str | None,
                  links: tuple[str, ...] | None, result: Any) -> dict[str, Any]:
    """Both roots in closed form, and the answer in the mechanism-file convention."""
    from .problems.freudenstein import equation_roots, file_convention

    a = 70.0 if alpha is None else alpha
    rs, lengths = _fourbar_coefficients(r1, r2, r3, links)
    roots = equation_roots(a, *rs)
    info: dict[str, Any] = {"alpha": a, "R": list(rs), "roots": roots,
                            "links": list(lengths) if lengths else None, "file_convention": None}
    if lengths and result.converged:
        info["file_convention"] = file_convention(a, result.x, lengths)
        others = [r for r in roots if abs(((r - result.x) + 180.0) % 360.0 - 180.0) > 1e-6]
        info["other_assembly"] = file_convention(a, others[0], lengths) if others else None
    return info


def _fourbar_blocks(info: dict[str, Any], digits: int) -> list[Any]:
    from .render.report import Text, fmt

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


def _scalar_problem(equation: str | None, g: str | None, alpha: float | None, r1: str | None,
                    r2: str | None, r3: str | None, links: tuple[str, ...] | None) -> Any:
    if equation is not None:
        given = [n for n, v in (("--alpha", alpha), ("--r1", r1), ("--r2", r2), ("--r3", r3),
                                ("--links", links)) if v is not None]
        if given:
            raise InputError(f"{', '.join(given)} belong to the four-bar equation; "
                             "they cannot be combined with --equation")
        from .problems.expression import equation_problem

        return equation_problem(equation, g)
    if g is not None:
        raise InputError("--g applies to --equation; the four-bar has its own g = acos(u)")
    from .problems.freudenstein import fourbar_equation

    rs, _ = _fourbar_coefficients(r1, r2, r3, links)
    return fourbar_equation(70.0 if alpha is None else alpha, *rs)


def _applicable(name: str, problem: Any, equation: str | None, x0: Any, x1: Any, bracket: Any) -> bool:
    if equation is None:
        return problem.guess is not None or x0 is not None or bracket is not None
    if name in ("bisection", "regula-falsi", "hybrid"):
        return bracket is not None
    if name == "secant":
        return x0 is not None and x1 is not None
    if name == "fixed-point":
        return x0 is not None and problem.g is not None
    return x0 is not None


def _time_solve(problem: Any, kwargs: dict[str, Any]) -> float:
    """Seconds per solve with recording off, the median of short timed batches."""
    from .solve import solve_scalar

    kw = dict(kwargs, record=False)
    times = []
    for _ in range(5):
        n = 0
        t0 = time.perf_counter()
        while True:
            solve_scalar(problem, **kw)
            n += 1
            dt = time.perf_counter() - t0
            if dt > 0.002:
                break
        times.append(dt / n)
    times.sort()
    return times[len(times) // 2]


# --- sweep ----------------------------------------------------------------------------------

@app.command(
    epilog="Examples:  linkage sweep sample_inputs/fourbar_me581.toml --from 0 --to 359 --step 1  |  "
    "linkage sweep sample_inputs/crank_rocker.toml --branch crossed --format csv -o cycle.csv",
)
def sweep(
    file: Annotated[Optional[Path], typer.Argument(
        metavar="[FILE]", help="A mechanism file (TOML, see sample_inputs/; - reads standard input); "
        "without it, the four-bar input-output equation over alpha.", show_default=False)] = None,
    *,
    start: Annotated[Optional[float], typer.Option("--from", help="First driver value (driver's "
                     "unit; default 0).")] = None,
    stop: Annotated[Optional[float], typer.Option("--to", help="Last driver value (default 360).")] = None,
    r1: Annotated[Optional[str], typer.Option("--r1", help="Without FILE: R1 (default 5/3).")] = None,
    r2: Annotated[Optional[str], typer.Option("--r2", help="Without FILE: R2 (default 5/2).")] = None,
    r3: Annotated[Optional[str], typer.Option("--r3", help="Without FILE: R3 (default 11/6).")] = None,
    links: Annotated[Optional[tuple[str, str, str, str]], typer.Option(
        metavar="A B C D", help="Without FILE: link lengths input, coupler, output, ground.")] = None,
    step: Annotated[Optional[float], typer.Option(help="Driver increment (default 1).")] = None,
    points: Annotated[Optional[int], typer.Option(help="Number of evenly spaced positions "
                      "instead of --step.")] = None,
    method: Annotated[str, typer.Option("--method", "-m", help="newton, newton-fd or lm.")] = "newton",
    branch: Annotated[Optional[str], typer.Option(help="Assembly branch to follow (mechanisms "
                      "whose loops have a closed form), by name or signs as in solve --branch: open, "
                      "crossed, open/crossed for a six-bar, 'open (mirror)', +-; default: the "
                      "branch of the file's guess.")] = None,
    set_: SetOpt = None,
    tol: Annotated[float, typer.Option(help="Step and residual tolerance per position.")] = 1e-12,
    batch: Annotated[Optional[bool], typer.Option("--batch/--no-batch", help="Use the numpy "
                     "batch engine (default: above 20,000 positions; newton only).")] = None,
    plot: Annotated[Optional[Path], typer.Option(help="Also plot the outputs against the driver "
                    "(.png, .svg or .pdf; needs matplotlib).")] = None,
    path: Annotated[Optional[list[str]], typer.Option(
        "--path", metavar="JOINT", help="With --plot: draw the path of this joint or named "
        "point over the sweep instead (a coupler curve; repeatable).")] = None,
    speed: SpeedOpt = None,
    accel: AccelOpt = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    digits: DigitsOpt = 10,
    columns: ColumnsOpt = None,
) -> None:
    """Solve a mechanism over a range of its driver, each position from the previous one.

    Reports every position (converged; no_solution where the linkage cannot be assembled;
    off_branch where it can, but not on the followed branch), the branch, det J, a
    four-bar's transmission angle, the feasible ranges and the limit/toggle positions
    (with --speed, each unknown's rates too). Without FILE:
    the four-bar input-output equation (solve's --r1/--r2/--r3/--links and --method) at
    each alpha from --from to --to, each from the previous root.

    Example: linkage sweep sample_inputs/rapier_drive.toml --step 5

    Example: linkage sweep --from 10 --to 160 --step 30
    """
    from .kinematics.sweep import BATCH_ABOVE, driver_values, sweep_mechanism
    from .problems.loops import load
    from .render.sweep import sweep_blocks, sweep_dict, sweep_headers, sweep_rows
    from .solve import SYSTEM_METHODS, check_criteria, check_number

    out_fmt = choose_format(fmt, output)
    check_paths([file], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    check_criteria(tol, 0.0, None, 50)
    a = check_number("--from", 0.0 if start is None else start)
    b = check_number("--to", 360.0 if stop is None else stop)
    equation_only = {"--r1": r1, "--r2": r2, "--r3": r3, "--links": links}
    if file is None:
        given = [k for k, v in {"--branch": branch, "--set": set_, "--batch": batch, "--path": path,
                                "--speed": speed, "--accel": accel}.items() if v or v == ""]
        if given:
            raise InputError(f"{', '.join(given)} apply to a mechanism FILE")
        _sweep_equation(a, b, step, points, method, r1, r2, r3, links, tol, out_fmt, output, digits, plot)
        return
    given = [k for k, v in equation_only.items() if v is not None]
    if given:
        raise InputError(f"{', '.join(given)} belong to the four-bar equation (sweep without FILE)")
    if step is not None and points is not None:
        raise InputError("give --step or --points, not both")
    if step is not None:
        check_number("--step", step)
    if b < a:
        raise InputError(f"--to ({b:g}) must not be below --from ({a:g})")
    if points is None and step is None:
        step = 1.0
    values = driver_values(a, b, step, points)
    if method not in SYSTEM_METHODS:
        raise InputError(f"unknown method {method!r}; choose from {', '.join(SYSTEM_METHODS)}")
    mechanism = load(file).with_values(parse_assignments("--set", set_ or []), {})
    note_closed_form(mechanism)
    w, a_ = parse_motion(speed, accel, mechanism)
    if path:
        if plot is None:
            raise InputError("--path draws into the --plot file: give --plot PATH.png as well")
        named = [j for loop in mechanism.loops for j in loop.joints if j] + list(mechanism.points)
        for name in path:
            if name not in named:
                raise InputError(f"--path {name}: no joint or point of that name in {file} "
                                 f"(named: {', '.join(dict.fromkeys(named)) or 'none'})")
    if batch is None and len(values) <= BATCH_ABOVE:
        # the numpy engines (closed form, batch) cost a fresh process numpy's import, more
        # than the one-at-a-time sweep of this many positions (the cold-start target)
        batch = False
    with _progress(len(values)) as advance:
        result = sweep_mechanism(mechanism, values, method=method, branch=branch, tol=tol, batch=batch,
                                 progress=advance, speed=w, accel=a_,
                                 joints=out_fmt in ("csv", "json") or bool(path))
    emit(out_fmt, output, blocks=sweep_blocks(result, digits), json_obj=sweep_dict(result),
         columns=columns,
         csv_table=(sweep_headers(result), sweep_rows(result)))
    if plot is not None:
        from .render.plots import path_plot, sweep_plot

        if path:
            path_plot(result, mechanism, path, plot)
        else:
            sweep_plot(result, plot)
        typer.echo(f"wrote {plot}", err=True)
    if result.summary.get("failed"):
        raise typer.Exit(1)


def _sweep_equation(a: float, b: float, step: float | None, points: int | None, method: str,
                    r1: str | None, r2: str | None, r3: str | None, links: Any, tol: float, out_fmt: str,
                    output: Path | None, digits: int, plot: Path | None) -> None:
    """The four-bar input-output equation over alpha: seed 002's table, each alpha solved
    from the previous alpha's root (the first from the equation's own default start).

    Where the closed form (freudenstein.equation_roots) has no real root the position is
    no_solution and continuation restarts after it. A run from the tangent prediction
    can start within rounding of the root; Newton then steps between the root's
    neighbouring floats with |f| at its rounding floor, and the loop's best-residual guard
    (scaled by the start's residual, itself at that floor) never lets the step test pass:
    such a run, stopped with its last step within the tolerance, is judged by the solver's
    own root certificate (solve.certify_root: |f| within its rounding bound, or a sign
    change across x +- tol)."""
    from .kinematics.sweep import driver_values
    from .methods import BRACKETING, SCALAR_METHODS
    from .problems.freudenstein import equation_roots
    from .render.report import Text, table
    from .result import Status
    from .solve import certify_root, solve_scalar

    if method not in SCALAR_METHODS:
        raise InputError(f"unknown method {method!r}; choose from {', '.join(SCALAR_METHODS)}")
    if plot is not None:
        raise InputError("--plot draws mechanism sweeps; without FILE use --format csv")
    if step is not None and points is not None:
        raise InputError("give --step or --points, not both")
    if b < a:
        raise InputError(f"--to ({b:g}) must not be below --from ({a:g})")
    values = driver_values(a, b, step if step is not None or points is not None else 1.0, points)
    if len(values) > 100_000:
        raise InputError(f"{len(values):,} values of alpha is more than 100,000; use a larger --step")
    first = _scalar_problem(None, None, values[0], r1, r2, r3, links)
    coeffs = first.title  # "..., R1 = ..., R2 = ..., R3 = ..." for the table's heading
    rs, _ = _fourbar_coefficients(r1, r2, r3, links)
    rows: list[tuple[Any, ...]] = []
    previous: tuple[float, float] | None = None  # (alpha, phi) of the last root on the branch

    def solve_at(alpha: float, guess: float | None) -> Any:
        problem = _scalar_problem(None, None, alpha, r1, r2, r3, links)
        kw: dict[str, Any] = dict(method=method, tol=tol, max_iter=200, record=False)
        if guess is None:
            if problem.guess is None:
                # roots closer together than the default start's 10-degree grid (near a
                # limit position): the closed form's, the first in [0, 180] as that grid
                # would find it
                roots = equation_roots(alpha, *rs)
                if not roots:
                    return None
                guess = min(roots, key=lambda p: (p < 0.0, p))
            elif method in BRACKETING:
                return solve_scalar(problem, bracket=problem.guess, **kw)
            else:
                # an open method starts inside the first bracket with a sign change, so
                # every method anchors on the same root (the seed's branch)
                guess = 0.5 * (problem.guess[0] + problem.guess[1])
        if method in BRACKETING:
            width = 0.5
            while width < 90.0:  # the nearest bracket around the prediction
                lo, hi = guess - width, guess + width
                if (problem.f(lo) < 0.0) != (problem.f(hi) < 0.0):
                    return solve_scalar(problem, bracket=(lo, hi), **kw)
                width *= 2.0
            return None
        kw["x0"] = guess
        if method == "secant":
            kw["x1"] = guess + 1e-3
        return certified(problem, solve_scalar(problem, **kw))

    def certified(problem: Any, r: Any) -> Any:
        """The run; or, where it stopped unconverged with its last step within the
        tolerance, the solver's root certificate's verdict on its last iterate; or, where
        f is zero to its rounding but the steps stay above the tolerance (f' so small that
        rounding moves the root by more), precision_limit."""
        from dataclasses import replace

        if r.converged or r.status not in (Status.MAX_ITER, Status.STALLED, Status.PRECISION_LIMIT):
            return r
        if r.error <= tol:
            verdict, why, n = certify_root(problem, r.x, r.residual, tol)
            if verdict is Status.CONVERGED_STEP:
                return replace(r, status=verdict, nfev=r.nfev + n,
                               detail=why or f"certified after {r.status.value}: the last step is "
                                             "within the tolerance and f is zero to its rounding")
        elif isinstance(r.residual, float) and abs(r.residual) <= problem.fbound(r.x):
            return replace(r, status=Status.PRECISION_LIMIT,
                           detail=f"f is zero to its rounding, but rounding moves the root by about "
                                  f"{r.error:.1g} deg, above the tolerance {tol:g}")
        return r

    def slope(alpha: float, phi: float) -> float:
        """dphi/dalpha on the branch: -(df/dalpha) / (df/dphi), both per degree."""
        p = _scalar_problem(None, None, alpha, r1, r2, r3, links)
        d = math.pi / 180.0
        h = 1e-6
        dfa = (_scalar_problem(None, None, alpha + h, r1, r2, r3, links).f(phi) - p.f(phi)) / h
        dfp = p.fprime(phi) if p.fprime is not None else d
        return -dfa / dfp if dfp else 0.0

    for alpha in values:
        r = None
        if not equation_roots(alpha, *rs):
            rows.append((alpha, "no_solution", None, 0, None))
            previous = None
            continue
        if previous is None:
            r = solve_at(alpha, None)
        else:
            # walk from the last root in steps of at most 2 degrees, predicting along the
            # tangent: the other root of the equation is never reached by a jump
            a0, phi = previous
            n = max(1, math.ceil(abs(alpha - a0) / 2.0))
            for k in range(1, n + 1):
                ak = a0 + (alpha - a0) * k / n
                ap = a0 + (alpha - a0) * (k - 1) / n
                r = solve_at(ak, phi + slope(ap, phi) * (ak - ap))
                if r is None or not r.converged:
                    break
                phi = r.x
        if r is None:
            # roots exist (above), but no sign change near the prediction for a bracketing
            # method: a double root, at a limit position
            rows.append((alpha, Status.INVALID_BRACKET.value, None, 0, None))
            previous = None
            continue
        if r.converged:
            previous = (alpha, r.x)
        rows.append((alpha, r.status.value, r.x if r.converged else None, r.iterations, r.residual))
    headers = ("alpha (deg)", "status", "phi (deg)", "iterations", "f(phi)")
    blocks: list[Any] = [
        Text(f"four-bar input-output equation over alpha ({method}, each from the previous root): "
             f"{coeffs.split(', ', 2)[2] if coeffs.count(', ') >= 2 else coeffs}", "bold"),
        Text(""), table("", headers, rows, digits)]
    json_obj = {"equation": "f(phi) = R1 cos(alpha) - R2 cos(phi) + R3 - cos(alpha - phi)",
                "method": method, "tol": tol,
                "positions": [dict(zip(("alpha", "status", "phi", "iterations", "residual"), r))
                              for r in rows]}
    emit(out_fmt, output, blocks=blocks, json_obj=json_obj, csv_table=(headers, rows))
    # as a mechanism sweep: where the linkage cannot be assembled is an answer, not a failure
    if any(r[2] is None and r[1] != "no_solution" for r in rows):
        raise typer.Exit(1)


@app.command(
    epilog="Examples:  linkage scan sample_inputs/crank_rocker.toml --vary r2=20:60:9 --vary r3=80:160:9 "
    "--where 'full_cycle and min_transmission_deg >= 40' --sort theta4_range --desc --top 10  |  "
    "linkage scan sample_inputs/crank_rocker.toml --vary r2=20:60 --vary r4=50:120 --samples 100000 "
    "-o designs.parquet",
)
def scan(
    file: MechanismFile,
    *,
    vary: Annotated[Optional[list[str]], typer.Option(
        "--vary", metavar="NAME=LO:HI[:N]", help="A parameter to vary, in the file's units "
        "(repeatable): N points from LO to HI (a grid of every combination), or LO:HI with "
        "--samples.")] = None,
    samples: Annotated[Optional[int], typer.Option(help="Draw this many random designs in the "
                       "--vary ranges instead of a grid.")] = None,
    sampling: Annotated[str, typer.Option(help="With --samples: lhs (Latin hypercube, default) "
                        "or random.")] = "lhs",
    seed: Annotated[int, typer.Option(help="With --samples: the random seed (same seed, same "
                    "designs).")] = 0,
    start: Annotated[Optional[float], typer.Option("--from", help="First driver value (default 0).")] = None,
    stop: Annotated[Optional[float], typer.Option("--to", help="Last driver value (default 359).")] = None,
    step: Annotated[float, typer.Option(help="Driver increment (default 1).", show_default=False)] = 1.0,
    branch: Annotated[Optional[str], typer.Option(help="Assembly branch every design follows: "
                      "open or crossed (mechanisms with a closed form); default: the branch of "
                      "the file's guess.")] = None,
    set_: SetOpt = None,
    tol: Annotated[float, typer.Option(help="Step and residual tolerance per position.")] = 1e-12,
    where: Annotated[Optional[str], typer.Option(metavar="TEST", help="Keep designs passing this "
                     "test of their columns, e.g. \"full_cycle and min_transmission_deg >= 40\" "
                     "(numbers, + - * / **, functions, comparisons, and, or, not).")] = None,
    sort: Annotated[Optional[str], typer.Option(metavar="COLUMN", help="Order the kept designs "
                    "by this column (ascending; NaN last).")] = None,
    desc: Annotated[bool, typer.Option("--desc", help="With --sort: largest first.")] = False,
    top: Annotated[Optional[int], typer.Option(metavar="K", help="Keep only the first K designs (after "
                   "--where and --sort). A table shows 20 unless given.")] = None,
    scheduler: Annotated[Optional[str], typer.Option(help="Where the chunks run: threads "
                         "(default), processes, synchronous, or tcp://HOST:PORT (a "
                         "dask.distributed scheduler).")] = None,
    workers: Annotated[Optional[int], typer.Option(help="Local workers (default: one per "
                       "core).")] = None,
    chunk: Annotated[Optional[int], typer.Option(help="Designs per task (default: about "
                     "200,000 positions per task).")] = None,
    fmt: Annotated[Optional[str], typer.Option("--format", "-f", help="table (default on a "
                   "terminal), plain, csv, json or parquet; -o FILE picks by suffix.")] = None,
    output: OutputOpt = None,
    digits: DigitsOpt = 6,
    columns: ColumnsOpt = None,
) -> None:
    """Scan a range of designs: each over its whole cycle, one record per design.

    Each record: the varied parameters, feasible_fraction (positions where an assembly
    exists), solved_fraction (positions solved on the followed branch), full_cycle, every
    unknown's _min, _max and _range, for four-bars grashof and min/max_transmission_deg
    (folded into 0..90), and the x/y extents of each [points] path.

    Example: linkage scan sample_inputs/crank_rocker.toml --vary r2=20:60:5 --vary r4=60:120:7
    """
    from .arguments import check_scan_options
    from .files import read_input
    from .kinematics.sweep import driver_values
    from .problems.loops import from_text
    from .render.scan import RecordSink, scan_blocks
    from .scan import (
        MAX_DESIGNS,
        Keeper,
        ScanJob,
        check_held,
        feed,
        parse_vary,
        pick_chunk,
        prepare,
    )
    from .solve import check_criteria

    if output is not None and str(output) == "-":
        output = None
    if fmt is None:
        suffix = output.suffix.lower() if output is not None else ""
        fmt = {".csv": "csv", ".json": "json", ".parquet": "parquet"}.get(suffix) or (
            "table" if output is None and sys.stdout.isatty() else "plain")
    if fmt not in ("table", "plain", "csv", "json", "parquet"):
        raise InputError(f"unknown format {fmt!r} for scan; use table, plain, csv, json or parquet")
    check_paths([file], [("--output", output)])
    check_criteria(tol, 0.0, None, 50)
    check_scan_options(seed=seed, samples=samples, top=top, chunk=chunk, workers=workers,
                       scheduler=scheduler, max_designs=MAX_DESIGNS, prefix="--")
    if not vary:
        raise InputError("give at least one --vary NAME=LO:HI[:N]")
    varies = [parse_vary(v) for v in vary]
    text = read_input(file)
    fixed = parse_assignments("--set", set_ or [])
    both = sorted({v.name for v in varies} & set(fixed))
    if both:
        raise InputError(f"{both[0]} is given by --set and by --vary; a scanned parameter takes its "
                         "values from --vary only")
    mechanism = from_text(text, str(file)).with_values(fixed, {})
    note_closed_form(mechanism)
    angle = mechanism.driver.kind == "angle"
    if not angle and (start is None or stop is None):
        raise InputError(f"{mechanism.driver.name} is a length: give --from and --to")
    a = 0.0 if start is None else start
    b = 359.0 if stop is None else stop
    if b < a:
        raise InputError(f"--to ({b:g}) must not be below --from ({a:g})")
    setup = prepare(mechanism, varies, samples=samples, seed=seed, sampling=sampling,
                    values=driver_values(a, b, step, None), branch=branch, tol=tol, where=where, sort=sort)
    plan, spec, test, chosen, values = setup.plan, setup.spec, setup.where, setup.branch, setup.values
    if columns:
        wanted = [w.strip().lower() for w in columns.split(",") if w.strip()]
        picked = [c for c in spec[1:] if any(c[0].lower().startswith(w) for w in wanted)]
        if not picked:
            raise InputError(f"--columns {columns!r} matches no column; the columns are "
                             f"{', '.join(c[0] for c in spec)}")
        spec = [spec[0], *picked]
    if desc and sort is None:
        raise InputError("--desc orders by --sort: give --sort COLUMN")
    if sort is not None and fmt not in ("table", "plain"):
        check_held(plan.total, len(setup.spec), top, f"--sort {sort} with --format {fmt}")
    overrides = tuple((k, float(v)) for k, v in fixed.items())
    job = ScanJob(text, str(file), overrides, plan.names, tuple(values), chosen, tol)
    size = pick_chunk(mechanism, len(values), chosen, chunk, plan.total)
    as_table = fmt in ("table", "plain")
    meta = {"mechanism": mechanism.name, "source": str(file), "branch": chosen,
            "driver": {"name": mechanism.driver.name, "unit": mechanism.driver.unit, "from": a,
                       "to": b, "step": step, "positions": len(values)},
            "where": where, "sort": sort, "descending": desc, "designs": plan.total}
    sink = None if as_table else RecordSink(fmt, output, spec, meta)
    started = time.perf_counter()
    with contextlib.ExitStack() as stack:
        if sink is not None:
            stack.enter_context(sink)
        keeper = Keeper(sort, desc, top, sink if (sink is not None and sort is None) else None,
                        show=20 if as_table else None)
        advance = stack.enter_context(_progress(plan.total, minimum=2 * size))
        scanned = feed(keeper, job, setup, size, scheduler=scheduler, workers=workers, progress=advance)
        held = keeper.result()
        if sink is not None and sort is not None:
            sink(held)
    elapsed = time.perf_counter() - started
    from .kinematics.designs import ENGINES, engine_for

    engine = ENGINES[engine_for(mechanism, chosen)]
    where_note = f"; {keeper.kept:,} pass --where" if test is not None else ""
    branch_shown = chosen or "the one the file's guess is on"
    stopped = f" (stopped early: the first {top} are final)" if scanned < plan.total else ""
    summary = [f"{mechanism.name}: {scanned:,} of {plan.total:,} designs scanned{stopped}"
               f"{where_note}; {elapsed:.2f} s",
               f"{len(values)} positions each ({mechanism.driver.name} {a:g}..{b:g} "
               f"{mechanism.driver.unit}, step {step:g}); branch: {branch_shown}; "
               f"engine: {engine}"]
    if as_table:
        n_held = len(held["design"]) if held else 0
        if n_held < keeper.kept:
            summary.append(f"showing {n_held} of {keeper.kept:,}"
                           + (f" by {sort}{' (largest first)' if desc else ''}" if sort else "")
                           + "; --top K or --format csv/json/parquet for more")
        emit(fmt, output, blocks=scan_blocks(held, spec, summary, digits), json_obj=None,
             csv_table=([], []))
    else:
        typer.echo(f"{summary[0]}; wrote {sink.count:,} records" +  # type: ignore[union-attr]
                   (f" to {output}" if output is not None else ""), err=True)


@app.command(
    epilog="Examples:  linkage draw sample_inputs/rapier_drive.toml -o rapier.svg  |  "
    "linkage draw sample_inputs/crank_rocker.toml --animate crank.gif --step 10",
)
def draw(
    file: MechanismFile,
    *,
    output: Annotated[Optional[Path], typer.Option("--output", "-o", help="The drawing at the "
                      "file's driver value (.png, .svg or .pdf).")] = None,
    animate: Annotated[Optional[Path], typer.Option(help="A GIF of the mechanism over a sweep of "
                       "its driver (--from, --to, --step).")] = None,
    set_: SetOpt = None,
    start: Annotated[float, typer.Option("--from", help="Animation: first driver value.")] = 0.0,
    stop: Annotated[float, typer.Option("--to", help="Animation: last driver value.")] = 360.0,
    step: Annotated[float, typer.Option(help="Animation: driver increment per frame.")] = 5.0,
) -> None:
    """Draw a mechanism from its joint coordinates, links and joints labelled.

    Example: linkage draw sample_inputs/fourbar_me581.toml --set theta2=80 -o fourbar.png
    """
    from .kinematics.sweep import driver_values
    from .kinematics.sweep import sweep as run_sweep
    from .problems.loops import load
    from .solve import check_number, solve_system

    if output is None and animate is None:
        raise InputError("give -o PATH for a drawing, --animate PATH.gif for an animation, or both")
    check_paths([file], [("--output", output), ("--animate", animate)],
                {"--output": (output, PICTURES), "--animate": (animate, (".gif",))})
    mechanism = load(file).with_values(parse_assignments("--set", set_ or []), {})
    note_closed_form(mechanism)
    if output is not None:
        from .render.plots import draw_mechanism

        problem = mechanism.problem()
        result = solve_system(problem, tol=1e-12, record=False)
        if not result.converged:
            typer.echo(f"error: cannot draw {file} at {problem.title}: {result.message}", err=True)
            raise typer.Exit(1)
        draw_mechanism(mechanism, result.x, output, problem.title)
        typer.echo(f"wrote {output}", err=True)
    if animate is not None:
        from .render.plots import animate_sweep

        a, b = check_number("--from", start), check_number("--to", stop)
        if not check_number("--step", step) > 0 or b < a:
            raise InputError("--step must be > 0 and --to must not be below --from")
        values = driver_values(a, b, step, None)
        if len(values) > 2000:
            raise InputError(f"{len(values)} frames is too many for a GIF; use a larger --step")
        s = run_sweep(mechanism, values)
        scale = math.pi / 180.0 if mechanism.driver.kind == "angle" else 1.0
        frames = [(p.input * scale,
                   [math.radians(p.solution[u.name]) if u.kind == "angle" else p.solution[u.name]
                    for u in mechanism.unknowns]) for p in s.positions if p.solution]
        if not frames:
            typer.echo(f"error: no position of {file} between {a:g} and {b:g} could be solved", err=True)
            raise typer.Exit(1)
        with _progress(len(frames), minimum=1) as advance:
            animate_sweep(mechanism, frames, animate, progress=advance)
        typer.echo(f"wrote {animate} ({len(frames)} frames)", err=True)


@app.command(
    epilog="Examples:  linkage samples  |  linkage samples crank_rocker -o my_linkage.toml  |  "
    "linkage samples watt_sixbar | linkage solve -",
)
def samples(
    name: Annotated[Optional[str], typer.Argument(metavar="[NAME]", help="A sample to print (or write "
                    "with -o), e.g. crank_rocker.", show_default=False)] = None,
    *,
    output: Annotated[Optional[Path], typer.Option("--output", "-o", help="Write the sample to this "
                      "new file (an existing file is never replaced).")] = None,
) -> None:
    """List the mechanism files shipped with linkage, or copy one out to start your own.

    Example: linkage samples crank_rocker -o my_linkage.toml
    """
    from .samples import find_sample
    from .samples import samples as shipped

    if name is None:
        if output is not None:
            raise InputError("give the NAME of the sample to write with -o")
        from .render.report import Text

        listing = shipped()
        width = max((len(k) for k in listing), default=0)
        emit("table" if sys.stdout.isatty() else "plain", None,
             blocks=[*(Text(f"{k.ljust(width)}  {v}") for k, v in listing.items()), Text(""),
                     Text("print one with `linkage samples NAME`, or copy it with "
                          "`linkage samples NAME -o FILE`")],
             json_obj=listing, csv_table=(("sample", "what it is"), list(listing.items())))
        return
    text = find_sample(name).read_text(encoding="utf-8")
    if output is None or str(output) == "-":
        with _stdout_errors():
            sys.stdout.write(text)
            sys.stdout.flush()
        return
    if output.exists() or output.is_symlink():
        raise InputError(f"{output} exists; choose a new file name (samples never replace a file)")
    check_paths([], [("--output", output)])
    from .files import write_atomic

    write_atomic(output, text)
    typer.echo(f"wrote {output}", err=True)


@app.command(
    epilog="Examples:  linkage stress --quick  |  linkage stress --seed 7 --method hybrid --format json",
)
def stress(
    *,
    quick: Annotated[bool, typer.Option("--quick", help="A third of the classic cases and fewer "
                     "random mechanisms (seconds instead of minutes).")] = False,
    seed: Annotated[int, typer.Option(help="Seed for the random families (runs are "
                    "deterministic for a seed).")] = 0,
    method: Annotated[Optional[list[str]], typer.Option("--method", "-m", help="Only these "
                      "methods (repeatable).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
) -> None:
    """Try to break every method (test functions, random four-bars, bad starts, tiny tolerances).

    Runs classic test functions, random four-bars, the MGH systems, bad starts, tiny
    tolerances and non-finite values; a claimed root that is not one fails the run.

    Example: linkage stress --quick
    """
    from .methods import SCALAR_METHODS
    from .render.report import Text, table
    from .solve import SYSTEM_METHODS
    from .stress import SUMMARY_HEADERS, run, summary_rows, totals

    known = set(SCALAR_METHODS) | set(SYSTEM_METHODS)
    for m in method or []:
        if m not in known:
            raise InputError(f"unknown method {m!r}; choose from {', '.join(sorted(known))}")
    out_fmt = choose_format(fmt, output)
    check_paths([], [("--output", output)])
    try:
        import mpmath  # noqa: F401
    except ImportError:
        raise InputError("the stress suite needs mpmath for its references: "
                         "pip install 'linkage-kinematics[stress]'") from None
    report = run(quick=quick, seed=seed, methods=method or None)
    rows = summary_rows(report)
    false, crashes = totals(rows)
    blocks: list[Any] = [
        Text(f"stress battery ({'quick' if quick else 'full'}, seed {seed}): {sum(r[2] for r in rows)} runs "
             f"in {report['seconds']:.1f} s", "bold"),
        Text(""),
        table("", SUMMARY_HEADERS, rows, 4),
        Text(f"false convergences: {false}; crashes: {crashes} (ours; scipy rows are a reference)",
             "green" if not false + crashes else "red"),
    ]
    h = report["hybrid"]
    if h:
        blocks.append(Text(f"hybrid on the bracketed classic cases: {h['within_4_eps']} of {h['cases']} "
                           "converged within 4 machine epsilons of the reference (or to an exact zero); "
                           f"{h['hybrid_iterations']} iterations in all, against {h['bisection_iterations']} "
                           "for bisection"))
    for (family, m), t in sorted(report["tallies"].items()):
        if m.startswith("scipy"):
            continue
        for e in t.examples[:5]:
            blocks.append(Text(f"  {family}/{m}: {e}", "red"))
    json_obj = {"seed": seed, "quick": quick, "seconds": report["seconds"],
                "summary": [dict(zip(SUMMARY_HEADERS, r)) for r in rows],
                "false_convergences": false, "crashes": crashes,
                "hybrid": ({**{k: v for k, v in h.items() if k not in ("rows", "failures")},
                            "cases_detail": [{"case": n, "within_4_eps": ok, "hybrid_iterations": hi,
                                              "bisection_iterations": bi, "hybrid_status": st}
                                             for n, ok, hi, bi, st in h["rows"]]} if h else None)}
    emit(out_fmt, output, blocks=blocks, json_obj=json_obj, csv_table=(SUMMARY_HEADERS, rows))
    if false or crashes:
        raise typer.Exit(1)


@app.command(
    epilog="Examples:  linkage bench --quick  |  linkage bench --problem fourbar --plot wp.png  |  "
    "linkage bench --format csv -o bench.csv",
)
def bench(
    *,
    quick: Annotated[bool, typer.Option("--quick", help="Two problems, three tolerances, short "
                     "timings (about 10 seconds).")] = False,
    problem: Annotated[Optional[list[str]], typer.Option(help="seed002, quadratic, fourbar, rapier "
                       "(repeatable; default: all, or seed002 and fourbar with --quick).")] = None,
    repeats: Annotated[Optional[int], typer.Option(help="Timed batches per measurement "
                       "(default 3, or 5 without --quick).")] = None,
    cold: Annotated[bool, typer.Option("--cold/--no-cold", help="Also time cold starts of the "
                    "CLI in fresh interpreters.")] = True,
    plot: Annotated[Optional[Path], typer.Option(help="Work-precision diagram: log10 error against "
                    "log10 time (.png, .svg or .pdf; needs matplotlib).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
) -> None:
    """Run time against achieved error for every method, beside scipy and a hand-written loop.

    Example: linkage bench --quick --plot wp.png
    """
    from .bench import (
        FULL_TOLERANCES,
        PROBLEMS,
        QUICK_TOLERANCES,
        cold_start,
        has_pylinkage,
        has_scipy,
        measure,
        sweep_times,
        targets,
    )
    from .render.report import Text, table

    out_fmt = choose_format(fmt, output)
    check_paths([], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    names = problem or (["seed002", "fourbar"] if quick else list(PROBLEMS))
    for name in names:
        if name not in PROBLEMS:
            raise InputError(f"unknown problem {name!r}; choose from {', '.join(PROBLEMS)}")
    n_repeats = repeats if repeats is not None else (3 if quick else 5)
    if n_repeats < 1:
        raise InputError(f"--repeats must be >= 1, got {n_repeats}")
    try:
        import mpmath  # noqa: F401
    except ImportError:
        raise InputError("the benchmark needs mpmath for its references: "
                         "pip install 'linkage-kinematics[bench]'") from None
    tolerances = QUICK_TOLERANCES if quick else FULL_TOLERANCES
    budget = 0.01 if quick else 0.015
    from .bench import count_measurements

    with _progress(count_measurements(names, tolerances), minimum=1) as advance:
        done = [0]

        def step(_: str) -> None:
            done[0] += 1
            if advance is not None:
                advance(done[0])

        results = measure(names, tolerances, n_repeats, budget, progress=step)
    cold_times = cold_start(3 if quick else 5) if cold else {}
    sweeps = sweep_times(n_repeats, 100_000 if quick else 1_000_000)
    target_rows = targets(results, cold_times, sweeps)
    headers = ("problem", "contender", "tol", "time per solve (us)", "fastest batch (us)",
               "slowest batch (us)", "error", "iterations",
               "evaluations")
    rows = [(m.problem, m.contender, m.tol, m.seconds * 1e6,
             m.spread[0] * 1e6, m.spread[1] * 1e6, m.error, m.iterations, m.nfev)
            for m in results]
    blocks: list[Any] = [Text(f"work-precision benchmark: {len(results)} measurements, {n_repeats} timed "
                              "batches each (median; spread = fastest-slowest batch)", "bold")]
    if not has_scipy():
        blocks.append(Text("scipy is not installed: its rows are skipped "
                           "(pip install 'linkage-kinematics[bench]')"))
    if not has_pylinkage():
        blocks.append(Text("pylinkage is not installed: the sweep comparison is skipped "
                           "(pip install 'pylinkage==1.3.0')"))
    blocks += [Text(""), table("", headers, rows, 4)]
    blocks.append(table("Sweeps (median seconds)", ("sweep", "seconds"), list(sweeps.items()), 4))
    if cold_times:
        blocks.append(table("Cold start (fresh interpreter, median wall time)", ("command", "seconds"),
                            list(cold_times.items()), 4))
    blocks.append(table("Targets (ratios measured in this run)", ("target", "ratio", "measured", "met"),
                        [(t, c, r, "n/a" if r is None or r != r or ok is None else ("yes" if ok else "no"))
                         for t, c, r, ok in target_rows], 3))
    json_obj = {"measurements": [dict(zip(headers, r)) for r in rows], "cold_start": cold_times,
                "sweeps": sweeps,
                "targets": [{"target": t, "ratio": c, "measured": r, "met": ok}
                            for t, c, r, ok in target_rows],
                "scipy": has_scipy()}
    emit(out_fmt, output, blocks=blocks, json_obj=json_obj, csv_table=(headers, rows))
    if plot is not None:
        from .render.plots import work_precision_plot

        work_precision_plot(results, plot)
        typer.echo(f"wrote {plot}", err=True)


class _progress:
    """A rich progress bar on a terminal for long runs; nothing when piped."""

    def __init__(self, total: int, minimum: int = 2000) -> None:
        self.total = total
        self.minimum = minimum
        self.bar: Any = None

    def __enter__(self) -> Any:
        if self.total < self.minimum or not sys.stderr.isatty():
            return None
        from rich.progress import Progress

        self.bar = Progress(transient=True)
        self.bar.start()
        task = self.bar.add_task("solving", total=self.total)
        return lambda done: self.bar.update(task, completed=done)

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.stop()


# --- entry point ----------------------------------------------------------------------------

def _reflow(doc: str) -> str:
    """A docstring as help text: each paragraph one line (rich keeps single line breaks,
    so hard-wrapped source lines would break mid-sentence at any width), and square
    brackets escaped (rich would read "[points]" as a style)."""
    import inspect

    paragraphs = inspect.cleandoc(doc).split("\n\n")
    return "\n\n".join(" ".join(line.strip() for line in p.splitlines()).replace("[", "\\[")
                       for p in paragraphs)


for _command in app.registered_commands:
    if _command.help is None and _command.callback is not None and _command.callback.__doc__:
        _command.help = _reflow(_command.callback.__doc__)


def _app_for(args: list[str]) -> typer.Typer:
    """The app with only the command this run names: typer builds the parser of every
    registered command (signature, type hints, options) before it dispatches, and a run
    uses one. Anything else (no command, an option first, a misspelt name) gets the
    whole app, whose help and "No such command" list them all."""
    if not args or args[0].startswith("-"):
        return app
    chosen = [c for c in app.registered_commands if c.callback is not None and
              (c.name or c.callback.__name__) == args[0]]
    if not chosen:
        return app
    lean = copy.copy(app)
    lean.registered_commands = chosen
    return lean


def run_cli(argv: list[str] | None = None) -> int:
    """Run the app and turn every error into one stderr line and an exit code; the notes
    a command made (:func:`note_closed_form`) follow its output when it ran (exit 0 or 1),
    not when it was refused or stopped (the error is then the one line)."""
    args = list(sys.argv[1:] if argv is None else argv)
    _NOTED.clear()  # each command says its notes once
    code = _run_command(args)
    if code in (0, 1):
        for note in _NOTED:
            typer.echo(_for_stderr(f"note: {note}"), err=True)
    return code


def _for_stderr(line: str) -> str:
    """A message as one line, or wrapped at words to a terminal's width (a person's
    terminal would otherwise fold it anywhere, mid-word or mid-path)."""
    if not sys.stderr.isatty():
        return line
    import shutil
    import textwrap

    width = shutil.get_terminal_size().columns
    return "\n".join(textwrap.wrap(line, width, subsequent_indent="  ", break_long_words=False,
                                    break_on_hyphens=False)) if len(line) > width else line


def _run_command(args: list[str]) -> int:
    try:
        rv = _app_for(args)(args=args, prog_name="linkage", standalone_mode=False)
    except typer.Exit as exc:
        return exc.exit_code
    except typer.Abort:
        typer.echo("error: aborted", err=True)
        return 1
    except LinkageError as exc:
        typer.echo(f"error: {exc}", err=True)
        return 2
    except KeyboardInterrupt:
        return _interrupted()
    except BrokenPipeError:
        typer.echo("error: cannot write to standard output: the pipe was closed", err=True)
        return 2
    except _StdoutClosed as exc:  # help or version text on a closed standard output
        typer.echo(f"error: cannot write to standard output: {exc.strerror}", err=True)
        return 2
    except RecursionError:
        typer.echo("error: the input is nested too deeply to read", err=True)
        return 2
    except MemoryError:
        typer.echo("error: out of memory: the input asks for more than this machine has", err=True)
        return 2
    except Exception as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":
            return 0  # bare `linkage`: the help was the answer
        if hasattr(exc, "format_message") and hasattr(exc, "exit_code"):
            # A usage error from typer's (or click's) parser: bad option, bad value.
            message = " ".join(exc.format_message().split())
            typer.echo(f"error: {message}", err=True)
            return 2
        typer.echo(f"internal error: {type(exc).__name__}: {exc} (please report this)", err=True)
        return 1
    if rv == 130:
        # typer turns Ctrl-C into a silent return of 130 (no command returns a number)
        return _interrupted()
    return rv if isinstance(rv, int) else 0


_terminated: list[int] = []
"""The signal number once SIGTERM arrived (see :func:`_on_sigterm`)."""


def _on_sigterm(signum: int, frame: Any) -> None:
    """SIGTERM is handled as Ctrl-C is: the KeyboardInterrupt unwinds every open output
    (files.atomic_target removes its partial file), then one line and 128 + 15."""
    _terminated.append(signum)
    raise KeyboardInterrupt


def _interrupted() -> int:
    if _terminated:
        typer.echo("error: terminated", err=True)
        return 128 + _terminated[0]
    typer.echo("error: interrupted", err=True)
    return 130


def _standard_streams() -> None:
    """A closed standard stream (``>&-``, ``<&-``) gets /dev/null on its descriptor, so no
    file opened later takes its number; standard output then refuses every write (one
    error line, exit 2) and standard input reads as closed (sys.stdin stays None)."""
    import io
    import os

    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
            continue
        except OSError:
            pass
        null = os.open(os.devnull, os.O_RDWR)
        if null != fd:
            os.dup2(null, fd)
            os.close(null)
        if fd == 1:
            sys.stdout = _ClosedStdout()
        elif fd == 2:
            sys.stderr = io.TextIOWrapper(io.FileIO(2, "w", closefd=False), write_through=True)


class _StdoutClosed(OSError):
    """A write to a standard output that was closed before the run."""


class _ClosedStdout:
    """Standard output that was closed before the run: every write fails as a closed
    descriptor does."""

    def write(self, text: str) -> int:
        import errno
        import os

        raise _StdoutClosed(errno.EBADF, os.strerror(errno.EBADF) + " (standard output is closed)")

    def fileno(self) -> int:
        return self.write("")  # descriptor 1 is /dev/null now: writing there would lose output

    def flush(self) -> None:
        return None

    def isatty(self) -> bool:
        return False


def main() -> None:
    import signal

    _standard_streams()
    with contextlib.suppress(ValueError, OSError):  # not the main thread, or no signals
        signal.signal(signal.SIGTERM, _on_sigterm)
    code = run_cli()
    try:
        sys.stdout.flush()
    except OSError:
        # stdout is gone (closed pipe, full disk): say nothing more when Python exits
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        if code == 0:
            typer.echo("error: cannot write to standard output", err=True)
            code = 2
    sys.exit(code)
