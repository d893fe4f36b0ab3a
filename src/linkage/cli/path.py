"""linkage synthesize --path: four-bars whose coupler point passes through nine points (its
own module: the CLI's modules stay short; docs/path_synthesis.md)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from ..errors import InputError


def read_points(point: list[str], option: str = "--point") -> list[tuple[float, float]]:
    """--point X,Y (or ``option``) repeated: the points."""
    from ..numbers import parse_number

    out = []
    for k, text in enumerate(point):
        parts = text.split(",")
        if len(parts) != 2:
            raise InputError(f"{option} {text!r}: write X,Y")
        out.append(tuple(parse_number(f"{option} {k + 1}", v) for v in parts))
    return out  # type: ignore[return-value]


def path_command(point: list[str], via: list[str], *, search: bool, samples: Optional[int], seed: int,
                 design: Optional[int], output: Optional[Path], write_file: bool,
                 force: bool, fmt: str, report_out: Optional[Path], digits: int, table: Optional[str],
                 scheduler: Optional[str], workers: Optional[int], min_transmission: float) -> None:
    from ..arguments import check_workers
    from ..render import writers
    from ..render.path_synthesis import path_report, ranked
    from ..synthesis.path import check_points, synthesize_path
    from ..synthesis.path_points import check_via
    from .path_search import as_options
    from .timed_path import check_design, is_timed, timed_path_command

    check_design(design, write_file)  # before the solve, not after it
    if is_timed(point):  # X,Y,DEG: prescribed timing, five points
        return timed_path_command(point, via, search=search, samples=samples, seed=seed, design=design,
                                  output=output, write_file=write_file, force=force, fmt=fmt,
                                  report_out=report_out, digits=digits, table=table, scheduler=scheduler,
                                  workers=workers, min_transmission=min_transmission)
    pairs, extra = read_points(point), read_points(via, "--via")
    check_points(pairs)  # before the workers, so a wrong count is the first thing said
    try:
        check_via(extra, [complex(*p) for p in pairs])
    except InputError as exc:
        raise InputError(as_options(str(exc))) from None
    workers = check_workers("--workers", workers, scheduler)
    options = {"via": extra, "seed": seed, "scheduler": scheduler, "workers": workers,
               "min_transmission": min_transmission}
    if search:
        from .path_search import path_search_command

        path_search_command(pairs, samples, options, design=design, output=output, write_file=write_file,
                            force=force, fmt=fmt, report_out=report_out, digits=digits, table=table)
        return
    if samples is not None:
        raise InputError("--samples is an option of --search")
    from ..homotopy.ninepoint_track import PATHS
    from .progress import progress_bar

    try:
        with progress_bar(PATHS, minimum=0, label="tracking paths") as advance:
            result = synthesize_path(pairs, progress=advance, **options)  # type: ignore[arg-type]
    except InputError as exc:
        raise InputError(as_options(str(exc))) from None
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

            text = mechanism_text(result.designs[chosen][0], f"four-bar through {len(pairs)} points")
            write_mechanism(output, text, force, said=" (its coupler point P passes through the points)")
    if result.missing or not clean:
        raise typer.Exit(1)

