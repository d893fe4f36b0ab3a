"""The instant centres' report (every format, through the writers' registry) and their
pictures: the centres on the mechanism's drawing, and the fixed and moving centrodes."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .data import Report, from_rows
from .report import Block, Text, denoise, fmt, table


def _where_scale(ic: Any) -> float:
    xs = [abs(v) for c in ic.centres for v in (c.x, c.y) if v is not None and math.isfinite(v)]
    return max(xs, default=1.0)


def centre_rows(ic: Any) -> list[tuple[Any, ...]]:
    return [(c.label, c.i, c.j, c.x, c.y, c.kind, c.direction_deg, c.how, ", ".join(c.via), c.residual,
             c.velocity_separation) for c in ic.centres]


def centrode_rows(cd: Any) -> list[tuple[Any, ...]]:
    return [(p.input, p.status, p.fixed.x, p.fixed.y, p.fixed.kind, p.fixed.direction_deg,
             p.moving.x, p.moving.y, p.moving.kind, p.moving.direction_deg) for p in cd.points]


def centres_report(ic: Any, digits: int, cd: Any = None) -> Report:
    """The centres at the pose (and with ``cd`` the centrodes over the sweep) as a report:
    tables with every column's unit, the display, and the JSON document."""
    unit = ic.length_unit
    tables = [from_rows("centres", [("centre", "", "text"), ("body_i", "", "text"), ("body_j", "", "text"),
                                    ("x", unit, "number"), ("y", unit, "number"), ("where", "", "text"),
                                    ("direction", "deg", "number"), ("how", "", "text"),
                                    ("on_lines", "", "text"), ("velocity_check", "", "number"),
                                    ("velocity_separation", "", "number")], centre_rows(ic))]
    if cd is not None:
        tables.append(from_rows("centrodes", [
            (cd.driver, cd.driver_unit, "number"), ("status", "", "text"),
            ("fixed_x", unit, "number"), ("fixed_y", unit, "number"), ("fixed_where", "", "text"),
            ("fixed_direction", "deg", "number"), ("moving_x", unit, "number"), ("moving_y", unit, "number"),
            ("moving_where", "", "text"), ("moving_direction", "deg", "number")], centrode_rows(cd)))
    title = (f"{ic.mechanism}: instant centres at {ic.driver} = {fmt(ic.driver_value, digits)} "
             f"{ic.driver_unit}")

    def blocks() -> list[Block]:
        scale = _where_scale(ic)
        names = ", ".join(f"{k + 1} {b}" for k, b in enumerate(ic.bodies))
        out: list[Block] = [Text(title, "bold"), Text(f"bodies: {names}")]
        if ic.converted:
            out.append(Text("(a loops-form file: its bodies named as linkage convert --form joints "
                            "draws it)"))
        rows = [(c.label, c.i, c.j, denoise(c.x, scale), denoise(c.y, scale), c.kind, c.direction_deg,
                 c.how + (f": {' x '.join(c.via)}" if c.via else ""),
                 None if c.residual is None else float(f"{c.residual:.2g}"))
                for c in ic.centres]
        out += [Text(""), table("", ["centre", "body i", "body j", f"x ({unit})", f"y ({unit})", "where",
                                     "direction (deg)", "how", "velocity check"], rows, digits)]
        out += [Text(f"status: {ic.status}: {ic.message}", "" if ic.status == "ok" else "red")]
        if cd is not None:
            out += centrode_blocks(cd, digits)
        return out

    def document() -> dict[str, Any]:
        doc: dict[str, Any] = {"title": title, "mechanism": ic.mechanism, "driver": ic.driver,
                               "driver_value": ic.driver_value, "driver_unit": ic.driver_unit,
                               "length_unit": unit, "bodies": list(ic.bodies), "status": ic.status,
                               "message": ic.message, "worst_velocity_check": ic.worst_residual,
                               "converted_from_loops": ic.converted}
        if cd is not None:
            doc["centrodes"] = {"body": cd.body, "relative_to": "ground", "moving_frame":
                                f"from {cd.frame_joint}, x along {cd.body}'s angle",
                                "through_infinity": [list(span) for span in cd.through_infinity]}
        return doc

    return Report(title, tuple(tables), blocks, document)


