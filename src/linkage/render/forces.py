"""The loads answer of one position: input, pin and slider forces, the ground's force."""

from __future__ import annotations

import math
from typing import Any

from .data import from_rows
from .report import Block, Text, fmt, table


def _shown(v: float | None, f: Any, digits: int) -> Any:
    """A force as the table shows it: undefined is no number; an ill-conditioned one is
    given to the digits its bound leaves."""
    if v is None or f.status == "undefined":
        return None
    if f.status == "ill_conditioned" and f.bound is not None and f.bound > 0:
        keep = max(1, min(digits, int(-math.log10(f.bound))))
        return float(f"{v:.{keep}g}")
    return v


def force_tables(f: Any) -> list[Any]:
    rows = [(p.joint, p.on, p.by, p.fx, p.fy, p.magnitude) for p in f.pins] if f.status != "undefined" else []
    out = [
        from_rows(
            "pin_forces",
            [
                ("joint", "", "text"),
                ("on", "", "text"),
                ("by", "", "text"),
                ("fx", "N", "number"),
                ("fy", "N", "number"),
                ("magnitude", "N", "number"),
            ],
            rows,
        )
    ]
    if f.sliders:
        srows = [(s.slider, s.on, s.normal, s.couple) for s in f.sliders] if f.status != "undefined" else []
        out.append(
            from_rows(
                "slider_forces",
                [
                    ("slider", "", "text"),
                    ("on", "", "text"),
                    ("normal", "N", "number"),
                    ("couple", "N m", "number"),
                ],
                srows,
            )
        )
    gf = f.ground_force or (None, None)
    out.append(
        from_rows(
            "loads_summary",
            [
                ("input", f.input_unit, "number"),
                ("virtual_power_input", f.input_unit, "number"),
                ("ground_fx", "N", "number"),
                ("ground_fy", "N", "number"),
                ("ground_moment", "N m", "number"),
                ("mechanical_advantage", "", "number"),
                ("condition", "", "number"),
                ("status", "", "text"),
            ],
            [
                (
                    f.input,
                    f.virtual_power_input,
                    gf[0],
                    gf[1],
                    f.ground_moment,
                    f.mechanical_advantage,
                    f.condition,
                    f.status,
                )
            ],
        )
    )
    return out


def applied_block(applied: Any, digits: int) -> Block:
    """The loads given, each with the link it acts on (problems.loads.applied_rows): a force
    at a joint two links share acts on the link its ``on`` names, else on the first listing it."""
    return table("loads applied (ground frame; a shared joint's force on the link named)",
                 ["load", "kind", "on", "fx (N)", "fy (N)", "torque (N m)"], list(applied), digits)


def applied_document(applied: Any) -> list[dict[str, Any]]:
    keys = ("load", "kind", "on", "fx", "fy", "torque")
    return [dict(zip(keys, row)) for row in applied]


def force_blocks(f: Any, digits: int, applied: Any = ()) -> list[Block]:
    out: list[Block] = [Text(""), Text("loads (matrix method; SI units)", "bold")]
    if applied:
        out.append(applied_block(applied, digits))
    if f.status == "undefined":
        out.append(
            Text(
                "forces: undefined here (a toggle or dead centre: the force matrix is singular; "
                "they grow without bound as it nears)",
                "red",
            )
        )
        return out
    what = "input torque" if f.input_unit == "N m" else "input force"
    out.append(
        Text(
            f"{what}: {fmt(_shown(f.input, f, digits), digits)} {f.input_unit} (virtual power: "
            f"{fmt(_shown(f.virtual_power_input, f, digits), digits)} {f.input_unit})"
        )
    )
    if f.status == "near_toggle":
        out.append(Text(f"near_toggle: condition number {f.condition:.3g}: the forces are amplified near a "
                        "toggle; a 0.1% change in the geometry can change them by "
                        f"{min(100.0, 0.1 * f.condition):.3g}%", "yellow"))
    if f.status == "ill_conditioned":
        out.append(
            Text(
                f"ill_conditioned: near a toggle (condition number {f.condition:.3g}); forces are "
                f"printed to the digits their bound ({f.bound:.1g} relative) leaves",
                "yellow",
            )
        )
    out.append(
        table(
            "pin forces (on the link, by the body named)",
            ["joint", "on", "by", "fx (N)", "fy (N)", "|F| (N)"],
            [
                (
                    p.joint,
                    p.on,
                    p.by,
                    _shown(p.fx, f, digits),
                    _shown(p.fy, f, digits),
                    _shown(p.magnitude, f, digits),
                )
                for p in f.pins
            ],
            digits,
        )
    )
    if f.sliders:
        out.append(
            table(
                "slider forces (normal to the line, on the slider)",
                ["slider", "on", "normal (N)", "couple (N m)"],
                [
                    (s.slider, s.on, _shown(s.normal, f, digits), _shown(s.couple, f, digits))
                    for s in f.sliders
                ],
                digits,
            )
        )
    gx, gy = f.ground_force
    out.append(
        Text(
            f"on the ground (shaking force): fx = {fmt(_shown(gx, f, digits), digits)} N, fy = "
            f"{fmt(_shown(gy, f, digits), digits)} N, moment about the origin "
            f"{fmt(_shown(f.ground_moment, f, digits), digits)} N m"
        )
    )
    if f.mechanical_advantage is not None:
        out.append(
            Text(
                "mechanical advantage "
                + ("|output torque / input torque|" if f.input_unit == "N m"
                   else "|output force| / |input force|")
                + f" = {fmt(_shown(f.mechanical_advantage, f, digits), digits)}"
            )
        )
    return out


