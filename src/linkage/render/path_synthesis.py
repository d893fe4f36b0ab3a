"""The report of ``linkage synthesize --path``: the four-bars through nine points."""

from __future__ import annotations

import math
from typing import Any

from .data import DataTable, Report, column, from_rows
from .report import Block, Text, table


def ranked(result: Any) -> list[int]:
    """Real designs, those without defects first, then by least transmission, largest first."""
    return rank([group[0] for group in result.designs])


def rank(designs: list[Any]) -> list[int]:
    """Four-bars, those without defects first, then by least transmission, largest first."""
    return sorted(range(len(designs)),
                  key=lambda i: (len(designs[i].defects), -designs[i].transmission_min_deg))


def design_row(number: int, cognate: int, fb: Any) -> tuple[Any, ...]:
    """A four-bar's row of the designs table (HEADS)."""
    r1, r2, r3, r4 = fb.lengths
    return (number, cognate, fb.grashof, " ".join(fb.defects) or "none", fb.ground_a.real,
            fb.ground_a.imag, fb.ground_b.real, fb.ground_b.imag, fb.pin_m.real, fb.pin_m.imag,
            fb.pin_n.real, fb.pin_n.imag,
            r1, r2, r3, r4, fb.transmission_min_deg, fb.max_point_error)


HEADS = [("design", "", "int"), ("cognate", "", "int"), ("grashof", "", "text"), ("defects", "", "text"),
         ("Ax", "", "number"), ("Ay", "", "number"), ("Bx", "", "number"), ("By", "", "number"),
         ("Mx", "", "number"), ("My", "", "number"), ("Nx", "", "number"), ("Ny", "", "number"),
         ("ground", "", "number"), ("crank", "", "number"), ("coupler", "", "number"),
         ("rocker", "", "number"), ("transmission_min", "deg", "number"), ("point_error", "", "number")]


def path_tables(result: Any) -> tuple[DataTable, ...]:
    order = ranked(result)
    designs = [design_row(k + 1, 1, result.designs[i][0]) for k, i in enumerate(order)]
    cognates = [design_row(k + 1, c + 1, fb) for k, i in enumerate(order)
                for c, fb in enumerate(result.designs[i])]
    s = result.solutions
    routes = [(r + 1, s.paths, s.failed[r], s.unrefined[r], s.steps[r]) for r in range(s.routes)]
    return (from_rows("designs", HEADS, designs), from_rows("cognates", HEADS, cognates),
            from_rows("routes", [("route", "", "int"), ("paths", "", "int"), ("failed", "", "int"),
                                 ("unsettled", "", "int"), ("steps", "", "int")], routes),
            outcomes_table(s), paths_table(result, order))


def outcomes_table(s: Any) -> DataTable:
    """Each route's paths counted by outcome class (linkage.homotopy.ninepoint_track.OUTCOMES),
    and how many of the settled ones settled only at 60 digits."""
    from ..homotopy.ninepoint_track import OUTCOMES

    counts = s.record.counts(s.routes)
    precise = [int(s.record.precise[s.record.route == r + 1].sum()) for r in range(s.routes)]
    rows = [(r + 1, s.paths, *map(int, counts[r]), precise[r]) for r in range(s.routes)]
    heads = [("route", "", "int"), ("paths", "", "int"), *[(name, "", "int") for name in OUTCOMES],
             ("polished_60_digits", "", "int")]
    return from_rows("outcomes", heads, rows)


PATH_HEADS = [("route", "", "int"), ("orbit", "", "int"), ("steps", "", "int"), ("rejected", "", "int"),
              ("newton", "", "int"), ("smallest_step", "", "number"), ("outcome", "", "text"),
              ("polished_60_digits", "", "bool"), ("stopped_on_leg", "", "int"), ("four_bar", "", "int"),
              ("real", "", "bool"), ("design", "", "int")]
"""The paths table: one row per path per route (NinePointSolutions.record); orbit is the
start instance's orbit (1-based), smallest_step the smallest accepted step in t, four_bar
the found four-bar's number (1-based, in the order found; real ones have a design number,
the designs table's)."""


def paths_table(result: Any, order: list[int]) -> DataTable:
    from ..homotopy.ninepoint_track import OUTCOMES

    s = result.solutions
    rec = s.record
    reals = [i for i, r in enumerate(s.real) if r]
    design = {reals[k]: pos + 1 for pos, k in enumerate(order)}
    fbs = [int(fb) for fb in rec.four_bar]
    values = [rec.route.tolist(), (rec.path + 1).tolist(), rec.steps.tolist(), rec.rejected.tolist(),
              rec.newton.tolist(), [v if math.isfinite(v) else None for v in rec.smallest_step.tolist()],
              [OUTCOMES[k] for k in rec.outcome], rec.precise.tolist(), [k or None for k in rec.leg.tolist()],
              [fb + 1 if fb >= 0 else None for fb in fbs],
              [bool(s.real[fb]) if fb >= 0 else None for fb in fbs], [design.get(fb) for fb in fbs]]
    return DataTable("paths", tuple(column(n, u, v, k) for (n, u, k), v in zip(PATH_HEADS, values)))


