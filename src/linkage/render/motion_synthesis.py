"""linkage synthesize --motion: the report (Burmester's cranks, every four-bar from two of
them with its defects) and the chosen design as a joints-form file (docs/motion_synthesis.md)."""

from __future__ import annotations

from typing import Any

from ..problems.closed_form import TRANSMISSION
from ..units import radians
from .assemblies import certified_line
from .data import Report, from_rows
from .report import Block, Text, fmt, table

CRANK_HEADERS = [
    ("crank", "", "int"),
    ("centre_x", "", "number"),
    ("centre_y", "", "number"),
    ("circle_x", "", "number"),
    ("circle_y", "", "number"),
    ("length", "", "number"),
    ("residual", "", "number"),
]
"""Burmester's cranks: the ground pivot (centre point), the moving pivot at pose 1 (circle
point), the crank's length and its rigidity residual (relative to the poses' size)."""
DESIGN_HEADERS = [
    ("design", "", "int"),
    ("input_crank", "", "int"),
    ("output_crank", "", "int"),
    ("input", "", "number"),
    ("coupler", "", "number"),
    ("output", "", "number"),
    ("ground", "", "number"),
    ("grashof", "", "text"),
    ("min_" + TRANSMISSION, "deg", "number"),
    ("max_pose_error", "", "number"),
    ("defects", "", "text"),
]


POSE_ERROR = ("max_pose_error: the largest distance from a pose, a position's over the poses' size or an "
              "angle's in rad (not a length)")
"""What max_pose_error is, below the table whose title gives the lengths' unit."""


def best_design(m: Any) -> int | None:
    """The design -o writes by default: of those without defects, the largest least
    transmission angle (the first of equals); None without one."""
    free = [k for k, d in enumerate(m.designs) if not d.defects]
    return max(free, key=lambda k: (m.designs[k].min_transmission_deg or 0.0, -k)) if free else None


CURVE_HEADERS = [
    ("centre_x", "", "number"),
    ("centre_y", "", "number"),
    ("circle_x", "", "number"),
    ("circle_y", "", "number"),
    ("spread", "", "number"),
]
"""Four poses: points of the centre-point curve with their circle points (at pose 1) and the
crank's spread in length over the poses (relative to their size)."""
FOUR_FREE = ("four poses leave one free number for each crank: its ground pivot anywhere on the "
             "centre-point curve (a cubic), its moving pivot the matching point of the circle-point "
             "curve; two of them make a four-bar")


def curves_report(m: Any, digits: int = 6, unit: str = "") -> Report:
    """Four poses: the curves' points (every one in the table; the terminal says how many)."""
    c = m.curves
    rows = [(g.real, g.imag, w.real, w.imag, s) for g, w, s in zip(c.centre, c.circle, c.spread)]
    title = "motion generation through 4 poses: the centre-point and circle-point curves"

    def blocks() -> list[Block]:
        return [
            Text(title, "bold"),
            Text(FOUR_FREE),
            Text(f"{len(rows)} points of the curve where it crosses a grid over x {fmt(c.box[0], 4)} to "
                 f"{fmt(c.box[1], 4)}, y {fmt(c.box[2], 4)} to {fmt(c.box[3], 4)} {unit}; "
                 f"largest spread of a crank's length over the poses "
                 f"{fmt(max((r[4] for r in rows), default=0.0), 3)} of their size"),
            Text("every point: -f csv (or json); the picture: --plot FILE.png"),
        ]

    return Report(title, (from_rows("curves", CURVE_HEADERS, rows),), blocks, None)


def curves_plot(m: Any, path: Any, unit: str = "") -> None:
    """The centre-point curve, the circle-point curve and the poses (a dot and a tick for each
    body's angle), equal axes."""
    import numpy as np

    from .plots import pyplot, save_figure

    plt = pyplot()
    c = m.curves
    fig, ax = plt.subplots(figsize=(7, 6))
    ax.plot(c.centre.real, c.centre.imag, ".", ms=2, color="tab:blue",
            label="centre-point curve (ground pivots)")
    ax.plot(c.circle.real, c.circle.imag, ".", ms=2, color="tab:orange",
            label="circle-point curve (moving pivots at pose 1)")
    size = max(np.hypot(p.x - m.poses[0].x, p.y - m.poses[0].y) for p in m.poses) or 1.0
    for k, p in enumerate(m.poses):
        tip = complex(p.x, p.y) + 0.25 * size * np.exp(1j * radians(p.angle_deg))
        ax.plot([p.x, tip.real], [p.y, tip.imag], "-", color="black", lw=1.5)
        ax.plot([p.x], [p.y], "o", color="black", ms=4)
        ax.annotate(str(k + 1), (p.x, p.y), textcoords="offset points", xytext=(4, 4))
    ax.set_xlim(c.box[0], c.box[1])
    ax.set_ylim(c.box[2], c.box[3])
    ax.set_aspect("equal")
    u = f" ({unit})" if unit else ""
    ax.set_xlabel("x" + u)
    ax.set_ylabel("y" + u)
    ax.set_title("four poses: centre-point and circle-point curves")
    ax.legend(loc="best", fontsize=8)
    save_figure(fig, path)


