"""linkage scan."""

from typing import Annotated, Optional

import typer

from .options import (
    AccelOpt,
    ColumnsOpt,
    DigitsOpt,
    FormatOpt,
    GravityOpt,
    LoadOpt,
    MechanismFile,
    OutputOpt,
    SetOpt,
    SpeedOpt,
    TorqueOpt,
    check_paths,
    note_closed_form,
    parse_assignments,
)
from .progress import progress_bar
from .root import app


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
        "--samples. In a joints file also a fixed joint's coordinate, e.g. O4.x (column "
        "O4_x).")] = None,
    samples: Annotated[Optional[int], typer.Option(help="Draw this many random designs in the "
                       "--vary ranges instead of a grid.")] = None,
    sampling: Annotated[str, typer.Option(help="With --samples: lhs (Latin hypercube, default) "
                        "or random.")] = "lhs",
    seed: Annotated[int, typer.Option(help="With --samples: the random seed (same seed, same "
                    "designs).")] = 0,
    start: Annotated[Optional[float], typer.Option("--from", help="First driver value (default 0, or "
                     "the file's [driver] range).")] = None,
    stop: Annotated[Optional[float], typer.Option("--to", help="Last driver value (default 359, or "
                    "the file's [driver] range).")] = None,
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
    fmt: FormatOpt = None,
    output: OutputOpt = None,
    digits: DigitsOpt = 6,
    columns: ColumnsOpt = None,
    force: LoadOpt = None,
    torque: TorqueOpt = None,
    gravity: GravityOpt = None,
    speed: SpeedOpt = None,
    accel: AccelOpt = None,
) -> None:
    """Scan a range of designs: each over its whole cycle, one record per design.

    Each record: the varied parameters, feasible_fraction (positions where an assembly
    exists), solved_fraction (positions solved on the followed branch), full_cycle, with a
    closed form meetings (positions where two assemblies meet to rounding, a change point:
    the branch there is a matter of rounding), every unknown's _min, _max and _range, for
    four-bars grashof and min/max_transmission_deg (folded into 0..90), and the x/y extents
    of each [points] path. With loads ([loads] or [mass] in a joints-form file, or
    --load/--torque/--gravity; --speed for inertia): peak_input (the largest |input
    torque|), max_pin_force, max_shaking_force (over the positions whose forces are ok) and
    forces_flagged (positions near a toggle).

    Example: linkage scan sample_inputs/crank_rocker.toml --vary r2=20:60:5 --vary r4=60:120:7
    """
    from ..arguments import driver_span, parse_motion
    from ..files import parse_toml, read_input
    from ..kinematics.bodies import command_loads
    from ..kinematics.loading import from_text
    from ..kinematics.sweep import driver_values
    from ..render import writers
    from ..render.scan import RecordSink, pick_spec, scan_meta, scan_report, scan_summary
    from ..scan import ScanRequest, open_scan, parse_vary, run_scan

    if output is not None and str(output) == "-":
        output = None
    fmt = writers.choose_format(fmt, output)
    check_paths([file], [("--output", output)])
    varies = [parse_vary(v) for v in vary or []]
    text = read_input(file)
    fixed = parse_assignments("--set", set_ or [])
    mechanism = from_text(text, str(file)).with_values(fixed, {})
    note_closed_form(mechanism)
    w, a_ = parse_motion(speed, accel, mechanism)
    a, b = driver_span(mechanism, start, stop, turn_end=359.0)
    doc = parse_toml(text, str(file)) if any("." in v.name for v in varies) else None
    request = ScanRequest(
        mechanism, tuple(varies), tuple(driver_values(a, b, step, None)), samples=samples, seed=seed,
        sampling=sampling, branch=branch, tol=tol, where=where, sort=sort, descending=desc, top=top,
        scheduler=scheduler, workers=workers, chunk=chunk,
        loads=command_loads(mechanism, force or [], torque or [], gravity), speed=w, accel=a_, doc=doc,
        text=text, fixed=tuple((k, float(v)) for k, v in fixed.items()), cli=True)
    opened = open_scan(request)
    setup, motion = opened.setup, (w or 0.0, a_)
    spec = pick_spec(setup.spec, columns) if columns else setup.spec
    streamed = writers.is_data(fmt)
    if streamed:
        writers.prefetch(fmt, setup.plan.total)  # the writer's imports beside the scan's solving
    meta = scan_meta(mechanism, str(file), setup, (a, b, step), where, sort, desc, motion)
    sink = RecordSink(fmt, output, spec, meta) if streamed else None
    done = run_scan(opened, output=sink, holding=f"--sort {sort} with --format {fmt}",
                    show=None if streamed else 20,
                    progress=lambda total, size: progress_bar(total, minimum=2 * size))
    summary = scan_summary(mechanism, setup, (a, b, step), done.scanned, done.keeper, done.held,
                           done.seconds, shown=not streamed, motion=motion)
    if sink is None:
        writers.write(scan_report(done.held, spec, summary, digits, meta), fmt, output)
    else:
        typer.echo(f"{summary[0]}; wrote {sink.count:,} records" +
                   (f" to {output}" if output is not None else ""), err=True)
