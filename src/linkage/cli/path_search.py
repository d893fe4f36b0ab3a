"""linkage synthesize --path --search: the defect-free four-bars through five to nine points,
ranked, over samples of the extra points (its own module: the CLI's modules stay short;
docs/path_synthesis.md, "Five to eight points")."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import typer

from ..errors import InputError


def path_search_command(pairs: list[tuple[float, float]], samples: Optional[int], options: dict[str, Any], *,
                        design: Optional[int], output: Optional[Path], write_file: bool, force: bool,
                        fmt: str, report_out: Optional[Path], digits: int, table: Optional[str]) -> None:
    from ..homotopy.ninepoint_track import PATHS
    from ..render import writers
    from ..render.path_search import path_search_report
    from ..synthesis.path_search import search_path
    from .progress import progress_bar
    from .timed_path import check_design

    check_design(design, write_file)
    try:
        with progress_bar(PATHS * (samples or 1), minimum=0, label="tracking paths") as advance:
            result = search_path(pairs, samples, progress=advance, **options)
    except InputError as exc:
        raise InputError(as_options(str(exc))) from None
    writers.write(path_search_report(result, digits), fmt, report_out, table=table)
    found = result.designs
    if write_file and output is not None:
        if design is not None and not 1 <= design <= len(found):
            raise InputError(f"--design {design}: there are {len(found)} designs without defects"
                             + (f" (1 to {len(found)})" if found else ""))
        if not found:
            typer.echo(f"note: {output} not written: no design without defects", err=True)
        else:
            from ..synthesis.path import mechanism_text
            from .options import write_mechanism

            chosen = found[(design or 1) - 1]
            text = mechanism_text(chosen.four_bar, f"four-bar through {len(pairs)} points")
            write_mechanism(output, text, force, said=f" (design {design or 1}: its coupler point P passes "
                            "through the points)")
    if not found:
        raise typer.Exit(1)


def as_options(message: str) -> str:
    """An API message with its argument names as the command's options."""
    for name, option in (("min_transmission", "--min-transmission"), ("via:", "--via:"),
                         ("samples", "--samples"), ("seed", "--seed")):
        message = message.replace(name, option)
    return message
