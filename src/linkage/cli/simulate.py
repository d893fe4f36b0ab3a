"""linkage simulate."""

import re
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from .options import (
    PICTURES,
    ColumnsOpt,
    DigitsOpt,
    FormatOpt,
    GravityOpt,
    LoadOpt,
    MechanismFile,
    OutputOpt,
    TableOpt,
    TorqueOpt,
    check_paths,
    choose_format,
    emit_report,
    note_exit_reasons,
)
from .root import app


def _span(text: str) -> tuple[float, float]:
    from ..numbers import parse_number

    start, colon, end = text.partition(":")
    if not colon:
        raise InputError(f"--time {text!r}: give START:END in s, e.g. 0:2")
    a, b = parse_number("--time", start), parse_number("--time", end)
    if not b > a:
        raise InputError(f"--time {text!r}: END must be after START")
    return a, b


def _constants(items: list[str]) -> dict[str, float]:
    from ..numbers import parse_number

    out = {}
    for item in items:
        name, eq, value = item.partition("=")
        name = name.strip()
        if not eq or not name.isidentifier():
            raise InputError(f"--const {item!r}: write NAME=VALUE, NAME a word (T0, omega_n)")
        out[name] = parse_number(f"--const {name}", value)
    return out


def _friction(option: str, items: list[str]) -> dict[str, float]:
    """--friction-* C (every pin, the key "*") and PIN=C (one pin), repeatable; each >= 0."""
    from ..numbers import parse_number

    pins = {}
    for item in items:
        name, eq, value = item.rpartition("=")
        v = parse_number(option, value)
        if not v >= 0.0:
            raise InputError(f"{option} {item!r}: friction must be >= 0")
        pins[name.strip() if eq else "*"] = v
    return pins


