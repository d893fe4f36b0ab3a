"""The defects of a synthesised linkage, each named with what shows it (docs/synthesis.md,
"Defects"): branch, grashof, order and transmission (no_linkage is the solve's)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..records import frozen
from .error_curve import CurvePoint, Design
from .request import GRID, PrecisionPoint, value_of
from .solve import assembly_gap, branch_label, grashof_of, off_branch

DEFECTS = ("no_linkage", "branch", "grashof", "order", "transmission")
"""Every defect's name, as JSON and exit 1 report them."""


@frozen
class Defect:
    name: str
    message: str



def judge(
    design: Design,
    pts: Sequence[PrecisionPoint],
    curve: Sequence[CurvePoint],
    grid_xs: Sequence[float],
    grid_errs: Sequence[float],
    mus: Sequence[tuple[float, float]],
) -> list[Defect]:
    """The defects of a synthesised linkage, each named with what shows it; ``mus`` its
    transmission angles (folded, deg) with their x."""
    found = (
        branch_defect(design, pts),
        grashof_defect(design, curve, grid_xs, grid_errs),
        order_defect(design, grid_xs, grid_errs),
        transmission_defect(design, mus),
    )
    return [d for d in found if d is not None]


def branch_defect(design: Design, pts: Sequence[PrecisionPoint]) -> Defect | None:
    """A precision point on the other assembly than the one followed from point 1, reached
    or beyond a limit (the points are then on no one circuit: grashof too)."""
    k = design.linkage

    def label(p: PrecisionPoint) -> str:
        return branch_label(k, p.alpha_deg + k.alpha_shift(), p.phi_deg + k.phi_shift())

    off = [
        (j, p)
        for j, p in enumerate(pts)
        if off_branch(p.alpha_deg + k.alpha_shift(), p.phi_deg + k.phi_shift(), design.real_R, design.sign)
    ]
    if not off:
        return None
    said = ", ".join(f"{j + 1} (x = {p.x:.6g}, {label(p)})" for j, p in off)
    return Defect(
        "branch",
        f"branch: precision point {said} is not on the {label(pts[0])} assembly "
        "through point 1: the linkage must be taken apart to reach every point",
    )


def grashof_defect(
    design: Design, curve: Sequence[CurvePoint], grid_xs: Sequence[float], grid_errs: Sequence[float]
) -> Defect | None:
    """The motion asked for against what this linkage's type allows: a gap on the grid, the
    followed branch ending at a limit, or a gap narrower than the grid's step."""
    req = design.req
    lead = f"grashof: this {grashof_of(design.linkage)} linkage cannot move its input through the range"
    gap = next((c for c in curve if c.phi_generated_deg is None), None)
    runs = _nan_runs(grid_xs, grid_errs)
    if runs:
        said = ", ".join(f"{a:.6g} to {b:.6g}" if a != b else f"{a:.6g}" for a, b in runs[:3])
        return Defect(
            "grashof",
            f"{lead}: it cannot be assembled for x from {said} (alpha "
            f"{req.alpha(runs[0][0]):.6g} to {req.alpha(runs[0][1]):.6g} deg)",
        )
    if gap is not None:
        return Defect(
            "grashof",
            f"{lead} on one branch: the branch through point 1 ends at a limit "
            f"position before x = {gap.x:.6g} (alpha = {req.alpha(gap.x):.6g} deg)",
        )
    if assembly_gap(design.real_R, design.real_alpha(req.x_range[0]), design.real_alpha(req.x_range[1])):
        return Defect(
            "grashof",
            f"{lead}: it cannot be assembled in a gap narrower than the {GRID}-point grid's step",
        )
    return None


def order_defect(design: Design, grid_xs: Sequence[float], grid_errs: Sequence[float]) -> Defect | None:
    """The output turns back where the function does not."""
    if not all(math.isfinite(e) for e in grid_errs):
        return None
    req = design.req
    want = [req.phi(value_of(req.f, x)) for x in grid_xs]
    gen = [w + e for w, e in zip(want, grid_errs)]
    turns_gen, turns_want = _turns(gen), _turns(want)
    if len(turns_gen) <= len(turns_want):
        return None
    extra = _turns_diff(turns_gen, turns_want) or sorted(turns_gen)
    return Defect(
        "order",
        f"order: the output turns back at x = {grid_xs[extra[0]]:.6g} where the "
        "function does not, so it passes the output positions out of order",
    )


def transmission_defect(design: Design, mus: Sequence[tuple[float, float]]) -> Defect | None:
    """The transmission angle below the request's least anywhere in the range."""
    if not mus:
        return None
    mu, x_mu = min(mus)
    if mu >= design.req.min_transmission:
        return None
    return Defect(
        "transmission",
        f"transmission: the transmission angle falls to {mu:.4g} deg (at x = {x_mu:.6g}), "
        f"below {design.req.min_transmission:g} deg",
    )


def _nan_runs(xs: Sequence[float], errs: Sequence[float]) -> list[tuple[float, float]]:
    """The runs of grid x where the linkage cannot be assembled (first and last x of each)."""
    runs: list[tuple[float, float]] = []
    start = None
    for i, e in enumerate(errs):
        if not math.isfinite(e):
            start = xs[i] if start is None else start
            last = xs[i]
        elif start is not None:
            runs.append((start, last))
            start = None
    if start is not None:
        runs.append((start, last))
    return runs


def _turns(values: Sequence[float]) -> set[int]:
    """Indices where a sampled curve changes direction (steps below rounding ignored)."""
    scale = max((abs(v) for v in values), default=1.0)
    floor = 1e-9 * max(scale, 1.0)
    out, last = set(), 0
    for i in range(1, len(values)):
        step = values[i] - values[i - 1]
        if abs(step) <= floor:
            continue
        s = 1 if step > 0 else -1
        if last and s != last:
            out.add(i - 1)
        last = s
    return out


def turns_np(values: Any) -> Any:
    """:func:`_turns` over the rows of an array: how many times each row changes direction."""
    import numpy as np

    scale = np.maximum(np.max(np.abs(values), axis=-1, keepdims=True), 1.0)
    step = np.diff(values, axis=-1)
    sign = np.where(np.abs(step) <= 1e-9 * scale, 0.0, np.sign(step))
    # carry the last non-zero direction over steps below rounding (as _turns skips them)
    idx = np.where(sign != 0.0, np.arange(sign.shape[-1]), 0)
    np.maximum.accumulate(idx, axis=-1, out=idx)
    carried = np.take_along_axis(sign, idx, axis=-1)
    moving = carried != 0.0
    changes = (carried[..., 1:] != carried[..., :-1]) & moving[..., 1:] & moving[..., :-1]
    return changes.sum(axis=-1)


def _turns_diff(gen: set[int], want: set[int], width: int = 3) -> list[int]:
    return sorted(i for i in gen if not any(abs(i - j) <= width for j in want))
