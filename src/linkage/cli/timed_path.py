"""linkage synthesize --path with --point X,Y,DEG: four-bars whose coupler point passes through
five points with the crank at prescribed angles (docs/path_synthesis.md, "Prescribed
timing"). Its own module: cli/path.py dispatches here when a point has three fields."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from ..errors import InputError


def is_timed(point: list[str]) -> bool:
    """Whether some --point carries a crank angle (X,Y,DEG)."""
    return any(text.count(",") == 2 for text in point)


def read_timed_points(point: list[str]) -> list[tuple[float, ...]]:
    """--point X,Y,DEG repeated (a point X,Y among them is refused by the synthesis, in one line)."""
    from ..numbers import parse_number

    out = []
    for k, text in enumerate(point):
        parts = text.split(",")
        if len(parts) not in (2, 3):
            raise InputError(f"--point {text!r}: write X,Y,DEG (the crank's angle at the point, deg)")
        out.append(tuple(parse_number(f"--point {k + 1}", v) for v in parts))
    return out


def check_design(design: Optional[int], write_file: bool) -> None:
    """--design K, checked before any work: a whole number from 1, and only with -o FILE.toml
    (it picks the design written; without a file it would be silently ignored)."""
    from ..arguments import check_whole

    if design is None:
        return
    check_whole("--design", design, 1)
    if not write_file:
        raise InputError(f"--design {design} picks the design -o FILE.toml writes: give -o FILE.toml")


def api_names(message: str) -> str:
    """An API message with its names as the command's: points[k] is --point k + 1."""
    import re

    message = message.replace("min_transmission", "--min-transmission")
    return re.sub(r"\bpoints\[(\d+)\]", lambda m: f"--point {int(m.group(1)) + 1}", message)


def timed_path_command(point: list[str], via: list[str], *, search: bool, samples: Optional[int], seed: int,
                       design: Optional[int], output: Optional[Path], write_file: bool, force: bool, fmt: str,
                       report_out: Optional[Path], digits: int, table: Optional[str],
                       scheduler: Optional[str], workers: Optional[int], min_transmission: float) -> None:
    from ..render import writers
    from ..render.path_synthesis import timed_path_report, timed_ranked
    from ..synthesis.path import mechanism_text, synthesize_timed_path
    from ..synthesis.timed_path import prescribed_turn

    untimed = (("--via", via or None), ("--search", search or None), ("--samples", samples),
               ("--scheduler", scheduler), ("--workers", workers))
    for option, given in untimed:
        if given is not None:
            raise InputError(f"{option} is for untimed points (X,Y): five timed points are two Burmester "
                             "problems, solved here")
    check_design(design, write_file)
    try:
        result = synthesize_timed_path(read_timed_points(point), seed=seed, min_transmission=min_transmission)
    except InputError as exc:  # the API's argument names, as the command's options
        raise InputError(api_names(str(exc))) from None
    writers.write(timed_path_report(result, digits), fmt, report_out, table=table)
    order = timed_ranked(result)  # cognate groups
    clean = [g for g in order if not result.designs[result.groups[g][0]].defects]
    if write_file and output is not None:
        if design is not None and not 1 <= design <= len(order):
            raise InputError(f"--design {design}: there are {len(order)} designs" +
                             (f" (1 to {len(order)})" if order else ""))
        chosen = order[design - 1] if design is not None else (clean[0] if clean else None)
        if chosen is None:
            typer.echo(f"note: {output} not written: no design without defects (--design K writes one)",
                       err=True)
        else:
            from .options import write_mechanism

            fb = result.designs[result.groups[chosen][0]]
            # its driver's range: from the first point through the prescribed turn
            turn = prescribed_turn(result.crank_deg)
            text = mechanism_text(fb, "four-bar through five timed points",
                                  (fb.crank_deg[0], fb.crank_deg[0] + turn))
            write_mechanism(output, text, force, said=" (its coupler point P passes through the points at "
                            "the prescribed crank angles, theta2)")
    if result.solutions.incomplete() or not clean:
        raise typer.Exit(1)
