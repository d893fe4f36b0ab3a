"""The matrix method (:func:`solve_loads`): every position's equilibrium equations of
every moving link, assembled and solved at once, over arrays of positions; and the motion
of each body and centre of mass that the inertia loads need (:func:`body_motion`,
:func:`cg_motion`). The method and its check by virtual power are described in
:mod:`.forces`, which judges the answers.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from ..errors import InputError
from ..linalg import back_substitute_np, lu_np
from ..problems.loads import Loads, load_link
from ..records import NamedTuple, frozen
from ..units import radians
from .bodies import Frame, metre

EPS = sys.float_info.epsilon


def body_motion(frame: Frame, pos: Mapping[str, Any], vel: Mapping[str, Any], acc: Mapping[str, Any],
                turned: Mapping[str, tuple[Any, Any, Any]] | None = None) -> dict[str, tuple[Any, Any, Any]]:
    """Each body's (rotation since the drawing, omega, alpha), arrays over the positions:
    from two of its joints, a one-joint block from the body its line is on; the ground's
    all zero. ``turned``: this function's answer at the same ``pos`` (other rates), whose
    rotations are taken as they are rather than found again (the same numbers)."""
    import numpy as np

    d = frame.drawing
    zero = np.zeros_like(next(iter(pos.values()))[0])
    out: dict[str, tuple[Any, Any, Any]] = {"ground": (zero, zero, zero)}
    pending = []
    for body, joints in d.bodies.items():
        if body == "ground":
            continue
        pair = two_apart(d, joints)
        if pair is None:
            pending.append(body)
            continue
        j0, j1 = pair
        rx, ry = pos[j1][0] - pos[j0][0], pos[j1][1] - pos[j0][1]
        r2 = rx * rx + ry * ry
        dvx, dvy = vel[j1][0] - vel[j0][0], vel[j1][1] - vel[j0][1]
        dax, day = acc[j1][0] - acc[j0][0], acc[j1][1] - acc[j0][1]
        if turned is None:
            drawn = math.atan2(d.xy[j1][1] - d.xy[j0][1], d.xy[j1][0] - d.xy[j0][0])
            rotation = np.arctan2(ry, rx) - drawn
        else:
            rotation = turned[body][0]
        out[body] = (rotation, (rx * dvy - ry * dvx) / r2, (rx * day - ry * dax) / r2)
    for body in pending:
        slide = d.sliders.get(body)
        out[body] = out.get(slide.on, out["ground"]) if slide is not None else out["ground"]
    return out


def cg_motion(d: Any, body: str, mass: Any, k: float, pos: Mapping[str, Any], vel: Mapping[str, Any],
              acc: Mapping[str, Any], motion: tuple[Any, Any, Any]) -> tuple[Any, Any, Any]:
    """The one rule for a link's centre of mass (``mass.cg``, drawn in the file's unit, ``k``
    m per unit): its position, velocity and acceleration, each (x, y) in SI, from the
    link's centre joint's (``pos``, ``vel``, ``acc``, m, m/s, m/s^2) and the link's
    (rotation since the drawing, omega, alpha) (:func:`body_motion`): r_G = r_0 + R rel,
    v_G = v_0 + omega x rel, a_G = a_0 + alpha x rel - omega^2 rel. Floats or arrays."""
    import numpy as np

    j0 = d.center(body)
    rot, w, al = motion
    dx, dy = (mass.cg[0] - d.xy[j0][0]) * k, (mass.cg[1] - d.xy[j0][1]) * k
    c, s = np.cos(rot), np.sin(rot)
    rel = (c * dx - s * dy, s * dx + c * dy)
    cg = (pos[j0][0] + rel[0], pos[j0][1] + rel[1])
    vg = (vel[j0][0] - w * rel[1], vel[j0][1] + w * rel[0])
    ag = (acc[j0][0] - al * rel[1] - w * w * rel[0], acc[j0][1] + al * rel[0] - w * w * rel[1])
    return cg, vg, ag


def two_apart(d: Any, joints: Sequence[str]) -> tuple[str, str] | None:
    for i, a in enumerate(joints):
        for b in joints[i + 1:]:
            if d.xy[a] != d.xy[b]:
                return a, b
    return None


def cross(r: tuple[Any, Any], f: tuple[Any, Any]) -> Any:
    return r[0] * f[1] - r[1] * f[0]


@frozen
class ForceArrays:
    """The matrix method over N positions at once (arrays of shape (N,), NaN where the
    force matrix is singular)."""

    input: Any
    input_unit: str
    pins: tuple[tuple[str, str, str, Any, Any], ...]
    """(joint, on, by, fx, fy) per pin force."""
    sliders: tuple[tuple[str, str, Any, Any], ...]
    ground: tuple[Any, Any, Any]
    virtual_power_input: Any
    condition: Any
    """The force matrix's 1-norm condition number (inf where singular); where the solve
    was screened (:func:`solve_scaled`'s ``screen_below``) and passed, a certified upper
    bound of it below the screen's limit."""
    applied: tuple[Any, Any, Any]


def pin_pairs(d: Any) -> list[tuple[str, str, str]]:
    """The one rule for what a pin joins: (joint, owner, link) for each link on a joint that
    two or more bodies share, other than its owner (the ground where the pin is fixed,
    else the first body listing it); a pin shared by k bodies is k - 1 pairs."""
    out = []
    for j in d.xy:
        on = [b for b, js in d.bodies.items() if j in js]
        if len(on) < 2:
            continue
        first = "ground" if "ground" in on else on[0]
        out += [(j, first, b) for b in on if b != first]
    return out


class Unknowns(NamedTuple):
    """The matrix method's unknowns and its equilibrium matrix's entries (:func:`assemble`)."""

    cols: list[tuple[str, Any]]
    """What each unknown is: ("pin", (joint, on, by)), "pin_y", ("slider", (slider, on)),
    "slider_m", "input"."""
    entries: list[tuple[int, int, Any]]
    """(row, column, value) of each entry, summed (values: numbers or arrays)."""
    line_dirs: dict[str, tuple[Any, Any]]
    """Each slider's line direction (cos, sin) at every position."""
    input_col: int
    input_unit: str


def assemble(frame: Frame, pos: Mapping[str, tuple[Any, Any]], motion: Mapping[str, Any],
             row: Mapping[str, int]) -> Unknowns:
    """The equilibrium equations' left-hand side: each pin's reaction (x, y), each slider's
    normal force and couple, and the driver's torque or force, on each moving body's three
    rows (``row``: its first)."""
    import numpy as np

    d = frame.drawing
    cols: list[tuple[str, Any]] = []
    entries: list[tuple[int, int, Any]] = []

    def add_force(body: str, at: tuple[Any, Any], cx: int, cy: int, sign: float = 1.0) -> None:
        if body == "ground":
            return
        r = row[body]
        entries.extend([(r, cx, sign), (r + 2, cx, -sign * at[1]),
                        (r + 1, cy, sign), (r + 2, cy, sign * at[0])])

    for j, first, b in pin_pairs(d):
        cx, cy = len(cols), len(cols) + 1
        cols += [("pin", (j, b, first)), ("pin_y", None)]
        add_force(b, pos[j], cx, cy)
        add_force(first, pos[j], cx, cy, sign=-1.0)
    line_dirs: dict[str, tuple[Any, Any]] = {}
    for s, slide in d.sliders.items():
        at = pos[d.bodies[s][0]]
        t = radians(slide.angle_deg) + motion[slide.on][0]
        u = (np.cos(t), np.sin(t))
        n = (-u[1], u[0])
        line_dirs[s] = u
        cn, cm = len(cols), len(cols) + 1
        cols += [("slider", (s, slide.on)), ("slider_m", None)]
        for body, sign in ((s, 1.0), (slide.on, -1.0)):
            if body != "ground":
                r = row[body]
                entries.extend([(r, cn, sign * n[0]), (r + 1, cn, sign * n[1]),
                                (r + 2, cn, sign * cross(at, n)), (r + 2, cm, sign)])
    ci = len(cols)
    cols.append(("input", None))
    if frame.driver_slider is not None:
        s = frame.driver_slider
        at, u = pos[d.bodies[s][0]], line_dirs[s]
        for body, sign in ((s, 1.0), (d.sliders[s].on, -1.0)):
            if body != "ground":
                r = row[body]
                entries.extend([(r, ci, sign * u[0]), (r + 1, ci, sign * u[1]),
                                (r + 2, ci, sign * cross(at, u))])
        return Unknowns(cols, entries, line_dirs, ci, "N")
    entries.append((row[frame.driver_link] + 2, ci, 1.0))
    return Unknowns(cols, entries, line_dirs, ci, "N m")


class KnownLoads(NamedTuple):
    """The equations' right-hand side: minus the known loads (external, gravity, inertia)
    on each body; their virtual power at a unit driver speed (the independent answer's
    numerator); their total force x, y and moment."""

    rhs: Any
    power: Any
    applied: tuple[Any, Any, Any]


def known_loads(frame: Frame, pos: Mapping[str, tuple[Any, Any]], acc: Mapping[str, tuple[Any, Any]],
                vstar: Mapping[str, tuple[Any, Any]], motion: Mapping[str, Any], star: Mapping[str, Any],
                loads: Loads, row: Mapping[str, int], n_eq: int) -> KnownLoads:
    """Every known load at every position (d'Alembert's inertia loads at each centre of
    mass by :func:`cg_motion`), with its virtual power at the unit-speed velocities
    ``vstar`` (``star``: the bodies' motion at them)."""
    import numpy as np

    d = frame.drawing
    k = metre(frame.length_unit)
    n_pos = len(next(iter(pos.values()))[0])
    rhs = np.zeros((n_eq, n_pos))  # one row per equation: each position's values contiguous
    power = np.zeros(n_pos)
    applied = [np.zeros(n_pos), np.zeros(n_pos), np.zeros(n_pos)]

    def known(body: str, at: tuple[Any, Any], f: tuple[Any, Any], moment: Any, v_at: tuple[Any, Any]) -> None:
        nonlocal power
        power = power + f[0] * v_at[0] + f[1] * v_at[1] + moment * star[body][1]
        m_at = cross(at, f) + moment
        applied[0] += f[0]
        applied[1] += f[1]
        applied[2] += m_at
        if body != "ground":
            r = row[body]
            rhs[r] -= f[0]
            rhs[r + 1] -= f[1]
            rhs[r + 2] -= m_at

    origin = (np.zeros(n_pos), np.zeros(n_pos))
    for j, f in loads.forces.items():
        known(load_link(d, j, loads.on.get(j)), pos[j], f, 0.0, vstar[j])
    for b, t in loads.torques.items():
        known(b, origin, (0.0, 0.0), t, origin)
    g = loads.gravity
    for b, mass in loads.masses.items():
        cg, _, ag = cg_motion(d, b, mass, k, pos, acc, acc, motion[b])
        _, vg, _ = cg_motion(d, b, mass, k, pos, vstar, vstar, star[b])
        al = motion[b][2]
        known(b, cg, (-mass.mass * ag[0], -mass.mass * ag[1]), -mass.inertia * al, vg)
        if g is not None:
            known(b, cg, (mass.mass * g[0], mass.mass * g[1]), 0.0, vg)
    return KnownLoads(rhs, power, (applied[0], applied[1], applied[2]))


def solve_scaled(frame: Frame, a: Any, rhs: Any, cols: Sequence[tuple[str, Any]],
                 screen_below: float | None = None, again: Callable[[Any], Any] | None = None
                 ) -> tuple[Any, Any]:
    """(the unknowns (N, n), the condition number (N,)) of each position's system, ``a``
    (n, n, N) and ``rhs`` (n, N) with the positions last, solved in the mechanism's own
    size: moments per metre of it, torques as forces at that arm, so the condition number
    (the near-toggle test) is the same in mm, in m or in miles. NaN where the matrix is
    singular to working precision.

    With ``screen_below``: where :func:`solve_bounded_np`'s certified upper bound of the
    condition number is below it, that bound stands for the condition number and its LU
    solution for the unknowns (what a verdict needs: the bound is at least the exact
    number, so a verdict the bound passes the exact number passes too); elsewhere, and
    always without it, the exact number and solution by :func:`condition_np` (one inverse
    per matrix, two and a half times the work of the LU). ``again(which)``, where given,
    builds ``a`` (unscaled) anew for the positions ``which``: the screen then eliminates
    in ``a`` itself, and the positions it does not pass get their matrices from it."""
    import numpy as np

    n_pos = a.shape[-1]
    size = np.broadcast_to(np.asarray(frame.size, dtype=float), (n_pos,))
    couples = [i for i, (kind, _) in enumerate(cols)
               if kind == "slider_m" or (kind == "input" and frame.driver_slider is None)]
    scale_moments(a, size, couples)
    rhs[2::3] /= size
    if screen_below is None:
        cond, x = condition_np(a.transpose(2, 0, 1), rhs.T)
    else:
        x, cond = solve_bounded_np(a, rhs, overwrite_a=again is not None)
        exact = np.flatnonzero(~(cond < screen_below))
        if exact.size:
            m = a[:, :, exact] if again is None else scale_moments(again(exact), size[exact], couples)
            # each matrix contiguous, as a[:, :, exact] lays it out: the norms' sums in one order
            cond[exact], x[exact] = condition_np(np.ascontiguousarray(m.transpose(2, 0, 1)), rhs[:, exact].T)
    good = np.isfinite(cond) & (cond * EPS < 0.5)
    x = np.where(good[:, None], x, np.nan)
    x[:, couples] *= size[:, None]
    return x, cond


def scale_moments(a: Any, size: Any, couples: Sequence[int]) -> Any:
    """``a`` (n, n, N) in place, and returned, in the mechanism's ``size`` (N,): each
    moment row per unit of it, each couple's column at that arm (:func:`solve_scaled`)."""
    a[2::3] /= size
    a[:, couples] *= size
    return a


def force_matrix(entries: Sequence[tuple[int, int, Any]], n: int, n_pos: int, which: Any = None) -> Any:
    """The equilibrium matrices (n, n, positions) of :func:`assemble`'s entries, summed in
    their order; of the positions ``which`` only, where given (the same numbers)."""
    import numpy as np

    if which is None:
        a = np.zeros((n, n, n_pos))  # the positions last: each entry's values contiguous
        for r, c, v in entries:
            a[r, c] += v
        return a
    a = np.zeros((n, n, len(which)))
    for r, c, v in entries:
        a[r, c] += np.broadcast_to(v, (n_pos,))[which]
    return a


def solve_loads(frame: Frame, pos: Mapping[str, tuple[Any, Any]], vel: Mapping[str, tuple[Any, Any]],
                acc: Mapping[str, tuple[Any, Any]], vstar: Mapping[str, tuple[Any, Any]], loads: Loads,
                source: str = "<mechanism>", screen_below: float | None = None) -> ForceArrays:
    """The one definition of the matrix method: every position's system assembled
    (:func:`assemble`, :func:`known_loads`) and solved (:func:`solve_scaled`, its
    ``screen_below`` for a caller that needs only verdicts) at once.
    ``pos``, ``vel``, ``acc``: each joint's (x, y) arrays in m, m/s, m/s^2; ``vstar`` its
    velocity at a unit driver speed (m/s per rad/s, or per unit/s), for the virtual-power
    answer."""
    import numpy as np

    d = frame.drawing
    n_pos = len(next(iter(pos.values()))[0])
    motion = body_motion(frame, pos, vel, acc)
    zero = np.zeros(n_pos)  # read only: the still accelerations of the unit-speed motion
    zeros = {j: (zero, zero) for j in pos}
    star = body_motion(frame, pos, vstar, zeros, turned=motion)
    moving = [b for b in d.bodies if b != "ground"]
    row = {b: 3 * i for i, b in enumerate(moving)}
    unknowns = assemble(frame, pos, motion, row)
    n_eq, n_un = 3 * len(moving), len(unknowns.cols)
    if n_eq != n_un:
        raise InputError(f"{source}: {n_eq} equilibrium equations but {n_un} unknown forces: the matrix "
                         "method needs a mobility-1 mechanism of pins and sliders")
    a = force_matrix(unknowns.entries, n_eq, n_pos)
    known = known_loads(frame, pos, acc, vstar, motion, star, loads, row, n_eq)
    x, cond = solve_scaled(frame, a, known.rhs, unknowns.cols, screen_below,
                           again=lambda which: force_matrix(unknowns.entries, n_eq, n_pos, which))
    # the unit driver speed's own size: rad/s, or the length unit per second in m/s
    vp = -known.power / (1.0 if frame.driver_slider is None else metre(frame.length_unit))
    pins, sliders, ground = reactions(frame, pos, unknowns, x)
    return ForceArrays(x[:, unknowns.input_col], unknowns.input_unit, pins, sliders, ground, vp, cond,
                       known.applied)


def reactions(frame: Frame, pos: Mapping[str, tuple[Any, Any]], unknowns: Unknowns, x: Any
              ) -> tuple[tuple[Any, ...], tuple[Any, ...], tuple[Any, Any, Any]]:
    """The solved unknowns read out: each pin's force (joint, on, by, fx, fy), each slider's
    (slider, on, normal, couple), and the force and moment on the ground (the reactions of
    its pins, its sliders' lines and the driver's, reversed)."""
    import numpy as np

    d = frame.drawing
    n_pos = x.shape[0]
    pins, sliders = [], []
    gx, gy, gm = np.zeros(n_pos), np.zeros(n_pos), np.zeros(n_pos)
    for i, (kind, what) in enumerate(unknowns.cols):
        if kind == "pin":
            j, on, by = what
            fx, fy = x[:, i], x[:, i + 1]
            pins.append((j, on, by, fx, fy))
            if by == "ground":
                gx, gy, gm = gx - fx, gy - fy, gm - cross(pos[j], (fx, fy))
        elif kind == "slider":
            s, on = what
            nn, mm = x[:, i], x[:, i + 1]
            sliders.append((s, on, nn, mm))
            if on == "ground":
                u = unknowns.line_dirs[s]
                f = (-u[1] * nn, u[0] * nn)
                gx, gy, gm = gx - f[0], gy - f[1], gm - cross(pos[d.bodies[s][0]], f) - mm
    inp = x[:, unknowns.input_col]
    if frame.driver_slider is None:
        gm = gm - inp
    elif d.sliders[frame.driver_slider].on == "ground":
        s = frame.driver_slider
        u = unknowns.line_dirs[s]
        f = (u[0] * inp, u[1] * inp)
        gx, gy, gm = gx - f[0], gy - f[1], gm - cross(pos[d.bodies[s][0]], f)
    return tuple(pins), tuple(sliders), (gx, gy, gm)


def condition_np(a: Any, rhs: Any) -> tuple[Any, Any]:
    """Each matrix's condition number in the 1-norm, ||A|| ||A^-1|| (inf where A is
    singular), and its solution for ``rhs`` (..., n) (NaN there): the inverse and the
    solution from one batched LU (:func:`~.rate_bounds.solve_np`), as an LU inverse costs
    a fraction of the SVD that the 2-norm's needs, and bounds the same error (within a
    factor of the matrix's size)."""
    import numpy as np

    from ..linalg import norm1_np
    from .rate_bounds import solve_np

    inv, x, usable = solve_np(a, rhs[..., None])
    with np.errstate(over="ignore", invalid="ignore"):
        cond = norm1_np(a) * norm1_np(inv)
    cond = np.where(usable & np.isfinite(cond), cond, np.inf)
    return cond, x[..., 0]


def solve_bounded_np(a: Any, rhs: Any, overwrite_a: bool = False) -> tuple[Any, Any]:
    """Each system of a stack, ``a`` (n, n, N) and ``rhs`` (n, N) with the N systems last:
    its solution (N, n) by LU with partial pivoting (linalg's :func:`~linkage.linalg.lu_np`,
    ``lu``'s twin, and its ``lu_solve``'s back substitution), and a certified upper bound (N,) of
    its 1-norm condition number ||A||_1 ||A^-1||_1 (NaN or inf where none is found: a
    zero pivot, a non-finite entry). ``rhs`` is left as it is, and ``a`` unless
    ``overwrite_a`` (then its elimination is done in ``a``, which is spent: a copy of a
    large stack costs a tenth of a loaded scan's time on two threads).

    The bound (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed.): the
    computed factors satisfy L U = P A + E with |E| <= gamma_n |L| |U| (theorem 9.3), and
    |T^-1| <= M(T)^-1 for a triangular T and its comparison matrix M(T) (theorem 8.12),
    so ||(L U)^-1||_1 <= g, the largest column sum of the non-negative M(U)^-1 M(L)^-1
    (two triangular solves), and ||A^-1||_1 <= g / (1 - g ||E||_1) where g ||E||_1 < 1.
    (An estimate such as Hager's is a lower bound, not this.) Its own evaluation adds,
    multiplies and divides non-negative numbers only, each triangular solve's relative
    error growing by at most (j + 2) eps at its j-th unknown: n (n + 3) eps for both, n eps
    for ||A||_1 and a few more, covered by the factor 1 + 2 (n + 2)^2 eps (barring
    underflow: the force matrices come scaled to the mechanism's size, entries near 1)."""
    import numpy as np

    n = a.shape[0]
    with np.errstate(all="ignore"):
        # ||A||_1, the largest column sum, a row at a time, before the elimination may spend A
        sums, row = np.abs(a[0]), np.empty(a.shape[1:])
        for i in range(1, n):
            sums += np.abs(a[i], out=row)
        norm = sums.max(axis=0)
        t, y = (a if overwrite_a else a.copy()), rhs.copy()
        lu_np(t, y)
        x = back_substitute_np(t, y)
        g, lu_norm = inverse_bound_np(np.abs(t, out=t))
        safety = 1.0 + 2.0 * (n + 2) ** 2 * EPS
        gamma = n * EPS / (1.0 - n * EPS)
        ge = g * gamma * lu_norm * safety
        bound = np.where(ge < 1.0, g / (1.0 - ge), np.inf)
        upper = norm * bound * safety
    return x.T, upper


def inverse_bound_np(lu_abs: Any) -> tuple[Any, Any]:
    """From |L| and |U| packed as :func:`~linkage.linalg.lu_np` leaves them (n, n, N): the largest
    column sum of M(U)^-1 M(L)^-1, by e^T M(U)^-1 (M(U)^T v = e, forward) then
    v^T M(L)^-1 (M(L)^T w = v, backward); and the largest column sum of |L| |U|, by
    (e^T |L|) |U|. Both (N,)."""
    import numpy as np

    n, _, count = lu_abs.shape
    v = np.empty((n, count))
    for j in range(n):
        v[j] = (1.0 + np.einsum("iN,iN->N", lu_abs[:j, j], v[:j])) / lu_abs[j, j]
    w = np.empty((n, count))
    for j in range(n - 1, -1, -1):
        w[j] = v[j] + np.einsum("iN,iN->N", lu_abs[j + 1:, j], w[j + 1:])
    l_sums = np.ones((n, count))  # e^T |L|: L's unit diagonal and its multipliers
    for i in range(n - 1):
        l_sums[i] += lu_abs[i + 1:, i].sum(axis=0)
    lu_sums = np.empty((n, count))
    for j in range(n):
        lu_sums[j] = np.einsum("iN,iN->N", l_sums[:j + 1], lu_abs[:j + 1, j])
    return w.max(axis=0), lu_sums.max(axis=0)
