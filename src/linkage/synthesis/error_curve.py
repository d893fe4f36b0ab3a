"""The structural error of a synthesised linkage: its output followed by the four-bar
equation's solver from the first precision point, against the function asked for; its
extrema located on a dense grid by the branch's closed form and refined (docs/synthesis.md)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

from ..records import frozen
from .request import GRID, SOLVER_TOL, PrecisionPoint, Request, value_of
from .solve import Linkage, assembly_gap, linkage_of, transmission_deg, transmission_deg_np


@frozen
class CurvePoint:
    x: float
    y: float
    alpha_deg: float
    phi_desired_deg: float
    phi_generated_deg: float | None
    error_deg: float | None
    error_y: float | None
    transmission_deg: float | None
    status: str



@frozen
class Design:
    """One synthesised linkage with what its error needs: the real R, the branch sign at
    the first precision point, and the shifts between the equation's angles and its own."""

    req: Request
    R: tuple[float, float, float]
    linkage: Linkage
    real_R: tuple[float, float, float]
    sign: float

    def real_alpha(self, x: float) -> float:
        return self.req.alpha(x) + self.linkage.alpha_shift()

    def closed_error(self, x: float, y: float) -> float:
        """phi generated - phi desired (deg) by the branch's closed form; NaN where the
        linkage cannot be assembled."""
        from ..problems.freudenstein import branch_root

        phi = branch_root(self.real_alpha(x), *self.real_R, self.sign) - self.linkage.phi_shift()
        return math.remainder(phi - self.req.phi(y), 360.0)


def design_of(
    req: Request, r: tuple[float, float, float], first: PrecisionPoint
) -> tuple[Design | None, str | None]:
    from ..problems.freudenstein import branch_sign

    k, why = linkage_of(r, req.ground)
    if k is None:
        return None, why
    real_r = k.coefficients
    sign = branch_sign(first.alpha_deg + k.alpha_shift(), first.phi_deg + k.phi_shift(), *real_r)
    return Design(req, r, k, real_r, sign), None


def golden_max(g: Callable[[float], float], lo: float, hi: float, iters: int = 80) -> tuple[float, float]:
    """The x in [lo, hi] where g is largest (g unimodal there) and g there: the golden-section
    loop (methods.golden) on -g, then the best of the last bracket and its ends."""
    from ..methods.golden import golden_min

    a, c, fc, d, fd, b = golden_min(lambda x: -g(x), lo, hi, iters,
                                    lambda k: k[5] - k[0] <= 1e-15 * max(1.0, abs(k[0]), abs(k[5])))
    ends = ((a, g(a)), (c, -fc), (d, -fd), (b, g(b)))
    return max(ends, key=lambda t: t[1] if math.isfinite(t[1]) else -1.0)


def extrema(
    design: Design, grid: int = GRID, reached: bool = False
) -> tuple[list[tuple[float, float]], list[float], list[float]]:
    """The structural error's local extrema (x, error_deg), refined by golden section from
    a dense grid (ends included), and the grid's x and errors (NaN: no assembly). Where
    the linkage cannot be assembled there are none, unless ``reached``: then the assembled
    runs' extrema, an end at a limit position being the last x that assembles (the error
    is steepest there)."""
    req = design.req
    lo, hi = req.x_range
    xs = [lo + (hi - lo) * i / (grid - 1) for i in range(grid)]
    errs = [design.closed_error(x, value_of(req.f, x)) for x in xs]
    out: list[tuple[float, float]] = []
    if not reached and any(not math.isfinite(e) for e in errs):
        return out, xs, errs
    mag = [abs(e) if math.isfinite(e) else -1.0 for e in errs]
    for i in range(grid):
        if mag[i] < 0.0:
            continue
        left = mag[i - 1] if i > 0 else -1.0
        right = mag[i + 1] if i < grid - 1 else -1.0
        if (mag[i] >= left and mag[i] > right) or (mag[i] > left and mag[i] >= right):
            if (left < 0.0 < i) or (right < 0.0 and i < grid - 1):
                x = _last_assembled(design, xs[i], xs[i - 1] if left < 0.0 else xs[i + 1])
            elif 0 < i < grid - 1:
                x, _ = golden_max(
                    lambda t: abs(design.closed_error(t, value_of(req.f, t))), xs[i - 1], xs[i + 1]
                )
            else:
                x = xs[i]
            out.append((x, design.closed_error(x, value_of(req.f, x))))
    # neighbours of one sign with a zero between them belong to different lobes; keep the
    # largest of each run of one sign (plateaus of rounding give several)
    lobes: list[tuple[float, float]] = []
    for x, e in out:
        if lobes and (lobes[-1][1] > 0.0) == (e > 0.0) and not _zero_between(errs, xs, lobes[-1][0], x):
            if abs(e) > abs(lobes[-1][1]):
                lobes[-1] = (x, e)
            continue
        lobes.append((x, e))
    return lobes, xs, errs


