"""linkage synthesize --path: four-bars whose coupler point passes through nine points (its
own module: the CLI's modules stay short; docs/path_synthesis.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from ..errors import InputError


def read_points(point: list[str]) -> list[tuple[float, float]]:
    """--point X,Y repeated: the nine points."""
    from ..numbers import parse_number

    out = []
    for k, text in enumerate(point):
        parts = text.split(",")
        if len(parts) != 2:
            raise InputError(f"--point {text!r}: write X,Y")
        out.append(tuple(parse_number(f"--point {k + 1}", v) for v in parts))
    return out  # type: ignore[return-value]


def path_command(point: list[str], *, design: Optional[int], output: Optional[Path], write_file: bool,
                 force: bool, fmt: str, report_out: Optional[Path], digits: int, table: Optional[str],
                 scheduler: Optional[str], workers: Optional[int], min_transmission: float) -> None:
    from ..arguments import check_workers
    from ..render import writers
    from ..render.path_synthesis import path_report, ranked
    from ..synthesis.path import check_points, synthesize_path
    from .timed_path import is_timed, timed_path_command

    if is_timed(point):  # X,Y,DEG: prescribed timing, five points
        return timed_path_command(point, design=design, output=output, write_file=write_file, force=force,
                                  fmt=fmt, report_out=report_out, digits=digits, table=table,
                                  scheduler=scheduler, workers=workers, min_transmission=min_transmission)
    pairs = read_points(point)
    check_points(pairs)  # before the workers, so a wrong count is the first thing said
    workers = check_workers("--workers", workers, scheduler)
    from ..homotopy.ninepoint import PATHS
    from .progress import progress_bar

    try:
        with progress_bar(PATHS, minimum=0, label="tracking paths") as advance:
            result = synthesize_path(pairs, scheduler=scheduler, workers=workers,
                                     min_transmission=min_transmission, progress=advance)
    except InputError as exc:  # the API's argument names, as the command's options
        raise InputError(str(exc).replace("min_transmission", "--min-transmission")) from None
    writers.write(path_report(result, digits), fmt, report_out, table=table)
    order = ranked(result)
    clean = [i for i in order if not result.designs[i][0].defects]
    if write_file and output is not None:
        if design is not None and not 1 <= design <= len(order):
            raise InputError(f"--design {design}: there are {len(order)} real designs (1 to {len(order)})")
        chosen = order[design - 1] if design is not None else (clean[0] if clean else None)
        if chosen is None:
            typer.echo(f"note: {output} not written: no design without defects (--design K writes one)",
                       err=True)
        else:
            from ..synthesis.path import mechanism_text
            from .options import write_mechanism

            text = mechanism_text(result.designs[chosen][0], "four-bar through nine points")
            write_mechanism(output, text, force, said=" (its coupler point P passes through the points)")
    if result.missing or not clean:
        raise typer.Exit(1)