def motion_report(m: Any, digits: int = 6, unit: str = "") -> Report:
    if m.curves is not None:
        return curves_report(m, digits, unit)
    u = f" ({unit})" if unit else ""
    cranks = [(k + 1, *c.ground, *c.first, c.length, c.residual) for k, c in enumerate(m.cranks)]
    designs = [
        (k + 1, d.cranks[0] + 1, d.cranks[1] + 1, d.links["input"], d.links["coupler"], d.links["output"],
         d.links["ground"], d.grashof, d.min_transmission_deg,
         None if None in d.pose_error else max(d.pose_error), " ".join(d.defect_names))
        for k, d in enumerate(m.designs)
    ]
    tables = (from_rows("cranks", CRANK_HEADERS, cranks),
              from_rows("designs", DESIGN_HEADERS, designs))
    title = f"motion generation through {len(m.poses)} poses"

    def blocks() -> list[Block]:
        account = [Text(crank_account(m))]
        if m.burmester is not None:
            account.append(Text(certified_line(m.burmester.solutions)))
        if m.cranks:
            largest = fmt(max(c.residual for c in m.cranks), 3)
            account.append(Text("each crank's rigidity residual (relative to the poses' size) at most "
                                f"{largest}; a four-bar's input and output links are its two cranks"))
        out: list[Block] = [Text(title, "bold"), *account, Text(""),
                            shown_table(("Burmester cranks" if m.burmester else "cranks") + u,
                                        CRANK_HEADERS, cranks, digits, ("residual",))]
        four_bars = f"four-bars{u}: input crank O2 -> A, output crank O4 -> B, the body the coupler"
        out += [Text(""), shown_table(four_bars, DESIGN_HEADERS, designs, digits, ("input", "output")),
                Text(POSE_ERROR)]
        best = best_design(m)
        if best is None:
            out.append(Text("defect: no four-bar from these cranks carries the body through every pose "
                            "in order on one assembly with the transmission asked for", "red"))
        else:
            out.append(Text(f"best: design {best + 1} (no defects; least {TRANSMISSION} "
                            f"{fmt(m.designs[best].min_transmission_deg, 4)} deg)", "green"))
        return out

    return Report(title, tables, blocks, None)


def shown_table(title: str, heads: list[tuple[str, str, str]], rows: list[tuple[Any, ...]], digits: int,
                hide: tuple[str, ...]) -> Block:
    """A table as a person reads it, without the columns ``hide`` names: what the lines above
    it say (the cranks' residuals, the input and output cranks' lengths, which are the cranks
    table's). Files (-f, -o) keep every column. At 80 columns the cranks table then fits
    and the four-bars table stacks in two parts, not three."""
    keep = [j for j, (h, _, _) in enumerate(heads) if h not in hide]
    return table(title, [heads[j][0] if not heads[j][1] else f"{heads[j][0]} ({heads[j][1]})" for j in keep],
                 [tuple(r[j] for j in keep) for r in rows], digits)


def crank_account(m: Any) -> str:
    """Where the cranks come from: the continuation's paths by class, or three poses' free choice."""
    from ..synthesis.motion import THREE_FREE

    b = m.burmester
    if b is None:
        return f"{THREE_FREE}; the cranks of the circle points given:"
    return (f"{len(b.cranks)} real Burmester cranks (centre point, circle point at pose 1); "
            f"paths: {b.complex_count} complex, {b.infinite} at infinity, {b.singular} singular, "
            f"{b.failed} failed" + (f", {b.unresolved} not rigid after Newton" if b.unresolved else ""))


def motion_design_text(m: Any, k: int, unit: str, made_by: str) -> str:
    """Design ``k`` as a joints-form mechanism file drawn at pose 1, its driver range the
    input's travel through the poses."""
    from ..synthesis.motion import mechanism_text, pose_order

    d = m.designs[k]
    s, travel, _ = pose_order(d.input_deg)
    start = d.input_deg[0]
    poses = "; ".join(f"({p.x:.12g}, {p.y:.12g}, {p.angle_deg:.12g} deg)" for p in m.poses)
    head = [
        f"# A motion generator through {len(m.poses)} poses (linkage synthesize --motion), made by:",
        f"#   {made_by}",
        f"# poses (x, y, body angle): {poses}",
        f"# design {k + 1}: Burmester cranks {d.cranks[0] + 1} (input) and {d.cranks[1] + 1} (output); "
        f"{d.grashof}; least {TRANSMISSION} {fmt(d.min_transmission_deg, 4)} deg; drawn at pose 1.",
        f"# the input turns {'anticlockwise' if s > 0 else 'clockwise'} from pose 1 through the others: "
        + ", ".join(f"{start + s * u:.6g}" for u in travel) + " deg.",
    ]
    if d.defects:
        head.append("# DEFECTS: " + "; ".join(x.message for x in d.defects))
    body = mechanism_text(d.joints, start, (start, start + s * travel[-1]),
                          name=f"motion generator, design {k + 1}", unit=unit)
    return "\n".join(head) + "\n" + body
