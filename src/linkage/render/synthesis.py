"""``linkage synthesize``: the report (precision points, linkage, structural error, defects),
the mechanism file of the result and the error plot."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..problems.closed_form import TRANSMISSION
from ..units import radians
from .data import Report, from_rows
from .report import Block, Text, fmt, table

EQUATION = "R1 cos(alpha) - R2 cos(phi) + R3 = cos(alpha - phi)"


def title(s: Any) -> str:
    (x0, x1), (a0, a1), (p0, p1) = s.x_range, s.alpha_range, s.phi_range
    return (
        f"function generator for y = {s.function}: x {x0:g}..{x1:g} -> alpha {a0:g}..{a1:g} deg, "
        f"y -> phi {p0:g}..{p1:g} deg"
    )


def real_angles(s: Any, alpha_deg: float, phi_deg: float) -> tuple[float, float]:
    """A position in the mechanism file's convention (ground O2 -> O4 along +x, angles from
    +x): theta2 = alpha + 180 and theta4 = phi + 180 (freudenstein.file_convention), with
    another 180 for a link drawn the other way."""
    k = s.linkage
    t2 = alpha_deg + k.alpha_shift() + 180.0
    t4 = phi_deg + k.phi_shift() + 180.0
    return math.remainder(t2, 360.0), math.remainder(t4, 360.0)


def check_command(s: Any, digits: int = 12) -> str | None:
    """``linkage solve --links`` of the result at the first precision point: the iteration
    table for the real linkage (its own alpha and phi: + 180 for a link drawn the other
    way), started at the precision point's phi so it stays on the followed assembly."""
    k = s.linkage
    if k is None:
        return None
    p = s.precision_points[0]
    alpha = (p.alpha_deg + k.alpha_shift()) % 360.0  # one turn, as a person gives it
    phi = math.remainder(p.phi_deg + k.phi_shift(), 360.0)  # started on the followed branch
    return (
        f"linkage solve --links {k.a:.{digits}g} {k.b:.{digits}g} {k.c:.{digits}g} {k.d:.{digits}g} "
        f"--alpha {alpha:.{digits}g} --x0 {phi:.{digits}g}"
    )


PP_HEADERS = [
    ("point", "", "int"),
    ("x", "", "number"),
    ("y", "", "number"),
    ("alpha", "deg", "number"),
    ("phi", "deg", "number"),
    ("residual", "", "number"),
]
"""The precision points' table: name, unit, kind."""
CURVE_HEADERS = [
    ("x", "", "number"),
    ("y", "", "number"),
    ("alpha", "deg", "number"),
    ("phi_desired", "deg", "number"),
    ("phi_generated", "deg", "number"),
    ("error", "deg", "number"),
    ("error_y", "", "number"),
    (TRANSMISSION, "deg", "number"),
    ("status", "", "text"),
]
"""The structural error's table: name, unit, kind."""
SPACING_WORDS = {
    "at": "given (--at)",
    "chebyshev": "Chebyshev",
    "uniform": "uniform (ends included)",
    "optimal": "optimal (equal ripple)",
}


def synthesis_report(s: Any, digits: int = 6, unit: str = "") -> Report:
    pp_rows = [(j + 1, p.x, p.y, p.alpha_deg, p.phi_deg, p.residual)
               for j, p in enumerate(s.precision_points)]
    curve_rows = [
        (c.x, c.y, c.alpha_deg, c.phi_desired_deg, c.phi_generated_deg, c.error_deg, c.error_y,
         c.transmission_deg, c.status)
        for c in s.curve
    ]
    k = s.linkage
    links = (
        ()
        if k is None
        else (
            # the design itself, in CSV and xlsx too (JSON also has it as "links")
            from_rows(
                "linkage",
                [("link", "", "text"), ("length", unit, "number")],
                [("input", k.a), ("coupler", k.b), ("output", k.c), ("ground", k.d)],
            ),
        )
    )
    tables = (
        from_rows("precision_points", PP_HEADERS, pp_rows),
        *links,
        from_rows("structural_error", CURVE_HEADERS, curve_rows),
    )

    def blocks() -> list[Block]:
        return design_blocks(s, digits, unit, pp_rows, curve_rows) + figure_blocks(s, digits)

    def document() -> dict[str, Any]:
        return document_of(s)

    return Report(title(s), tables, blocks, document)


def headed(headers: list[tuple[str, str, str]]) -> list[str]:
    """Column titles with their units: ``name (unit)``."""
    return [h if not u else f"{h} ({u})" for h, u, _ in headers]


