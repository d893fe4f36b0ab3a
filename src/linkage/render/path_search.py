"""The report of ``linkage synthesize --path --search``: the defect-free four-bars through
five to nine points, ranked (linkage.synthesis.path_search)."""

from __future__ import annotations

from typing import Any

from .data import Report, from_rows
from .path_synthesis import HEADS, design_row, terminal_table
from .report import Block, Text, table

SEARCH_HEADS = [HEADS[0], ("sample", "", "int"), *HEADS[1:]]
"""The designs table: the rank (design), the sample that found it, then the path report's
columns."""
SAMPLE_HEADS = [("sample", "", "int"), ("extra", "", "text"), ("found", "", "int"), ("missing", "", "int"),
                ("real", "", "int"), ("without_defects", "", "int"), ("routes", "", "int"),
                ("steps", "", "int"), ("seconds", "s", "number")]
"""A sample: its extra points (X,Y each, as --via takes them), the orbits found and not
reached, its real designs (cognate groups), its defect-free cognates, and the tracking."""
TERMINAL_COLUMNS = ("design", "sample", "cognate", "grashof", "transmission_min", "ground", "crank",
                    "coupler", "rocker", "point_error")
"""The terminal's columns, the ranking's key (the least transmission angle) beside the rank
(path_synthesis.TERMINAL_COLUMNS)."""


def extra_text(points: Any, extra: Any, digits: int | None = None) -> str:
    """The extra points as --via takes them, X,Y each (all digits, or ``digits``)."""
    def num(v: float) -> str:
        return repr(v) if digits is None else f"{v:.{digits}g}"

    return " ".join(f"{num(points[k].real)},{num(points[k].imag)}" for k in extra)


def sample_rows(result: Any, digits: int | None = None) -> list[tuple[Any, ...]]:
    out = []
    for k, s in enumerate(result.samples):
        clean = sum(1 for group in s.designs for fb in group if not fb.defects)
        sol = s.solutions
        # (a quick look at some orbits may find more than it tracked: routes permute them)
        out.append((k + 1, extra_text(s.points, s.extra, digits), s.found, max(0, s.missing), len(s.designs),
                    clean, sol.routes, sum(sol.steps), sol.seconds))
    return out


def summary_line(result: Any) -> str:
    given, n = len(result.points), len(result.samples)
    how = ("the finite set through nine points" if given == 9 else
           f"{n} sample{'s' if n != 1 else ''} of {9 - given} extra point{'s' if 9 - given != 1 else ''} "
           "between them")
    missing = sum(max(0, s.missing) for s in result.samples)
    return (f"{given} points, {how}: {result.real} real four-bars (up to cognates), {len(result.designs)} "
            f"without defects (transmission >= {result.min_transmission:g} deg)"
            + (f"; {missing} orbits not reached" if missing else ""))


def path_search_report(result: Any, digits: int) -> Report:
    designs = [(k + 1, d.sample, *design_row(k + 1, d.cognate, d.four_bar)[1:])
               for k, d in enumerate(result.designs)]
    tables = (from_rows("designs", SEARCH_HEADS, designs),
              from_rows("samples", SAMPLE_HEADS, sample_rows(result)))
    title = "four-bars whose coupler point passes through the points, without defects, ranked"

    def blocks() -> list[Block]:
        out: list[Block] = [Text(title, "bold"), Text(summary_line(result)), Text("")]
        if designs:
            out.append(terminal_table(tables[0], TERMINAL_COLUMNS, digits))
            out.append(Text("ranked by the least transmission angle over the motion from the first point to "
                            "the last, largest first; the pivots are in the designs table (-f, -o); -o "
                            "FILE.toml writes design 1 (--design K writes design K)"))
        else:
            out.append(Text("no four-bar without defects: more --samples, other points or a lower "
                            "--min-transmission", "red"))
        heads = [f"{n} ({u})" if u else n for n, u, _ in SAMPLE_HEADS]
        out += [Text("Samples"), table("", heads, sample_rows(result, digits), digits)]
        return out

    def document() -> dict[str, Any]:
        return {"title": title, "points": len(result.points), "samples": len(result.samples),
                "real": result.real, "without_defects": len(result.designs),
                "min_transmission_deg": result.min_transmission}

    return Report(title, tables, blocks, document)