def centrode_blocks(cd: Any, digits: int) -> list[Block]:
    unit = cd.length_unit
    at_inf = [p.input for p in cd.points if p.fixed.kind == "at infinity"]
    counts: dict[str, int] = {}
    for p in cd.points:
        key = p.fixed.kind if p.status == "ok" else p.status
        counts[key] = counts.get(key, 0) + 1
    scale = max((abs(v) for p in cd.points for v in (p.fixed.x, p.fixed.y, p.moving.x, p.moving.y)
                 if v is not None and math.isfinite(v) and abs(v) < 1e6 * cd.size), default=1.0)
    rows = [(p.input, p.status, denoise(p.fixed.x, scale), denoise(p.fixed.y, scale), p.fixed.direction_deg,
             denoise(p.moving.x, scale), denoise(p.moving.y, scale), p.moving.direction_deg)
            for p in cd.points]
    out: list[Block] = [
        Text(""),
        Text(f"centrodes of {cd.body} relative to the ground over {cd.driver} (fixed: in the ground's frame; "
             f"moving: in {cd.body}'s, from {cd.frame_joint}, x along its angle)", "bold"),
        table("", [f"{cd.driver} ({cd.driver_unit})", "status", f"fixed x ({unit})", f"fixed y ({unit})",
                   "fixed at infinity (deg)", f"moving x ({unit})", f"moving y ({unit})",
                   "moving at infinity (deg)"], rows, digits),
        Text("positions: " + ", ".join(f"{k}: {n}" for k, n in counts.items())),
    ]
    crossing = cd.through_infinity
    if crossing:
        spans = ", ".join(f"{fmt(a, digits)} and {fmt(b, digits)}" for a, b in crossing)
        out.append(Text(f"the fixed centrode passes through infinity ({cd.body}'s angular velocity "
                        f"changes sign) between {cd.driver} = {spans} {cd.driver_unit}"))
    if at_inf:
        listed = ", ".join(fmt(v, digits) for v in at_inf[:12]) + (" ..." if len(at_inf) > 12 else "")
        out.append(Text(f"at infinity ({cd.body} translating for an instant) at {cd.driver} = "
                        f"{listed} {cd.driver_unit}"))
    return out


# --- pictures ----------------------------------------------------------------------------------

COLOURS = {"primary": "black", "Kennedy": "tab:purple", "velocity": "tab:green"}
WINDOW = 1.5
"""How far around the mechanism (times its extent) a picture shows: centres and centrode
points beyond it are listed, not plotted (a centre near infinity would shrink the
mechanism to a dot)."""


def _window(points: Sequence[tuple[float, float]]) -> tuple[float, float, float, float]:
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    cx, cy = (min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2
    half = max(max(xs) - min(xs), max(ys) - min(ys)) / 2 or 1.0
    reach = half * (1.0 + 2.0 * WINDOW)
    return cx - reach, cx + reach, cy - reach, cy + reach


def _inside(w: tuple[float, float, float, float], x: float | None, y: float | None) -> bool:
    return x is not None and y is not None and w[0] <= x <= w[1] and w[2] <= y <= w[3]


def centres_plot(pose: Any, ic: Any, path: Path, cd: Any = None) -> None:
    """The mechanism drawn at the pose with every finite centre on it (labelled, coloured by
    how it was found), those at infinity and those off the picture listed; with ``cd`` the
    fixed centrode and the moving one carried to the pose (they touch at the body's centre),
    broken wherever a point is at infinity or off the picture."""
    from .plots import SUFFIXES, draw_on, pyplot, save_figure

    if path.suffix.lower() not in SUFFIXES:
        from ..errors import InputError

        raise InputError(f"{path}: use one of {', '.join(SUFFIXES)} for the picture")
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 6.5))
    m = pose.mechanism
    title = f"{ic.mechanism}: instant centres at {ic.driver} = {ic.driver_value:.6g} {ic.driver_unit}"
    if cd is not None and cd.points:
        title += (f";\ncentrodes of the {cd.body} over {cd.driver} = {cd.points[0].input:g} to "
                  f"{cd.points[-1].input:g} {cd.driver_unit}")
    draw_on(ax, m, list(pose.q), pose.driver, title)
    w = _window(list(pose.rates.joints.values()))
    notes = []
    if cd is not None:
        _centrode_curves(ax, pose, cd, w)
    _construction_lines(ax, ic, w)
    shown: dict[tuple[float, float], list[Any]] = {}
    for c in ic.centres:
        if c.kind == "finite" and _inside(w, c.x, c.y):
            shown.setdefault((round(c.x, 9), round(c.y, 9)), []).append(c)
            ax.plot([c.x], [c.y], "s" if c.how != "primary" else "o", ms=5 if c.how == "primary" else 6,
                    color=COLOURS.get(c.how, "tab:red"), zorder=7)
    for (x, y), here in shown.items():
        # a pin's labels above right of it, a constructed centre's above left: a centre
        # beside a pin (a four-bar's I24 near O2) keeps its own label
        pin = any(c.how == "primary" for c in here)
        ax.annotate(", ".join(c.label for c in here), (x, y), textcoords="offset points",
                    xytext=(6, 5) if pin else (-6, 6), ha="left" if pin else "right", fontsize=8,
                    color="tab:purple", zorder=8)
    far = [f"{c.label} ({c.x:.4g}, {c.y:.4g})" for c in ic.centres
           if c.kind == "finite" and not _inside(w, c.x, c.y)]
    inf = [f"{c.label} at {c.direction_deg:.4g} deg" for c in ic.centres if c.kind == "at infinity"]
    if inf:
        notes.append("at infinity: " + ", ".join(inf))
    if far:
        notes.append("off the picture: " + ", ".join(far))
    undefined = [c.label for c in ic.centres if c.kind == "undefined"]
    if undefined:
        notes.append("undefined: " + ", ".join(undefined))
    notes.append("circles: primary (pins); squares: Kennedy (dotted: its lines)" +
                 (", green: from the velocities" if any(c.how == "velocity" for c in ic.centres) else ""))
    ax.set_aspect("equal", adjustable="box")  # the window is square: both limits hold
    ax.set_xlim(w[0], w[1])
    ax.set_ylim(w[2], w[3])
    import textwrap

    ax.set_title(title + "\n" + "\n".join(textwrap.fill(n, 110) for n in notes), fontsize=9)
    save_figure(fig, path)


