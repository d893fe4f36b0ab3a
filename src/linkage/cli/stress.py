"""linkage stress."""

from typing import Annotated, Any, Optional

import typer

from ..errors import InputError
from .options import FormatOpt, OutputOpt, check_paths, choose_format, emit
from .root import app


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
    from ..methods import SCALAR_METHODS
    from ..render.report import Text, table
    from ..solve import SYSTEM_METHODS
    from ..stress import SUMMARY_HEADERS, run, summary_rows, totals

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