def design_blocks(s: Any, digits: int, unit: str, pp_rows: list[Any], curve_rows: list[Any]) -> list[Block]:
    """The report's text down to the structural error's table: the equation, the precision
    points, R, the linkage, the notes and the table."""
    n = len(s.precision_points)
    fit = "solved exactly" if n == 3 else f"least squares (QR), residual |A R - b| = {s.fit_residual:.3g}"
    out: list[Block] = [
        Text(title(s), "bold"),
        Text(f"Freudenstein's equation: {EQUATION}; alpha at O2, phi at O4, both from the line O4 -> O2"),
        Text(f"{n} precision points, {SPACING_WORDS[s.spacing]} spacing; " + fit),
        Text(""),
        table("precision points", headed(PP_HEADERS), pp_rows, digits),
        Text(f"R1 = {fmt(s.R[0], 12)}, R2 = {fmt(s.R[1], 12)}, R3 = {fmt(s.R[2], 12)}"),
    ]
    k = s.linkage
    if k is not None:
        u = f" ({unit})" if unit else ""
        rows = [("input (O2 A)", k.a), ("coupler (A B)", k.b), ("output (O4 B)", k.c),
                ("ground (O2 O4)", k.d)]
        out += [
            Text(""),
            table(f"linkage ({s.grashof}, {s.branch} assembly at point 1)", ["link", f"length{u}"],
                  rows, digits),
        ]
    out += [Text(f"note: {n_}", "yellow") for n_ in s.notes]
    if s.curve:
        out += [
            Text(""),
            table("structural error (phi generated - phi desired), followed from point 1",
                  headed(CURVE_HEADERS), curve_rows, digits),
        ]
    return out


def figure_blocks(s: Any, digits: int) -> list[Block]:
    """The report's figures after the table: the max error, Chebyshev's for comparison, the
    transmission angle, the check command and the defects."""
    out: list[Block] = []
    if s.max_error_deg is not None:
        partly = any(c.status != "converged" for c in s.curve)
        out.append(Text(
            f"max |error| = {fmt(s.max_error_deg, digits)} deg = {fmt(s.max_error_y, digits)} in y, "
            f"at x = {fmt(s.at_x, digits)}" + (", over the part of the range reached" if partly else "")
        ))
    if s.chebyshev_max_error_deg is not None:
        spread = "" if s.equioscillation is None else f"; extrema equal within {100 * s.equioscillation:.2g}%"
        out.append(Text(f"Chebyshev spacing's max |error| = {fmt(s.chebyshev_max_error_deg, digits)} "
                        f"deg{spread}"))
    if s.transmission is not None:
        out.append(Text(
            f"{TRANSMISSION}: min {fmt(s.transmission[0], 4)} deg "
            f"(at x = {fmt(s.transmission_at_x, digits)}), max {fmt(s.transmission[1], 4)} deg"
        ))
    cmd = check_command(s)
    if cmd:
        out.append(Text(f"check: {cmd}"))
    out += [Text(f"defect: {d.message}", "red") for d in s.defects]
    if not s.defects:
        out.append(Text("no defects", "green"))
    return out


def document_of(s: Any) -> dict[str, Any]:
    k = s.linkage
    return {
        "function": s.function,
        "x_range": list(s.x_range),
        "alpha_range": list(s.alpha_range),
        "phi_range": list(s.phi_range),
        "spacing": s.spacing,
        "R1": s.R[0],
        "R2": s.R[1],
        "R3": s.R[2],
        "fit_residual": s.fit_residual,
        "links": s.links,
        "turned": None if k is None else {"input": k.input_turned, "output": k.output_turned},
        "grashof": s.grashof,
        "branch": s.branch,
        "precision_points": [
            {"x": p.x, "y": p.y, "alpha": p.alpha_deg, "phi": p.phi_deg, "residual": p.residual}
            for p in s.precision_points
        ],
        "structural_error": {
            "max_deg": s.max_error_deg,
            "at_x": s.at_x,
            "max_y": s.max_error_y,
            "curve": [[c.x, c.error_deg] for c in s.curve],
            "extrema": [[x, e] for x, e in s.extrema],
            "chebyshev_max_deg": s.chebyshev_max_error_deg,
            "equioscillation": s.equioscillation,
        },
        "transmission": None
        if s.transmission is None
        else {"min": s.transmission[0], "max": s.transmission[1], "at_x_min": s.transmission_at_x},
        "defects": s.defect_names,
        "defect_messages": [d.message for d in s.defects],
        "notes": list(s.notes),
        "check": check_command(s),
    }