def _construction_lines(ax: Any, ic: Any, w: tuple[float, float, float, float]) -> None:
    """Each Kennedy centre's two lines, thin and dotted: along each, from the finite one of
    its two centres (or both) to the centre it places."""
    by_label = {c.label: c for c in ic.centres}
    for c in ic.centres:
        if c.how != "Kennedy" or c.kind != "finite" or not _inside(w, c.x, c.y):
            continue
        for line in c.via:
            ends = [by_label[k] for k in line.split()]
            pts = [(e.x, e.y) for e in ends if e.kind == "finite"] + [(c.x, c.y)]
            if len(pts) < 2:
                continue
            a, b = max(((p, r) for p in pts for r in pts), key=lambda pr: math.dist(*pr))
            ax.plot([a[0], b[0]], [a[1], b[1]], color="tab:purple", lw=1.0, ls=":", zorder=1)


def _centrode_curves(ax: Any, pose: Any, cd: Any, w: tuple[float, float, float, float]) -> None:
    """The two centrodes, each a polyline broken (NaN) at every point not finite inside the
    picture; the moving one carried by the body's pose (its frame: from its first joint,
    x along its angle)."""
    from ..kinematics.centres import body_angle

    m = pose.mechanism
    turn = body_angle(m, pose.q, pose.driver, cd.body)
    c, s = math.cos(turn), math.sin(turn)
    ox, oy = pose.rates.joints[cd.frame_joint]

    breaks = {k + 1 for k, (a, b) in enumerate(zip(cd.points, cd.points[1:]))
              if a.omega is not None and b.omega is not None and a.omega * b.omega < 0.0}

    def curve(points: list[tuple[float | None, float | None]]) -> tuple[list[float], list[float]]:
        xs, ys = [], []
        for k, (x, y) in enumerate(points):
            if k in breaks:  # through infinity between these two: never join them
                xs.append(math.nan)
                ys.append(math.nan)
            ok = _inside(w, x, y)
            xs.append(x if ok else math.nan)  # type: ignore[arg-type]
            ys.append(y if ok else math.nan)  # type: ignore[arg-type]
        return xs, ys

    fixed = [(p.fixed.x, p.fixed.y) for p in cd.points]
    moving = [(ox + c * p.moving.x - s * p.moving.y, oy + s * p.moving.x + c * p.moving.y)
              if p.moving.kind == "finite" else (None, None) for p in cd.points]
    ax.plot(*curve(fixed), color="tab:orange", lw=1.8, label=f"fixed centrode (of {cd.body}, on the ground)")
    ax.plot(*curve(moving), color="tab:cyan", lw=1.8, ls="--",
            label=f"moving centrode (on {cd.body}, carried to this pose)")
    ax.legend(fontsize=8, loc="lower right")