def certified_line(result: Any) -> str:
    """The alpha test's verdict on the real four-bars (``result.certificates``,
    :func:`linkage.synthesis.path.real_certificates`): how many are certified real, and
    whether all are told apart."""
    from .assemblies import distinct_text

    certs, apart = result.certificates
    return (f"alpha test (Smale; 50 digits): {sum(c.certified and c.real for c in certs)} of the "
            f"{len(certs)} real four-bars certified real"
            + distinct_text(len(apart), sum(c.certified for c in certs), len(certs)))


def summary_lines(result: Any) -> list[str]:
    s = result.solutions
    clean = sum(1 for group in result.designs if not group[0].defects)
    return [
        "nine-point path synthesis (Wampler, Morgan and Sommese 1992): parameter homotopy from a stored "
        f"generic instance, {s.paths} paths a route (one per four-bar up to Roberts cognates and the order "
        "of the dyads)",
        f"{s.routes} route{'s' if s.routes != 1 else ''}, {sum(s.steps)} steps, {s.seconds:.0f} s: "
        f"{result.found} four-bars found of {s.paths}" + (f" ({result.missing} not reached)" if result.missing
                                                          else "")
        + f"; {len(result.designs)} real, {clean} without defects",
        *extra_lines(result.points, result.extra),
        certified_line(result),
    ]


def extra_lines(points: Any, extra: Any) -> list[str]:
    """What the nine points are when some are extra (linkage.synthesis.path_points)."""
    if not extra:
        return []
    given = len(points) - len(extra)
    where = ", ".join(f"{k + 1} ({points[k].real:.6g}, {points[k].imag:.6g})" for k in extra)
    return [f"through {given} given points and {len(extra)} extra points between them, points {where} of "
            "the nine: each design passes through all nine in order"]


TERMINAL_COLUMNS = ("design", "grashof", "defects", "transmission_min", "ground", "crank", "coupler",
                    "rocker", "point_error")
"""The designs table's columns on a terminal, in this order: the judgement beside the design's
number (the rank is by the least transmission angle), then its links, then the check. Too
wide for 80 columns, rich stacks them in parts (report.column_groups): the first then holds
what a person chooses by."""


def terminal_table(t: DataTable, names: tuple[str, ...], digits: int) -> Block:
    """The columns ``names`` of table ``t``, in that order: the pivots' coordinates go to
    files (-f, -o), a terminal gets the judgement."""
    by_name = {c.name: c for c in t.columns}
    shown = [by_name[n] for n in names]
    return table("", [c.header for c in shown], list(zip(*[c.values for c in shown])), digits)


def path_report(result: Any, digits: int) -> Report:
    tables = path_tables(result)
    title = "four-bars whose coupler point passes through nine points"

    def blocks() -> list[Block]:
        out: list[Block] = [Text(title, "bold"), *[Text(line) for line in summary_lines(result)], Text("")]
        out.append(terminal_table(tables[0], TERMINAL_COLUMNS, digits))
        out.append(Text("defects: branch, the points are not all on one circuit (the linkage would have "
                        "to be taken apart); order, the circuit meets them out of order; transmission, the "
                        "least transmission angle from the first point to the last is below "
                        "--min-transmission; each design's two Roberts cognates are in the cognates table "
                        "(--table cognates -f csv)"))
        rows = list(zip(*[c.values for c in tables[2].columns]))
        out += [Text("Routes"), table("", [c.header for c in tables[2].columns], rows, digits)]
        out += outcome_blocks(tables[3], digits)
        return out

    def document() -> dict[str, Any]:
        s = result.solutions
        return {"title": title, "paths": s.paths, "routes": s.routes, "found": result.found,
                "missing": result.missing, "real": len(result.designs),
                "without_defects": sum(1 for g in result.designs if not g[0].defects), "seconds": s.seconds}

    return Report(title, tables, blocks, document)


def outcome_blocks(outcomes: DataTable, digits: int) -> list[Block]:
    """The outcomes table as the terminal shows it, and where every path's record is."""
    rows = list(zip(*[c.values for c in outcomes.columns]))
    return [Text("Paths by outcome"), table("", [c.header for c in outcomes.columns], rows, digits),
            Text("outcomes: reached, a four-bar no path had reached; reached_again, one an earlier route "
                 "found; duplicate, one another path of the route reached first; unsettled, Newton's method "
                 "did not settle at the points (in double precision nor at 60 digits); step_underflow, "
                 "too_many_steps, infinite, the tracker gave the path up; polished_60_digits, of the "
                 "settled, those that settled only at 60 digits. Every path's steps, rejected steps, "
                 "corrector iterations and smallest step: --table paths with -f csv or json "
                 "(docs/path_synthesis.md)")]


