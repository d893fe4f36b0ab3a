"""linkage draw."""

from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from ..errors import InputError
from .options import PICTURES, MechanismFile, SetOpt, check_paths, note_closed_form, parse_assignments
from .progress import progress_bar
from .root import app


@app.command(
    epilog="Examples:  linkage draw sample_inputs/rapier_drive.toml -o rapier.svg  |  "
    "linkage draw sample_inputs/crank_rocker.toml --animate crank.gif --step 10",
)
def draw(
    file: MechanismFile,
    *,
    output: Annotated[Optional[Path], typer.Option("--output", "-o", help="The drawing at the "
                      "file's driver value: .png or .pdf (matplotlib), or a CAD sheet in the file's "
                      "units with the coupler curves: .dxf (needs ezdxf) or .svg.")] = None,
    animate: Annotated[Optional[Path], typer.Option(help="A GIF of the mechanism over a sweep of "
                       "its driver (--from, --to, --step).")] = None,
    set_: SetOpt = None,
    start: Annotated[Optional[float], typer.Option("--from", help="Animation, and a .dxf or .svg's "
                     "coupler curves: first driver value (default 0, or the file's [driver] range).")] = None,
    stop: Annotated[Optional[float], typer.Option("--to", help="Animation, and a .dxf or .svg's "
                    "coupler curves: last driver value (default 360, or the file's [driver] range).")] = None,
    step: Annotated[Optional[float], typer.Option(help="Animation: driver increment per frame "
                    "(default 5); a .dxf or .svg's coupler curves: between their vertices (default: "
                    "the range in 360 steps).")] = None,
    fps: Annotated[Optional[float], typer.Option(help="Animation: frames per second (0.01 to 100; "
                   "default 12).")] = None,
) -> None:
    """Draw a mechanism from its joint coordinates, links and joints labelled.

    Example: linkage draw sample_inputs/fourbar_me581.toml --set theta2=80 -o fourbar.png
    """
    from ..arguments import check_fps, check_number, driver_span
    from ..kinematics.centres import assembled
    from ..kinematics.loading import load
    from ..kinematics.sweep import driver_values
    from ..kinematics.sweep import sweep as run_sweep

    if output is None and animate is None:
        raise InputError("give -o PATH for a drawing, --animate PATH.gif for an animation, or both")
    from ..render.cad import SUFFIXES as CAD
    from ..render.cad import require_ezdxf

    check_paths([file], [("--output", output), ("--animate", animate)],
                {"--output": (output, (*PICTURES, ".dxf")), "--animate": (animate, (".gif",))})
    sheet = output is not None and output.suffix.lower() in CAD
    if sheet and output.suffix.lower() == ".dxf":
        require_ezdxf()
    if fps is not None and animate is None:
        raise InputError("--fps sets the speed of the --animate GIF: give --animate PATH.gif as well")
    rate = check_fps("--fps", 12.0 if fps is None else fps)
    if step is not None and not check_number("--step", step) > 0:
        raise InputError("--step must be > 0 and --to must not be below --from")
    mechanism = load(file).with_values(parse_assignments("--set", set_ or []), {})
    note_closed_form(mechanism)
    if output is not None:
        problem = mechanism.problem()
        result = assembled(mechanism)  # refused as centres and convert refuse it (exit 2)
        if sheet:
            _write_sheet(mechanism, result.x, output, start, stop, step)
        else:
            from ..render.plots import draw_mechanism

            draw_mechanism(mechanism, result.x, output, problem.title)
        typer.echo(f"wrote {output}", err=True)
    if animate is not None:
        from ..render.plots import animate_sweep, assembly_gaps, sweep_frames

        a, b = driver_span(mechanism, start, stop)
        values = driver_values(a, b, 5.0 if step is None else step, None)
        if len(values) > 2000:
            raise InputError(f"{len(values)} frames is too many for a GIF; use a larger --step")
        s = run_sweep(mechanism, values)
        frames = sweep_frames(mechanism, s)
        if not frames:
            typer.echo(f"error: no position of {file} between {a:g} and {b:g} could be solved", err=True)
            raise typer.Exit(1)
        with progress_bar(len(frames), minimum=1) as advance:
            animate_sweep(mechanism, frames, animate, fps=rate, progress=advance, gaps=assembly_gaps(s))
        typer.echo(f"wrote {animate} ({len(frames)} frames)", err=True)


def _write_sheet(mechanism: Any, q: Any, output: Path, start: float | None, stop: float | None,
                 step: float | None) -> None:
    """A CAD sheet (render/cad.py) of the pose ``q``, with the coupler curves of the file's
    points over the driver's range when it has points."""
    from ..arguments import driver_span
    from ..kinematics.sweep import driver_values, sweep_mechanism
    from ..render.cad import needs_sweep, sheet, write_sheet

    swept, note = None, ""
    # the sweep also sets how long a slider's line is drawn; a length driver without a
    # range has none (driver_span asks for one where the curves need it)
    sweepable = mechanism.driver.kind == "angle" or getattr(mechanism, "driver_range", None) is not None \
        or (start is not None and stop is not None)
    if needs_sweep(mechanism) and (sweepable or mechanism.points):
        a, b = driver_span(mechanism, start, stop)
        values = driver_values(a, b, step, None if step is not None else 361)
        swept = sweep_mechanism(mechanism, values, joints=True)
        unit = mechanism.driver.unit
        note = (f"{mechanism.driver.name} from {a:g} to {b:g} {unit} in "
                + (f"steps of {step:g} {unit}" if step is not None else f"{len(values) - 1} steps"))
    write_sheet(sheet(mechanism, q, swept, note), output)
