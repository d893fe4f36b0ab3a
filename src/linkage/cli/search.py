"""linkage synthesize --search: the candidates' table (its own module: the CLI's modules stay
short)."""

from pathlib import Path
from typing import Optional

import typer


def search_command(
    function: str,
    x: str,
    alpha: Optional[str],
    phi: Optional[str],
    vary: list[str],
    *,
    fmt: str,
    output: Optional[Path],
    digits: int,
    table: Optional[str] = None,
    **options: object,
) -> None:
    import time

    from ..render import writers
    from ..render.synthesis import search_report
    from ..scan import DesignPlan, parse_vary
    from ..synthesis import search
    from .progress import progress_bar

    # the candidates' count for the bar (search checks the same options again, naming them)
    total = (
        DesignPlan(
            [parse_vary(v) for v in vary],
            options["samples"],
            options["seed"],  # type: ignore[arg-type]
            options["sampling"],
        ).total
        if vary
        else 1
    )  # type: ignore[arg-type]
    started = time.perf_counter()
    with progress_bar(total, minimum=2000, label="synthesising") as advance:
        result = search(function, x, alpha, phi, vary, progress=advance, **options)  # type: ignore[arg-type]
    writers.write(search_report(result, digits, time.perf_counter() - started), fmt, output, table=table)
    if not result.without_defects:
        raise typer.Exit(1)
