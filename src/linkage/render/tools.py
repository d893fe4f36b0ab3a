"""Reports of the tool commands: ``samples`` (the listing), ``stress`` and ``bench``."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from .data import DataTable, Report, from_rows
from .report import Block, Text, table


def samples_report(listing: Mapping[str, str]) -> Report:
    rows = list(listing.items())
    width = max((len(k) for k in listing), default=0)

    def blocks() -> list[Block]:  # lines, not a table: a table right-aligns the descriptions
        return [*(Text(f"{k.ljust(width)}  {v}") for k, v in rows), Text(""),
                Text("print one with `linkage samples NAME`, or copy it with `linkage samples NAME -o FILE`")]

    return Report("the mechanism files shipped with linkage",
                  (from_rows("samples", [("sample", "", "text"), ("what it is", "", "text")], rows),),
                  blocks, lambda: {"samples": dict(listing)})


STRESS_COLUMNS = {"cases": "int", "right root/branch": "int", "other root/branch": "int",
                  "failed (named)": "int", "false convergence": "int", "crash": "int"}


def stress_report(report: Mapping[str, Any], rows: Sequence[Sequence[Any]], headers: Sequence[str],
                  quick: bool, seed: int, false: int, crashes: int) -> Report:
    """The battery's summary (a row per family and method) and the hybrid's record on the
    bracketed classic cases."""
    h = report["hybrid"]
    title = (f"stress battery ({'quick' if quick else 'full'}, seed {seed}): {sum(r[2] for r in rows)} runs "
             f"in {report['seconds']:.1f} s")

    def kind(name: str, j: int) -> str:
        if name in STRESS_COLUMNS:
            return STRESS_COLUMNS[name]
        return "text" if any(isinstance(r[j], str) for r in rows) else "number" if rows and \
            any(isinstance(r[j], float) for r in rows) else "int"

    tables = [from_rows("summary", [(n, "", kind(n, j)) for j, n in enumerate(headers)], rows)]
    if h:
        tables.append(from_rows("hybrid", [("case", "", "text"), ("within_4_eps", "", "bool"),
                                           ("hybrid_iterations", "", "int"),
                                           ("bisection_iterations", "", "int"),
                                           ("hybrid_status", "", "text")], h["rows"]))

    def blocks() -> list[Block]:
        out: list[Block] = [Text(title, "bold"), Text(""), table("", headers, rows, 4),
                            Text(f"false convergences: {false}; crashes: {crashes} (ours; scipy rows are "
                                 "a reference)", "green" if not false + crashes else "red")]
        if h:
            out.append(Text(f"hybrid on the bracketed classic cases: {h['within_4_eps']} of {h['cases']} "
                            "converged within 4 machine epsilons of the reference (or to an exact zero); "
                            f"{h['hybrid_iterations']} iterations in all, against "
                            f"{h['bisection_iterations']} for bisection"))
        for (family, m), t in sorted(report["tallies"].items()):
            if not m.startswith("scipy"):
                out.extend(Text(f"  {family}/{m}: {e}", "red") for e in t.examples[:5])
        return out

    def document() -> dict[str, Any]:
        return {"seed": seed, "quick": quick, "seconds": report["seconds"],
                "summary": [dict(zip(headers, r)) for r in rows],
                "false_convergences": false, "crashes": crashes,
                "hybrid": ({**{k: v for k, v in h.items() if k not in ("rows", "failures")},
                            "cases_detail": [{"case": n, "within_4_eps": ok, "hybrid_iterations": hi,
                                              "bisection_iterations": bi, "hybrid_status": st}
                                             for n, ok, hi, bi, st in h["rows"]]} if h else None)}

    return Report(title, tuple(tables), blocks, document)


def bench_report(rows: Sequence[Sequence[Any]], sweeps: Mapping[str, float], cold: Mapping[str, float],
                 target_rows: Sequence[tuple[str, str, float | None, bool | None]], n_repeats: int,
                 notes: Sequence[str], scipy: bool) -> Report:
    """The work-precision measurements (bench.measurement_rows), the sweeps, the cold
    starts and the targets (each a ratio measured in this run, met or not)."""
    headers = (("problem", "", "text"), ("contender", "", "text"), ("tol", "", "number"),
               ("time per solve", "us", "number"), ("fastest batch", "us", "number"),
               ("slowest batch", "us", "number"), ("error", "", "number"), ("iterations", "", "number"),
               ("evaluations", "", "number"))
    met = [(t, c, r, None if r is None or r != r or ok is None else ok) for t, c, r, ok in target_rows]
    tables: list[DataTable] = [
        from_rows("measurements", headers, rows),
        from_rows("sweeps", [("sweep", "", "text"), ("seconds", "s", "number")], list(sweeps.items())),
        from_rows("cold_start", [("command", "", "text"), ("seconds", "s", "number")], list(cold.items())),
        from_rows("targets", [("target", "", "text"), ("ratio", "", "text"), ("measured", "", "number"),
                              ("met", "", "bool")], met),
    ]
    title = (f"work-precision benchmark: {len(rows)} measurements, {n_repeats} timed "
             f"batch{'' if n_repeats == 1 else 'es'} each "
             "(median; spread = fastest-slowest batch)")
    shown = [f"{n} ({u})" if u else n for n, u, _ in headers]

    def blocks() -> list[Block]:
        out: list[Block] = [Text(title, "bold"), *(Text(n) for n in notes), Text(""),
                            table("", shown, rows, 4),
                            table("Sweeps (median seconds)", ("sweep", "seconds (s)"),
                                  list(sweeps.items()), 4)]
        if cold:
            out.append(table("Cold start (fresh interpreter, median wall time)", ("command", "seconds (s)"),
                             list(cold.items()), 4))
        out.append(table("Targets (ratios measured in this run)", ("target", "ratio", "measured", "met"),
                         [(t, c, r, "n/a" if ok is None else ("yes" if ok else "no"))
                          for t, c, r, ok in met], 3))
        return out

    def document() -> dict[str, Any]:
        return {"measurements": [dict(zip(shown, r)) for r in rows], "cold_start": dict(cold),
                "sweeps": dict(sweeps),
                "targets": [{"target": t, "ratio": c, "measured": r, "met": ok}
                            for t, c, r, ok in target_rows],
                "scipy": scipy}

    return Report(title, tuple(tables), blocks, document)
