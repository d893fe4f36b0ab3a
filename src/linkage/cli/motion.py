"""linkage synthesize --motion: four-bars through five poses (its own module: the CLI's
modules stay short; docs/motion_synthesis.md)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Optional

import typer

from ..errors import InputError


def read_poses(pose: list[str], poses_file: Optional[Path]) -> list[tuple[float, float, float]]:
    """--pose X,Y,DEG repeated, or --poses FILE (one pose a line: X,Y,DEG or X Y DEG; # comments)."""
    from ..synthesis.motion import pose_list

    if pose and poses_file is not None:
        raise InputError("give the poses as --pose X,Y,DEG (repeated) or --poses FILE, not both")
    if poses_file is None:
        if not pose:
            raise InputError("--motion: give 5 poses, --pose X,Y,DEG repeated (or --poses FILE)")
        return pose_list(pose)
    from ..errors import ParseError
    from ..files import read_input

    try:  # as a mechanism file is read: a regular file, of bounded size (files.read_input)
        text = read_input(poses_file, "poses file")
    except ParseError as exc:
        raise InputError(f"--poses: {exc}") from None
    out = []
    for number, line in enumerate(text.splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        try:  # each line by the --pose rule, its refusal naming the file's line (not "--pose 1")
            out += pose_list([",".join(line.replace(",", " ").split())])
        except InputError as exc:
            said = re.sub(r"^--pose (\d+ |'[^']*': )", "", str(exc))
            raise InputError(f"--poses {poses_file} line {number} ({line!r}): {said}") from None
    return out


def read_circle_points(circle: list[str]) -> list[tuple[float, float]] | None:
    """--circle X,Y (twice, with three poses): the moving pivots at pose 1."""
    from ..numbers import parse_number

    out = []
    for k, text in enumerate(circle):
        parts = text.split(",")
        if len(parts) != 2:
            raise InputError(f"--circle {text!r}: write X,Y")
        x, y = (parse_number(f"--circle {k + 1}", v) for v in parts)
        out.append((x, y))
    return out or None


def motion_command(pose: list[str], poses_file: Optional[Path], circle: list[str], *,
                   min_transmission: float, design: Optional[int], output: Optional[Path], write_file: bool,
                   force: bool, unit: str, fmt: str, report_out: Optional[Path], digits: int,
                   table: Optional[str], plot: Optional[Path] = None) -> None:
    from ..render import writers
    from ..render.motion_synthesis import best_design, motion_report
    from ..synthesis.motion import THREE_FREE, synthesize_motion

    poses = read_poses(pose, poses_file)
    points = read_circle_points(circle)
    if plot is not None and len(poses) != 4:
        raise InputError("--plot with --motion draws four poses' centre-point and circle-point curves: "
                         f"give 4 poses, not {len(poses)}")
    if write_file and output is not None and len(poses) == 4:
        raise InputError(f"-o {output} writes a four-bar: 4 poses give the centre-point and circle-point "
                         "curves, not a design (-f csv lists their points); give 5 poses, or 3 with "
                         "--circle X,Y twice")
    if len(poses) == 3 and points is None:
        raise InputError(f"{THREE_FREE}: give them as --circle X,Y twice")
    try:
        m = synthesize_motion(poses, circle_points=points, min_transmission=min_transmission)
    except InputError as exc:  # the API's argument names, as the command's options
        raise InputError(str(exc).replace("circle_points", "--circle")) from None
    chosen = best_design(m)
    if design is not None:
        if not 1 <= design <= len(m.designs):
            raise InputError(f"--design {design}: there are {len(m.designs)} designs (1 to {len(m.designs)})")
        chosen = design - 1
    writers.write(motion_report(m, digits, unit), fmt, report_out, table=table)
    if plot is not None:
        from ..render.motion_synthesis import curves_plot

        curves_plot(m, plot, unit)
    if m.curves is not None:
        return
    if write_file and output is not None:
        if chosen is None:
            typer.echo(f"note: {output} not written: no design without defects (--design K writes one)",
                       err=True)
        else:
            from .synthesis_output import write_motion_design

            write_motion_design(m, chosen, output, unit, force)
    if best_design(m) is None:
        raise typer.Exit(1)