@app.command(
    epilog="Examples:  linkage simulate docs/crank_rocker_loads.toml --drive 'T0*(1 - omega/w0)' "
    "--const T0=5 --const w0=40 --time 0:2 --flywheel 0.01  |  linkage simulate FILE --omega0 300rpm "
    "--time 0:1 --gravity 9.81 --friction-viscous 1e-4 --plot motion.png",
)
def simulate(
    file: MechanismFile,
    *,
    time: Annotated[str, typer.Option("--time", metavar="START:END", help="The time span, s.")],
    drive: Annotated[str, typer.Option("--drive", metavar="EXPR", help="The driving torque (N m; a force in "
                     "N for a sliding driver) as an expression in t (s), theta (rad, or m) and omega (rad/s, "
                     "or m/s), with numbers, --const names, + - * / ** and the equations' functions "
                     "(sin, exp, ...).")] = "0",
    const: Annotated[Optional[list[str]], typer.Option("--const", metavar="NAME=VALUE",
                     help="A named number for --drive (repeatable).")] = None,
    theta0: Annotated[Optional[float], typer.Option("--theta0", help="The driver's starting value, in the "
                      "file's unit (deg, or its length unit); default the file's.")] = None,
    omega0: Annotated[str, typer.Option("--omega0", metavar="SPEED", help="The driver's starting speed: "
                      "rad/s (or length unit/s), or with a unit: 300rpm, 90deg/s.")] = "0",
    load: LoadOpt = None,
    torque: TorqueOpt = None,
    gravity: GravityOpt = None,
    friction_viscous: Annotated[Optional[list[str]], typer.Option("--friction-viscous", metavar="C|PIN=C",
                                help="Viscous friction at the pins, N m s/rad: C at every pin, PIN=C at one "
                                "(repeatable).")] = None,
    friction_coulomb: Annotated[Optional[list[str]], typer.Option("--friction-coulomb", metavar="M|PIN=M",
                                help="Coulomb friction at the pins: a constant torque M (N m) against each "
                                "pin's relative rotation, zero at rest; M at every pin, PIN=M at one "
                                "(repeatable).")] = None,
    flywheel: Annotated[float, typer.Option("--flywheel", metavar="I", help="A flywheel's inertia on a "
                        "turning driver, kg m^2.")] = 0.0,
    target_cs: Annotated[float, typer.Option("--target-cs", metavar="CS", help="The coefficient of speed "
                         "fluctuation the flywheel line sizes for.")] = 0.02,
    samples: Annotated[int, typer.Option("--samples", metavar="N", help="Output times, evenly spaced "
                       "over the span (2 to 100000).")] = 101,
    rtol: Annotated[float, typer.Option("--rtol", help="The integrator's relative tolerance (1e-14 to "
                    "1e-2); its absolute tolerance is 1e-2 of it.")] = 1e-10,
    plot: Annotated[Optional[Path], typer.Option(help="Draw the driver's angle and speed against time "
                    "into this picture (.png, .svg or .pdf; needs matplotlib).")] = None,
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    digits: DigitsOpt = 10,
    table: TableOpt = None,
    columns: ColumnsOpt = None,
) -> None:
    """How a mechanism with masses moves under a drive, its loads, gravity and friction.

    Forward dynamics of a one-degree-of-freedom mechanism with masses (a joints-form file
    with a [mass] table): I(theta) theta'' + I'(theta) theta'^2 / 2 = Q(t, theta, theta'),
    I from every link's mass and inertia by the rates at unit driver speed, Q the virtual
    power of the drive (--drive), the file's loads, gravity and pin friction; integrated by
    scipy's DOP853. Prints the driver's motion, every unknown, the energies, the pin forces
    (the matrix method at the simulated motion), two checks (the work-energy balance; the
    matrix method's input equal to the drive) and the last full turn's speed fluctuation.
    Exit 1 at a named event (dead_point, limit_of_assembly, stopped,
    integration_failed) with the rows up to it, or where a check fails. See docs/simulate.md.
    """
    from ..arguments import parse_motion
    from ..kinematics.bodies import command_loads
    from ..kinematics.loading import load as load_file
    from ..kinematics.simulation import simulate as run
    from ..render.simulate import simulate_plot, simulate_report, simulation_checks

    out_fmt = choose_format(fmt, output)
    check_paths([file], [("--output", output), ("--plot", plot)], {"--plot": (plot, PICTURES)})
    span = _span(time)
    if not 0.0 < target_cs < 1.0:
        raise InputError(f"--target-cs {target_cs!r}: give a fraction between 0 and 1, e.g. 0.02")
    fv = _friction("--friction-viscous", friction_viscous or [])
    fc = _friction("--friction-coulomb", friction_coulomb or [])
    mechanism = load_file(file)
    loads = command_loads(mechanism, load or [], torque or [], gravity)
    speed = parse_motion(omega0, None, mechanism, ("--omega0", "--accel"))[0] or 0.0
    try:
        sim = run(mechanism, drive, span, constants=_constants(const or []), theta0=theta0, omega0=speed,
                  loads=loads, friction_viscous=fv, friction_coulomb=fc, flywheel=flywheel, samples=samples,
                  rtol=rtol, atol=rtol * 1e-2)
    except InputError as exc:  # the library's argument names, as the command's options
        raise InputError(re.sub(r"^(theta0|flywheel|rtol|samples|friction_viscous|friction_coulomb)\b",
                                lambda m: "--" + m.group(1).replace("_", "-"), str(exc))) from None
    energy_tol, drive_tol = max(100.0 * rtol, 1e-12), max(rtol, 1e-12)
    emit_report(simulate_report(sim, mechanism, digits, energy_tol, drive_tol, target_cs), out_fmt, output,
                columns=columns, table=table)
    if plot is not None:
        simulate_plot(sim, mechanism, plot)
        typer.echo(f"wrote {plot}", err=True)
    if sim.event is not None or not simulation_checks(sim, energy_tol, drive_tol, target_cs).passed:
        note_exit_reasons(out_fmt, [f"event: {sim.event} at t = {sim.event_time:.10g} s: {sim.message}"
                                    if sim.event is not None else
                                    "a check failed: --format json or plain shows which"])
        raise typer.Exit(1)
