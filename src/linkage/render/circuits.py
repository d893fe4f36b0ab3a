"""The report of ``linkage assemblies --sweep``: every assembly, and the circuit it is on."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from .assemblies import assemblies_report
from .data import DataTable, Report, from_rows
from .report import Block, Text, table


def _driver_shown(m: Any, v: float) -> float:
    from ..problems.loops import ANGLE_UNITS

    return v / ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else v


def _driver_unit(m: Any) -> str:
    return m.driver.unit if m.driver.kind == "angle" else m.length_unit


def circuits_table(c: Any) -> DataTable:
    m = c.assemblies.mechanism
    unit = _driver_unit(m)
    rows = []
    for k, circ in enumerate(c.circuits):
        full = circ.full_turn
        rows.append((k + 1, " ".join(str(i + 1) for i in circ.members), " ".join(circ.branches), circ.status,
                     None if full else _driver_shown(m, circ.driver_low),
                     None if full else _driver_shown(m, circ.driver_high), full, len(circ.limits),
                     " ".join(f"{_driver_shown(m, v):.10g}" for v in circ.limits), circ.crossings,
                     circ.steps, circ.rejected))
    return from_rows("circuits", [
        ("circuit", "", "int"), ("assemblies", "", "text"), ("branches", "", "text"), ("status", "", "text"),
        (f"{m.driver.name}_low", unit, "number"), (f"{m.driver.name}_high", unit, "number"),
        ("full_turn", "", "bool"), ("limits", "", "int"), (f"limit_{m.driver.name}", unit, "text"),
        ("singular_points", "", "int"), ("steps", "", "int"), ("rejected", "", "int")], rows)


def circuit_lines(c: Any) -> list[str]:
    m = c.assemblies.mechanism
    n = len(c.circuits)
    out = [f"{n} circuit{'s' if n != 1 else ''} through the {len(c.assemblies.real)} real assemblies "
           "(followed by arc length through limit positions; assemblies on one circuit can be reached "
           "from one another by moving, on different circuits only by taking the mechanism apart)"]
    for k, circ in enumerate(c.circuits):
        who = ", ".join(str(i + 1) for i in circ.members)
        if circ.full_turn:
            how = f"{m.driver.name} turns fully"
        else:
            lo, hi = _driver_shown(m, circ.driver_low), _driver_shown(m, circ.driver_high)
            how = f"{m.driver.name} from {lo:.6f} to {hi:.6f} {_driver_unit(m)}"
        extra = "" if circ.status == "closed" else f"; {circ.status}: not followed to its end"
        if circ.crossings:
            extra += f"; passes {circ.crossings} singular point(s) where circuits meet (a change point)"
        out.append(f"circuit {k + 1}: assembl{'ies' if len(circ.members) > 1 else 'y'} {who}; {how}, "
                   f"{len(circ.limits)} limit position{'s' if len(circ.limits) != 1 else ''}{extra}")
    return out


TERMINAL_COLUMNS = ("circuit", "assemblies", "branches", "status", "limits", "singular_points")


def circuits_report(c: Any, digits: int, show_paths: bool) -> Report:
    base = assemblies_report(c.assemblies, digits, show_paths)
    extra = circuits_table(c)

    def blocks() -> list[Block]:
        # the lines above give each circuit's range and limits: the terminal's table keeps
        # what they do not, within 80 columns (files get every column, with the steps taken)
        shown = [col for col in extra.columns if col.name in TERMINAL_COLUMNS]
        rows = list(zip(*[col.values for col in shown]))
        return [*base.blocks(), Text("Circuits"), *[Text(line) for line in circuit_lines(c)],
                table("", [col.header for col in shown], rows, digits)]

    def document() -> dict[str, Any]:
        return {**base.document(), "circuits": len(c.circuits)}

    return Report(base.title, (*base.tables, extra), blocks, document)


def _window(values: list[float], period: float) -> float:
    """The lower end of a one-period window centred on the values' circular mean (so that
    a curve that stays within a turn is drawn in one piece)."""
    c = sum(math.cos(v * 2 * math.pi / period) for v in values)
    s = sum(math.sin(v * 2 * math.pi / period) for v in values)
    return math.atan2(s, c) * period / (2 * math.pi) - period / 2


def _wrapped(values: list[float], low: float, period: float) -> list[float]:
    return [low + (v - low) % period for v in values]


def _pieces(xs: list[float], ys: list[float],
            gaps: tuple[float, float]) -> list[tuple[list[float], list[float]]]:
    """The polyline cut where either coordinate jumps by more than half its period."""
    out = [([xs[0]], [ys[0]])]
    for a, b, ya, yb in zip(xs, xs[1:], ys, ys[1:]):
        if abs(b - a) > gaps[0] or abs(yb - ya) > gaps[1]:
            out.append(([], []))
        out[-1][0].append(b)
        out[-1][1].append(yb)
    return out


def circuits_plot(c: Any, path: Path) -> None:
    """Each unknown against the driver over every circuit, one colour per circuit, the
    assemblies at the start value marked and numbered, limit positions as dashed lines."""
    from ..problems.loops import ANGLE_UNITS
    from .plots import pyplot, save_figure

    plt = pyplot()
    m = c.assemblies.mechanism
    n = len(m.unknowns)
    fig, axes = plt.subplots(n, 1, figsize=(8, 2.6 * n + 0.6), sharex=True, squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    angle_driver = m.driver.kind == "angle"
    d_period = _driver_shown(m, 2 * math.pi) if angle_driver else math.inf
    d0 = _driver_shown(m, c.assemblies.driver)
    if angle_driver:
        full = any(circ.full_turn for circ in c.circuits)
        d_low = 0.0 if full else d0 - d_period / 2
    shown_d = [[_driver_shown(m, d) for d in circ.drivers] for circ in c.circuits]
    if angle_driver:
        shown_d = [_wrapped(xs, d_low, d_period) for xs in shown_d]
        d0 = _wrapped([d0], d_low, d_period)[0]
    for j, u in enumerate(m.unknowns):
        ax = axes[j][0]
        scale = ANGLE_UNITS[u.unit] if u.kind == "angle" else 1.0
        period = 2 * math.pi / scale if u.kind == "angle" else math.inf
        curves = [[q[j] / scale for q in circ.configurations] for circ in c.circuits]
        marks = [a.q[j] / scale for a in c.assemblies.real]
        if u.kind == "angle":
            # -180..180 unless a window centred on the curves cuts them fewer times
            def cuts(low: float, curves: list[list[float]] = curves, period: float = period) -> int:
                return sum(len(_pieces(xs, _wrapped(ys, low, period), (math.inf, period / 2)))
                           for xs, ys in zip(shown_d, curves))

            centred = _window([v for ys in curves for v in ys] or marks, period)
            low = centred if cuts(centred) < cuts(-period / 2) else -period / 2
            curves = [_wrapped(ys, low, period) for ys in curves]
            marks = _wrapped(marks, low, period)
        for k, (circ, xs, ys) in enumerate(zip(c.circuits, shown_d, curves)):
            colour = colours[k % len(colours)]
            for i, (px, py) in enumerate(_pieces(xs, ys, (d_period / 2, period / 2))):
                ax.plot(px, py, color=colour, lw=1.4, label=f"circuit {k + 1}" if i == 0 else None)
            for v in circ.limits:
                x = _driver_shown(m, v)
                ax.axvline(_wrapped([x], d_low, d_period)[0] if angle_driver else x, color=colour, ls="--",
                           lw=0.7)
        for i, y in enumerate(marks):
            ax.plot([d0], [y], "ko", ms=4)
            ax.annotate(str(i + 1), (d0, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
        unit = u.unit if u.kind == "angle" else m.length_unit
        ax.set_ylabel(f"{u.name} ({unit})")
        ax.grid(True, alpha=0.3)
    if axes[0][0].get_legend_handles_labels()[0]:
        axes[0][0].legend(loc="best", fontsize=8)
    else:  # no circuit (no real assembly): the empty axes say why, not nothing
        why = (f"no real assembly at {m.driver.name} = {_driver_shown(m, c.assemblies.driver):g} "
               f"{_driver_unit(m)}: no circuit to draw")
        for row in axes:
            row[0].text(0.5, 0.5, why, transform=row[0].transAxes, ha="center", va="center", color="0.4")
    axes[-1][0].set_xlabel(f"{m.driver.name} ({_driver_unit(m)}); dashed: limit positions")
    axes[0][0].set_title(f"{m.name}: circuits (dots: the assemblies at {m.driver.name} = "
                         f"{_driver_shown(m, c.assemblies.driver):g})")
    save_figure(fig, path)