def design_text(s: Any, unit: str, made_by: str) -> str:
    """The result as a joints-form mechanism file, drawn at the first precision point as
    the linkage generates it (synthesis.drawn_position: the file's joints give the reported
    lengths), its driver range the alpha range (in the file's convention: theta = alpha +
    180). ValueError where the linkage has no position at precision point 1."""
    from ..problems.toml_text import toml_value
    from ..synthesis.function import drawn_position

    k = s.linkage
    p = s.precision_points[0]
    drawn = drawn_position(s)
    if drawn is None:
        raise ValueError("the linkage has no position at precision point 1 to draw")
    t2, t4 = real_angles(s, *drawn)
    a_pt = (k.a * math.cos(radians(t2)), k.a * math.sin(radians(t2)))
    b_pt = (k.d + k.c * math.cos(radians(t4)), k.c * math.sin(radians(t4)))
    a0, a1 = s.alpha_range
    shift = 180.0 + k.alpha_shift()
    r0, r1 = a0 + shift, a1 + shift
    # the drawn value and the range in one turn: the range's numbers as the sweep runs them
    turn = 360.0 * math.floor(min(r0, r1) / 360.0)
    lo, hi = sorted((r0 - turn, r1 - turn))
    value = p.alpha_deg + shift - turn
    lines = [
        f"# A function generator for y = {s.function} (linkage synthesize), made by:",
        f"#   {made_by}",
        f"# x {s.x_range[0]:g}..{s.x_range[1]:g} -> alpha {a0:g}..{a1:g} deg at O2; y -> phi "
        f"{s.phi_range[0]:g}..{s.phi_range[1]:g} deg at O4 (both from the line O4 -> O2).",
        f"# In this file angles are from +x (O2 -> O4): theta_crank = {_plus('alpha', shift)}, "
        f"theta_rocker = {_plus('phi', 180.0 + k.phi_shift())} (mod 360).",
        f"# Max structural error {s.max_error_deg:.6g} deg at x = {s.at_x:.6g}; {s.grashof}; "
        f"drawn at precision point 1 (x = {p.x:.12g})."
        if s.max_error_deg is not None
        else "# No structural error curve (see the defects).",
    ]
    if s.defects:
        lines.append("# DEFECTS: " + "; ".join(s.defect_names))
    lines += [
        "",
        f"name = {toml_value('function generator: y = ' + s.function)}",
        f"length_unit = {toml_value(unit)}",
        'ground = ["O2", "O4"]  # fixed joints',
        "",
        f"[joints]  # one pose, in {unit}: precision point 1",
        f"O2 = {toml_value([0.0, 0.0])}  # the input's ground pivot",
        f"A = {toml_value([a_pt[0], a_pt[1]])}  # the input's pin",
        f"B = {toml_value([b_pt[0], b_pt[1]])}  # coupler and output",
        f"O4 = {toml_value([k.d, 0.0])}  # the output's ground pivot",
        "",
        "[links]",
        'crank = ["O2", "A"]  # the input (alpha)',
        'coupler = ["A", "B"]',
        'rocker = ["O4", "B"]  # the output (phi)',
        "",
        "[driver]",
        'link = "crank"  # its angle O2 -> A, degrees',
        f"value = {toml_value(value)}  # {_plus('alpha', shift)} at precision point 1",
        f"range = {toml_value([lo, hi])}  # the alpha range {a0:g}..{a1:g}"
        + ("" if _plus("alpha", shift) == "alpha" else f", as {_plus('alpha', shift)}"),
    ]
    return "\n".join(lines) + "\n"


def write_design(s: Any, path: Path, unit: str, made_by: str,
                 write: Callable[[Path, str], None] | None = None) -> str | None:
    """``synthesize -o FILE.toml``: the result written as :func:`design_text` (completely or
    not at all: ``write``, by default files.write_atomic; the command passes the one rule
    for writing mechanism files), or why not (None: written)."""
    from ..files import write_atomic
    from ..synthesis.function import drawn_position

    if s.linkage is None:
        return "there is no real linkage"
    if drawn_position(s) is None:
        return "the linkage cannot be assembled at precision point 1 (the pose a file is drawn at)"
    (write or write_atomic)(path, design_text(s, unit, made_by))
    return None


def _plus(name: str, shift: float) -> str:
    s = shift % 360.0
    return name if s == 0.0 else f"{name} + {s:g}"


