"""The report of ``linkage synthesize --path``: the four-bars through nine points."""

from __future__ import annotations

from typing import Any

from .data import DataTable, Report, from_rows
from .report import Block, Text, table


def ranked(result: Any) -> list[int]:
    """Real designs, those without defects first, then by least transmission, largest first."""
    designs = result.designs
    return sorted(range(len(designs)),
                  key=lambda i: (len(designs[i][0].defects), -designs[i][0].transmission_min_deg))


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
                                 ("unsettled", "", "int"), ("steps", "", "int")], routes))


def certified_line(result: Any) -> str:
    """The alpha test's verdict on the real four-bars (``result.certificates``,
    :func:`linkage.synthesis.path.real_certificates`): how many are certified real, and
    whether all are told apart."""
    certs, apart = result.certificates
    return (f"alpha test (Smale; 50 digits): {sum(c.certified and c.real for c in certs)} of the "
            f"{len(certs)} real four-bars certified real"
            + (", all distinct" if not apart else f", {len(apart)} pair(s) not told apart"))


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


TERMINAL_COLUMNS = ("design", "grashof", "defects", "ground", "crank", "coupler", "rocker",
                    "transmission_min", "point_error")


def path_report(result: Any, digits: int) -> Report:
    tables = path_tables(result)
    title = "four-bars whose coupler point passes through nine points"

    def blocks() -> list[Block]:
        out: list[Block] = [Text(title, "bold"), *[Text(line) for line in summary_lines(result)], Text("")]
        # the pivots' coordinates go to files (-f, -o): a terminal gets the judgement
        shown = [c for c in tables[0].columns if c.name in TERMINAL_COLUMNS]
        rows = list(zip(*[c.values for c in shown]))
        out.append(table("", [c.header for c in shown], rows, digits))
        out.append(Text("defects: branch, the points are not all on one circuit (the linkage would have "
                        "to be taken apart); order, the circuit meets them out of order; transmission, the "
                        "least transmission angle from the first point to the last is below "
                        "--min-transmission; each design's two Roberts cognates are in the cognates table"))
        rows = list(zip(*[c.values for c in tables[2].columns]))
        out += [Text("Routes"), table("", [c.header for c in tables[2].columns], rows, digits)]
        return out

    def document() -> dict[str, Any]:
        s = result.solutions
        return {"title": title, "paths": s.paths, "routes": s.routes, "found": result.found,
                "missing": result.missing, "real": len(result.designs),
                "without_defects": sum(1 for g in result.designs if not g[0].defects), "seconds": s.seconds}

    return Report(title, tables, blocks, document)