def _last_assembled(design: Design, inside: float, outside: float) -> float:
    """The x between an assembled ``inside`` and an unassembled ``outside`` nearest the
    limit position that still assembles (bisection)."""
    f = design.req.f
    for _ in range(60):
        mid = 0.5 * (inside + outside)
        if mid in (inside, outside):
            break
        if math.isfinite(design.closed_error(mid, value_of(f, mid))):
            inside = mid
        else:
            outside = mid
    return inside


def _zero_between(errs: Sequence[float], xs: Sequence[float], x0: float, x1: float) -> bool:
    inside = [e for x, e in zip(xs, errs) if x0 < x < x1]
    return any((e > 0.0) != (inside[0] > 0.0) for e in inside) if inside else False


def follow(design: Design, xs: Sequence[float], first: PrecisionPoint) -> list[float | None]:
    """The generated phi (deg, the equation's convention) at each x, by the four-bar equation's solver
    (Newton with continuation, kinematics.equation_sweep) from the first precision point,
    both ways; None from the first position it cannot reach on that branch onwards (a
    limit position in between, even one narrower than the steps). Near a limit the two
    roots are close and a continuation step can land on the other one: a root nearer the
    other branch's closed form (freudenstein.branch_root with -sign) than the followed
    one's is such a jump, and the walk restarts there from the followed branch's root."""
    from ..kinematics.equation_sweep import equation_sweep
    from ..problems.freudenstein import branch_root

    k, real_r, sign = design.linkage, design.real_R, design.sign
    seed = (first.alpha_deg + k.alpha_shift(), first.phi_deg + k.phi_shift())
    order = sorted(range(len(xs)), key=lambda i: xs[i])
    ahead = [i for i in order if xs[i] >= first.x]
    behind = [i for i in reversed(order) if xs[i] < first.x]
    out: list[float | None] = [None] * len(xs)
    for part in (ahead, behind):
        start, last, j, restarted = seed, seed[0], 0, -1
        while j < len(part):
            alphas = [design.real_alpha(xs[i]) for i in part[j:]]
            rows = equation_sweep(alphas, real_r, "newton", SOLVER_TOL, seed=start)
            jump = None
            for m, (i, row, al) in enumerate(zip(part[j:], rows, alphas)):
                if row.phi is None or assembly_gap(real_r, last, al):
                    break  # beyond a limit: the rest of this side is not on the followed branch
                on, other = branch_root(al, *real_r, sign), branch_root(al, *real_r, -sign)
                if abs(math.remainder(row.phi - on, 360.0)) > abs(math.remainder(row.phi - other, 360.0)):
                    jump = (j + m, (al, on))
                    break
                out[i], last = row.phi - k.phi_shift(), al
            if jump is None or jump[0] == restarted:
                break
            (j, start), restarted = jump, jump[0]
    return out


def structural_error(design: Design, xs: Sequence[float], first: PrecisionPoint) -> list[CurvePoint]:
    req, k = design.req, design.linkage
    phis = follow(design, xs, first)
    out = []
    for x, phi in zip(xs, phis):
        y = value_of(req.f, x)
        want = req.phi(y)
        al = req.alpha(x)
        if phi is None:
            out.append(CurvePoint(x, y, al, want, None, None, None, None, "not_reached"))
            continue
        err = math.remainder(phi - want, 360.0)
        mu = transmission_deg(k, al + k.alpha_shift(), phi + k.phi_shift())
        out.append(CurvePoint(x, y, al, want, phi, err, err * req.y_per_deg, mu, "converged"))
    return out


def dense_transmission(
    design: Design, xs: Sequence[float], errs: Sequence[float]
) -> list[tuple[float, float]] | None:
    import numpy as np

    from ..problems.freudenstein import branch_root_np

    k = design.linkage
    good = np.isfinite(np.asarray(errs))
    if not good.any():
        return None
    x = np.asarray(xs)[good]
    al = np.array([design.real_alpha(v) for v in x])
    ph = branch_root_np(al, *design.real_R, design.sign)
    fold = transmission_deg_np(k.a, k.c, k.d, al, ph)  # folded (closed_form.transmission)
    i, j = int(np.nanargmin(fold)), int(np.nanargmax(fold))
    return [(float(fold[i]), float(x[i])), (float(fold[j]), float(x[j]))]