def error_plot(s: Any, path: Path) -> None:
    """The structural error against x, the precision points marked, the largest error noted."""
    from .plots import pyplot, save_figure

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    from ..synthesis.function import dense_curve

    curve = dense_curve(s)
    xs = [c.x for c in curve if c.error_deg is not None]
    es = [c.error_deg for c in curve if c.error_deg is not None]
    ax.plot(xs, es, "-", color="C0", lw=1.6, label="phi generated - phi desired")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.plot(
        [p.x for p in s.precision_points],
        [0.0] * len(s.precision_points),
        "o",
        color="C3",
        label="precision points",
    )
    if s.max_error_deg is not None:
        worst = next(c for c in s.curve if c.x == s.at_x)
        ax.plot([worst.x], [worst.error_deg], "s", color="C1", label=f"max |error| {s.max_error_deg:.3g} deg")
    ax.set_xlabel("x")
    ax.set_ylabel("structural error (deg)")
    said = f" (defects: {', '.join(s.defect_names)})" if s.defects else ""
    ax.set_title(f"y = {s.function}: {s.spacing} spacing{said}", fontsize=10,
                 color="C3" if s.defects else "black")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    save_figure(fig, path)


SEARCH_COLUMNS = (
    ("design", "", "int"),
    ("alpha0", "deg", "number"),
    ("alpha_span", "deg", "number"),
    ("phi0", "deg", "number"),
    ("phi_span", "deg", "number"),
    ("max_error_deg", "", "number"),
    ("at_x", "", "number"),
    ("max_error_y", "", "number"),
    ("min_transmission_deg", "", "number"),
    ("grashof", "", "text"),
    ("input", "", "number"),
    ("coupler", "", "number"),
    ("output", "", "number"),
    ("ground", "", "number"),
    ("R1", "", "number"),
    ("R2", "", "number"),
    ("R3", "", "number"),
)


def best_command(job: Any, row: dict[str, Any]) -> str:
    """The ``linkage synthesize`` line of one candidate."""
    import shlex

    a0, da, p0, dp = (float(row[k]) for k in ("alpha0", "alpha_span", "phi0", "phi_span"))
    words = [
        "linkage",
        "synthesize",
        "--function",
        job.text,
        "--x",
        f"{job.x_range[0]:.17g}:{job.x_range[1]:.17g}",
        "--alpha",
        f"{a0:.17g}:{a0 + da:.17g}",
        "--phi",
        f"{p0:.17g}:{p0 + dp:.17g}",
    ]
    if job.at is not None:
        words += ["--at", ",".join(f"{v:.17g}" for v in job.at)]
    else:
        words += ["--points", str(job.points), "--spacing", job.spacing]
    if job.ground != 1.0:
        words += ["--ground", f"{job.ground:.17g}"]
    if job.min_transmission != 30.0:
        words += ["--min-transmission", f"{job.min_transmission:.17g}"]
    return " ".join(shlex.quote(w) for w in words)


def search_report(result: Any, digits: int = 6, seconds: float | None = None) -> Report:
    from .data import DataTable, column

    rows = result.rows
    n = len(rows.get("design", ()))
    tables = (
        DataTable(
            "candidates",
            tuple(
                column(name, unit, list(rows[name]) if n else [], kind) for name, unit, kind in SEARCH_COLUMNS
            ),
        ),
    )
    job = result.job
    head = (
        f"search for y = {job.text}, x {job.x_range[0]:g}..{job.x_range[1]:g}: "
        f"{result.scanned:,} candidates, "
        f"{result.without_defects:,} without defects (transmission >= {job.min_transmission:g} deg)"
    )

    def blocks() -> list[Block]:
        out: list[Block] = [Text(head, "bold")]
        if seconds is not None:
            out.append(
                Text(
                    f"in {seconds:.3g} s; the best {n} by max structural error (the grid's twin of "
                    "synthesize's rules: run a candidate's command for its full report)"
                )
            )
        if n:
            shown = [
                ("design", ""),
                ("alpha0", "deg"),
                ("alpha_span", "deg"),
                ("phi0", "deg"),
                ("phi_span", "deg"),
                ("max_error_deg", ""),
                ("at_x", ""),
                ("min_transmission_deg", ""),
                ("grashof", ""),
            ]
            out.append(
                table(
                    "",
                    [f"{k} ({u})" if u else k for k, u in shown],
                    [tuple(_plain(rows[k][i]) for k, _ in shown) for i in range(n)],
                    digits,
                )
            )
            best = {k: rows[k][0] for k in rows}
            out.append(Text(f"best: {best_command(job, best)}"))
        else:
            out.append(
                Text("no candidate without defects: widen the ranges or lower --min-transmission", "red")
            )
        return out

    def document() -> dict[str, Any]:
        return {
            "function": job.text,
            "x_range": list(job.x_range),
            "candidates": result.scanned,
            "without_defects": result.without_defects,
            "min_transmission": job.min_transmission,
            "best": best_command(job, {k: rows[k][0] for k in rows}) if n else None,
        }

    return Report(head, tables, blocks, document)


def _plain(v: Any) -> Any:
    """A numpy scalar as the Python number or text the table formats."""
    if hasattr(v, "item"):
        return v.item()
    return v