def force_document(f: Any) -> dict[str, Any]:
    defined = f.status != "undefined"
    return {
        "status": f.status,
        "input": f.input,
        "input_unit": f.input_unit,
        "virtual_power_input": f.virtual_power_input,
        "condition": f.condition,
        "bound": f.bound,
        "pins": [
            {"joint": p.joint, "on": p.on, "by": p.by, "fx": p.fx, "fy": p.fy, "magnitude": p.magnitude}
            for p in f.pins
        ]
        if defined
        else [],
        "sliders": [
            {"slider": s.slider, "on": s.on, "normal": s.normal, "couple": s.couple} for s in f.sliders
        ]
        if defined
        else [],
        "ground_force": list(f.ground_force) if f.ground_force else None,
        "ground_moment": f.ground_moment,
        "mechanical_advantage": f.mechanical_advantage,
    }


def status_words(codes: Any) -> Any:
    """Each position's forces status as text from its FORCE_STATUSES code (-1: unsolved)."""
    import numpy as np

    from ..kinematics.forces import FORCE_STATUSES

    words = np.array([*FORCE_STATUSES, "unsolved"], dtype=object)
    return words[np.asarray(codes, dtype=np.intp)]  # -1 is the last: unsolved


def sweep_force_table(inputs: Any, status: Any, columns: Any, driver: str, driver_unit: str,
                      input_unit: str, pins: Any = ()) -> Any:
    """The sweep's ``loads`` table: per position the status, the input, the largest pin
    force, the ground's force and moment, the condition number, each pin force's x and y
    (``<joint>_on_<link>_fx``: on that link) and each slider's normal force and couple (SI).
    ``columns``: kinematics.force_sweeps.SweepLoads' (arrays, NaN where no number)."""
    from .data import DataTable, column

    out = [column(driver, driver_unit, inputs), column("forces_status", "", status, "text")]
    out += [column(k, u, columns[k]) for k, u in (("input", input_unit), ("max_pin_force", "N"),
                                                   ("ground_fx", "N"), ("ground_fy", "N"),
                                                   ("ground_moment", "N m"), ("condition", ""),
                                                   ("mechanical_advantage", ""))]
    out += [column(k, "N m" if k.endswith("_couple") else "N", columns[k]) for k in pins]
    return DataTable("loads", tuple(out))


def torque_plot(rows: list[tuple[Any, ...]], driver: str, driver_unit: str, input_unit: str, path: Any,
                title: str, peak: int) -> None:
    """The input torque (or force) over the sweep, the peak (row ``peak``, by the one peak
    rule; -1: none) marked; flagged positions drawn as hollow markers, undefined ones left
    out (the line breaks there)."""
    from .plots import pyplot, save_figure

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    xs = [r[0] for r in rows]
    ys = [r[2] if r[1] in ("ok", "near_toggle", "ill_conditioned") else math.nan for r in rows]
    ax.plot(xs, ys, "-", color="C0", lw=1.6, label=f"input ({input_unit})")
    flagged = [(x, y) for x, y, r in zip(xs, ys, rows) if r[1] in ("near_toggle", "ill_conditioned")]
    if flagged:
        ax.plot(*zip(*flagged), "o", mfc="none", color="C1", ms=5, label="near a toggle (flagged)")
    if peak >= 0:
        px, py = xs[peak], ys[peak]
        ax.plot([px], [py], "s", color="C3", label=f"peak {py:.4g} {input_unit} at {px:g} {driver_unit}")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel(f"{driver} ({driver_unit})")
    ax.set_ylabel(f"input {'torque' if input_unit == 'N m' else 'force'} ({input_unit})")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    save_figure(fig, path)