TIMED_HEADS = [*HEADS, ("crank_dyad", "", "int"), ("rocker_dyad", "", "int"),
               ("crank_first", "deg", "number"), ("timing_error", "deg", "number")]
"""The timed designs' columns: the untimed ones, which dyads (of the crank problem and of
its rocker problem), the crank's angle at the first point and the timing error."""
TIMED_TERMINAL = (*TERMINAL_COLUMNS, "timing_error")


def timed_ranked(result: Any) -> list[int]:
    """The cognate groups of a timed result, ranked by their first members."""
    return rank([result.designs[g[0]] for g in result.groups])


def timed_path_tables(result: Any) -> tuple[DataTable, ...]:
    four_bars = result.solutions.four_bars

    def row(number: int, cognate: int, i: int) -> tuple[Any, ...]:
        fb = result.designs[i]
        return (*design_row(number, cognate, fb), four_bars[i].crank + 1, four_bars[i].rocker + 1,
                fb.crank_deg[0], fb.timing_error_deg)

    order = timed_ranked(result)
    leads = [row(k + 1, 1, result.groups[g][0]) for k, g in enumerate(order)]
    members = [row(k + 1, c + 1, i) for k, g in enumerate(order) for c, i in enumerate(result.groups[g])]
    return from_rows("designs", TIMED_HEADS, leads), from_rows("cognates", TIMED_HEADS, members)


def timed_path_report(result: Any, digits: int) -> Report:
    """The report of five points with prescribed crank angles (synthesis.path.TimedPathSynthesis)."""
    tables = timed_path_tables(result)
    title = "four-bars whose coupler point passes through five points at prescribed crank angles"

    def blocks() -> list[Block]:
        out: list[Block] = [Text(title, "bold"), *[Text(line) for line in timed_summary(result)], Text("")]
        out.append(terminal_table(tables[0], TIMED_TERMINAL, digits))
        out.append(Text("defects: branch, the points are not all on one circuit; order, the circuit meets "
                        "them out of order; transmission, the least transmission angle from the first point "
                        "to the last is below --min-transmission; grashof, the crank cannot turn one way "
                        "from the first point to the last; timing, the crank's turn from the first point is "
                        "not the prescribed one. A design's Roberts cognate with the same timing is in the "
                        "cognates table (--table cognates -f csv)"))
        return out

    def document() -> dict[str, Any]:
        s = result.solutions
        return {"title": title, "crank_dyads": len(s.cranks.cranks), "four_bars": len(result.designs),
                "designs": len(result.groups),
                "without_defects": sum(1 for g in result.groups if not result.designs[g[0]].defects),
                "failed_or_unsettled": s.incomplete()}

    return Report(title, tables, blocks, document)


def timed_summary(result: Any) -> list[str]:
    s = result.solutions
    rockers = ", ".join("-" if r is None else str(sum(1 for f in s.four_bars if f.crank == i))
                        for i, r in enumerate(s.rockers)) or "none"
    clean = sum(1 for g in result.groups if not result.designs[g[0]].defects)
    missed = s.incomplete()
    failed = sum(b.failed for b in s.problems())
    return [
        "prescribed timing (Sandor and Erdman's standard form): Burmester's five-pose problem for the crank "
        "dyads (the crank turned as prescribed), then for each one's rocker dyads (the coupler turned as "
        "that crank dyad turns it)",
        f"crank dyads: {len(s.cranks.cranks)} real ({s.cranks.complex_count} complex, {s.cranks.infinite} at "
        f"infinity, {s.cranks.failed} failed); rocker dyads of each: {rockers}; {len(result.designs)} "
        f"four-bars, {len(result.groups)} up to Roberts cognates, {clean} without defects",
        f"Burmester paths failed: {failed}; " + roots_line(s.problems(), missed),
    ]


def roots_line(problems: list[Any], missed: int) -> str:
    """What the Burmester problems' roots say: all four found in each, some not found (a
    four-bar may be missing), or fewer finite (the others at infinity: points in special
    position)."""
    from ..synthesis.timed_path import BURMESTER_ROOTS

    if missed:
        return f"{missed} root{'s' if missed != 1 else ''} not found (a four-bar may be missing)"
    few = sum(1 for b in problems if len(b.cranks) + b.complex_count < BURMESTER_ROOTS)
    if few:
        return (f"{few} of the {len(problems)} problems have fewer than {BURMESTER_ROOTS} finite roots "
                "(the others at infinity: points in special position)")
    return f"every problem's {BURMESTER_ROOTS} roots found (real and complex)"
