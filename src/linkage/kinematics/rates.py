"""Velocity and acceleration of every unknown, joint and named point, at one position.

Every vector of every loop is ``sign * r * e^(i theta)``. Differentiating the loops in
time (worked example P7, docs/worked_examples.md), with ' for d/dt:

    velocity:      sum sign (r' + i r theta') e^(i theta) = 0
                   -> J q' = -(dPhi/dv) v'
    acceleration:  sum sign (r'' + i r theta'' + 2 i r' theta' - r theta'^2) e^(i theta) = 0
                   -> J q'' = -(dPhi/dv) v'' - b,
                      b = sum sign (2 i r' theta' - r theta'^2) e^(i theta)

with J and dPhi/dv the compiled Jacobian and driver derivative of the position problem
(the same J: a velocity or acceleration is one more linear solve), ``- r theta'^2`` the
centripetal term of every moving vector and ``2 i r' theta'`` the Coriolis term of a
vector whose length and angle both move (a slider on a rotating link). Where J is
singular (a toggle or dead centre) the rates are undefined and the status says so.

The joints and points are placed by the one placing rule (:mod:`.placing`), each vector by
the one definition of its motion (:mod:`.vectors`), the bounds by :mod:`.rate_bounds`. A
block of positions (a sweep's chunk) runs the same definitions over numpy arrays
(:func:`polish_np`, :func:`rates_from_jacobian_np`, :mod:`.rate_blocks`).
"""

from __future__ import annotations

import math
from dataclasses import field
from typing import Any

from ..methods.newton_system import max_abs, newton_direction
from ..problems.loops import DRIVER, LoopModel
from ..records import frozen
from .block_linalg import direction_np
from .labels import rate_label
from .placing import place, place_bounded
from .rate_bounds import SAFETY, rate_bounds, solve_np, static_values
from .vectors import EPS, XY, bias, bias_np, value_of

RATE_RTOL = 1e-6
"""A rate whose error bound exceeds this, relative to the rate (or to the driver's own
speed or acceleration where the rate is smaller), is ``ill_conditioned``."""

POLISH_STEPS = 60
"""Most Newton steps taken to polish a position before its rates (each must shrink)."""


@frozen
class Rates:
    """One position's kinematics. ``velocities``/``accelerations``: unknown name -> rad/s
    and rad/s^2 (angles) or length unit/s and /s^2 (lengths); the joint and point maps:
    name -> (x, y) in the length unit (/s, /s^2). Empty rate maps when ``status`` is
    ``undefined`` (J is singular there, within its own uncertainty) or when no driver
    motion was given.

    Each rate carries an error bound (``*_bounds``: absolute, in the rate's unit; for a
    joint or point, on each of its x and y): the rates are computed at the position
    polished to full precision, and the bound covers rounding in J and the right-hand
    side, the position's remaining error and the inputs' representation, propagated
    through J^-1 (see :func:`rate_bounds`). A rate whose bound exceeds ``RATE_RTOL`` of
    itself (or of the driver's motion, where the rate is smaller) is listed by label in
    ``ill_conditioned`` (``dtheta3/dt``, ``d2theta3/dt2``, ``B.v``, ``B.a``), and the
    status is then ``ill_conditioned``."""

    joints: dict[str, XY]
    velocities: dict[str, float] = field(default_factory=dict)
    accelerations: dict[str, float] = field(default_factory=dict)
    joint_velocities: dict[str, XY] = field(default_factory=dict)
    joint_accelerations: dict[str, XY] = field(default_factory=dict)
    status: str = "ok"
    velocity_bounds: dict[str, float] = field(default_factory=dict)
    acceleration_bounds: dict[str, float] = field(default_factory=dict)
    joint_velocity_bounds: dict[str, float] = field(default_factory=dict)
    joint_acceleration_bounds: dict[str, float] = field(default_factory=dict)
    ill_conditioned: tuple[str, ...] = ()

    def flagged(self, label: str) -> bool:
        """Whether the rate labelled ``label`` (see :func:`rate_label`) is ill-conditioned."""
        return label in self.ill_conditioned


def polish(model: LoopModel, q: Any, d: float, funcs: Any = None) -> list[float]:
    """The position q made as exact as double precision allows: Newton steps (quadratic
    there, so usually one or two) while each step is smaller than the last and max|Phi|
    does not grow; q as given if the first step is refused. A solve stopped at its
    tolerance can be 1e-7 rad from the root near a limit, where the rates' sensitivity
    turns that into percent. ``funcs``: ``model.factory(d)`` if already built."""
    F, J, _ = funcs if funcs is not None else model.factory(d)
    q = [float(x) for x in q]
    phi = F(q)
    res = max_abs(phi)
    last = math.inf
    for _ in range(POLISH_STEPS):
        if not res > 0.0:
            break
        dq = newton_direction(J(q), phi)[0]
        if dq is None or not all(map(math.isfinite, dq)):
            break
        size = max_abs(dq)
        if not size < last:
            break
        trial = [a + b for a, b in zip(q, dq)]
        phi_t = F(trial)
        res_t = max_abs(phi_t)
        if not res_t <= res:
            break
        q, phi, res, last = trial, phi_t, res_t, size
        if all(abs(s) <= 4.0 * EPS * abs(x) for s, x in zip(dq, q)):
            break  # a step at rounding level: nothing more to gain
    return q


def rates_from_jacobian(jac: list[list[float]], dv: list[float], model: LoopModel, q: Any, d: float,
                        speed: float, accel: float) -> tuple[list[float], list[float]] | None:
    """(q', q'') from J q' = -(dPhi/dv) v' and J q'' = -(dPhi/dv) v'' - b (b:
    :func:`~.vectors.bias`), or None where J is singular (newton_direction's equilibrated
    test, the engine's one singularity rule)."""
    qd = newton_direction(jac, [speed * c for c in dv])[0]
    if qd is None or not all(map(math.isfinite, qd)):
        return None
    rhs = [accel * c + b for c, b in zip(dv, bias(model, q, d, qd, speed))]
    qdd = newton_direction(jac, rhs)[0]
    if qdd is None or not all(map(math.isfinite, qdd)):
        return None
    return qd, qdd


_COMPILED: dict[int, tuple[LoopModel, Any]] = {}


def compiled_np(model: LoopModel, d: Any, q: Any) -> tuple[Any, Any, Any]:
    """(Phi, J, dPhi/dv) over a block by the model's own compiled code (linkage.codegen's
    ``source``, the scalar :attr:`LoopModel.factory`'s text) run on numpy arrays: the same
    folded constants, the same sums in the same order, so the block's Phi and J are the
    scalar ones' bits (where numpy's cos and sin are the C library's). Stacks (..., rows),
    (..., rows, n), (..., rows). For a model of plain numbers (a scan's array parameters:
    :func:`jacobian_np`)."""
    import numpy as np

    got = _COMPILED.get(id(model))
    if got is None or got[0] is not model:
        namespace: dict[str, Any] = {"_cos": np.cos, "_sin": np.sin, "__builtins__": {}}
        exec(compile(model.source, "<linkage-model-numpy>", "exec"), namespace)
        if len(_COMPILED) > 16:
            _COMPILED.clear()
        got = _COMPILED[id(model)] = (model, namespace["make"])
    F, J, V = got[1](d)
    shape = np.shape(d)

    def stack(values: Any, axis: int) -> Any:
        return np.stack([np.broadcast_to(v, shape) for v in values], axis=axis)

    return (stack(F(q), -1), np.stack([stack(row, -1) for row in J(q)], axis=-2), stack(V(q), -1))


def jacobian_np(model: LoopModel, q: Any, d: Any) -> tuple[Any, Any, Any]:
    """(Phi, J, dPhi/dv) over a block of positions, from each vector's derivatives (the
    interpreted definition the compiled model is tested against, LoopModel.interpreted_functions),
    for a model whose parameters may be arrays: stacks (..., rows), (..., rows, n), (..., rows)."""
    import numpy as np

    d = np.asarray(d, dtype=float)
    n, rows = model.n, 2 * len(model.terms)
    phi = np.zeros((*d.shape, rows))
    jac = np.zeros((*d.shape, rows, n))
    dv = np.zeros((*d.shape, rows))
    for k, loop in enumerate(model.terms):
        for sign, lc, li, ac, ai, off in loop:
            r = value_of(li, lc, q, d)
            th = value_of(ai, ac, q, d) + off
            c, s = sign * np.cos(th), sign * np.sin(th)
            phi[..., 2 * k] += r * c
            phi[..., 2 * k + 1] += r * s
            for idx, (ex, ey) in ((li, (c, s)), (ai, (-r * s, r * c))):
                if idx >= 0:
                    jac[..., 2 * k, idx] += ex
                    jac[..., 2 * k + 1, idx] += ey
                elif idx == DRIVER:
                    dv[..., 2 * k] += ex
                    dv[..., 2 * k + 1] += ey
    return phi, jac, dv


def polish_np(model: LoopModel, q: Any, d: Any) -> list[Any]:
    """:func:`polish` over a block of positions (``q`` one array per unknown): each position's
    Newton steps under the same three rules (each step smaller than the last, max|Phi|
    not growing, stop at a step at rounding level), by masks."""
    import numpy as np

    d = np.asarray(d, dtype=float)
    x = np.stack([np.broadcast_to(np.asarray(c, dtype=float), d.shape) for c in q], axis=-1)
    phi, jac, _ = compiled_np(model, d, list(np.moveaxis(x, -1, 0)))
    res = np.abs(phi).max(axis=-1, initial=0.0)
    last = np.full(d.shape, np.inf)
    active = res > 0.0
    for _ in range(POLISH_STEPS):
        if not active.any():
            break
        dq, ok = direction_np(jac, phi)
        size = np.abs(dq).max(axis=-1, initial=0.0)
        trial = x + dq
        phi_t, jac_t, _ = compiled_np(model, d, list(np.moveaxis(trial, -1, 0)))
        res_t = np.abs(phi_t).max(axis=-1, initial=0.0)
        step = active & ok & (size < last) & (res_t <= res)
        x = np.where(step[..., None], trial, x)
        phi = np.where(step[..., None], phi_t, phi)
        jac = np.where(step[..., None, None], jac_t, jac)
        res, last = np.where(step, res_t, res), np.where(step, size, last)
        rounding = (np.abs(dq) <= 4.0 * EPS * np.abs(trial)).all(axis=-1)
        active = step & ~rounding & (res > 0.0)
    return list(np.moveaxis(x, -1, 0))


def rates_from_jacobian_np(jac: Any, dv: Any, model: LoopModel, q: Any, d: Any, speed: float,
                           accel: float) -> tuple[list[Any], list[Any], Any]:
    """:func:`rates_from_jacobian` over a block (stacks as :func:`compiled_np` gives them):
    (q', q'', solved), NaN where unsolved."""
    import numpy as np

    qd, ok = direction_np(jac, speed * dv)
    qd_list = list(np.moveaxis(qd, -1, 0))
    rhs = accel * dv + np.stack(np.broadcast_arrays(*bias_np(model, q, d, qd_list, speed)), axis=-1)
    qdd, ok2 = direction_np(jac, rhs)
    return qd_list, list(np.moveaxis(qdd, -1, 0)), ok & ok2


def solve_rates(model: LoopModel, q: Any, d: float, speed: float,
                accel: float) -> tuple[list[float], list[float]] | None:
    """(q', q'') at (q, d) for driver rate ``speed`` and ``accel`` (internal units), or
    None where J is singular. No polishing and no bound: see :func:`position_rates`."""
    _, J, V = model.factory(d)
    q = list(q)
    return rates_from_jacobian(J(q), V(q), model, q, d, speed, accel)


def solve_rates_np(model: LoopModel, q: Any, d: Any, speed: float, accel: float
                   ) -> tuple[list[Any], list[Any], Any]:
    """:func:`rates_from_jacobian`'s twin over arrays of positions (``model`` may carry arrays of
    parameters, :meth:`LoopModel.compile`'s ``values``): (q', q'', solved), the same two
    linear solves, J q' = -(dPhi/dv) v' and J q'' = -(dPhi/dv) v'' - b, with J and
    dPhi/dv from each vector's derivatives and b its centripetal and Coriolis parts. NaN
    (and solved False) where J is singular. No polishing and no bound: a batch's positions
    are judged by the loads' condition number (kinematics.forces)."""
    ((qd, qdd),), solved = motions_rates_np(model, q, d, ((speed, accel),))
    return qd, qdd, solved


def motions_rates_np(model: LoopModel, q: Any, d: Any, motions: Any, *, accelerations: bool = True
                     ) -> tuple[list[Any], Any]:
    """:func:`solve_rates_np` at each driver (speed, accel) of ``motions``, J and its
    inverse found once for all of them: [(q', q'') per motion], solved. q' is the unit
    speed's times the speed (J q' = -(dPhi/dv) v' is linear in v'). Without
    ``accelerations`` q'' is None (not computed: a static load needs velocities only)."""
    import numpy as np

    d = np.asarray(d, dtype=float)
    _, jac, dv = jacobian_np(model, q, d)
    inv, unit, solved = solve_np(jac, dv[..., None])
    unit = -unit[..., 0]
    out = []
    for speed, accel in motions:
        qd_list = list(np.moveaxis(speed * unit, -1, 0))
        if not accelerations:
            out.append((qd_list, None))
            continue
        rhs = accel * dv + np.stack(np.broadcast_arrays(d, *bias_np(model, q, d, qd_list, speed))[1:],
                                    axis=-1)
        qdd = -np.einsum("...ij,...j->...i", inv, rhs)
        out.append((qd_list, list(np.moveaxis(qdd, -1, 0))))
    return out, solved


def _xy(c: complex) -> XY:
    return (c.real, c.imag)


def position_rates(model: LoopModel, q: Any, d: float, speed: float | None = None,
                   accel: float = 0.0) -> Rates:
    """The joints and points at (q, d) (internal units), and with a driver ``speed`` the
    rates of every unknown, joint and point (internal units: rad/s for angles), each with
    its error bound: computed at q polished to full precision (:func:`polish`), bounded by
    :func:`rate_bounds`, flagged ``ill_conditioned`` beyond ``RATE_RTOL``, and absent
    (status ``undefined``) where J is singular within its own uncertainty."""
    names = [u.name for u in model.mechanism.unknowns]
    if speed is None:
        return Rates({k: _xy(p) for k, (p, _, _) in place(model, q, d).items()})
    funcs = model.factory(d)
    q = polish(model, q, d, funcs)
    _, J, V = funcs
    jac = J(q)
    solved = rates_from_jacobian(jac, V(q), model, q, d, speed, accel)
    if solved is None:
        return Rates({k: _xy(p) for k, (p, _, _) in place(model, q, d).items()}, status="undefined")
    qd, qdd = solved
    # each vector's values, once for its bounds and for the joints
    data = [[static_values(t, q, d, qd, speed, qdd, accel) for t in terms] for terms in model.terms]
    bounds = rate_bounds(model, q, d, speed, accel, qd, qdd, jac, data)
    if bounds is None:
        return Rates({k: _xy(p) for k, (p, _, _) in place(model, q, d).items()}, status="undefined")
    pts = place_bounded(model, q, d, qd, speed, qdd, accel, bounds.uncertainty, data)
    # the scale below which a rate is judged against the driver's own motion instead
    size = model.mechanism.length_scale
    omega = abs(speed) / (1.0 if model.mechanism.driver.kind == "angle" else size)
    alpha = abs(accel) / (1.0 if model.mechanism.driver.kind == "angle" else size) + omega * omega
    kinds = [u.kind for u in model.mechanism.unknowns]
    flags: list[str] = []

    def judge(label: str, value: float, bound: float, floor: float) -> None:
        if not bound <= RATE_RTOL * max(abs(value), floor):
            flags.append(label)

    vb = [SAFETY * b for b in bounds.velocity]
    ab = [SAFETY * b for b in bounds.acceleration]
    for name, kind, v, a, bv, ba in zip(names, kinds, qd, qdd, vb, ab):
        unit = 1.0 if kind == "angle" else size
        judge(rate_label(name, 1), v, bv, omega * unit)
        judge(rate_label(name, 2), a, ba, alpha * unit)
    jvb = {k: SAFETY * bv for k, (_, _, _, bv, _) in pts.items()}
    jab = {k: SAFETY * ba for k, (_, _, _, _, ba) in pts.items()}
    for k, (_, v, a, _, _) in pts.items():
        judge(rate_label(k, 1, joint=True), abs(v), jvb[k], omega * size)
        judge(rate_label(k, 2, joint=True), abs(a), jab[k], alpha * size)
    return Rates(
        joints={k: _xy(p[0]) for k, p in pts.items()},
        velocities=dict(zip(names, qd)),
        accelerations=dict(zip(names, qdd)),
        joint_velocities={k: _xy(p[1]) for k, p in pts.items()},
        joint_accelerations={k: _xy(p[2]) for k, p in pts.items()},
        status="ill_conditioned" if flags else "ok",
        velocity_bounds=dict(zip(names, vb)),
        acceleration_bounds=dict(zip(names, ab)),
        joint_velocity_bounds=jvb,
        joint_acceleration_bounds=jab,
        ill_conditioned=tuple(flags),
    )


def rates_at(mechanism: Any, q: Any, *, speed: float | None = None, accel: float = 0.0,
             driver: float | None = None) -> Rates:
    """The public ``linkage.position_rates``: joints and points of ``mechanism`` at the
    solution ``q`` (radians and length units, as ``solve_system`` returns it), at its
    driver value (or ``driver``, internal units), with the rates of everything when a
    driver ``speed`` (rad/s or length/s) and ``accel`` are given. ``mechanism`` may be a
    path to a file. Numbers only, in those internal units (a unit string such as "10rpm"
    is the command line's); every argument is checked first, and a misuse raises
    :class:`~linkage.errors.InputError` naming it."""
    from ..arguments import check_motion, check_number, check_reals
    from .loading import mechanism_of

    mechanism = mechanism_of("mechanism", mechanism)
    names = [u.name for u in mechanism.unknowns]
    q = check_reals("q", q, len(names), names)
    speed, accel = check_motion(speed, accel, mechanism.driver.kind, mechanism.length_unit)
    model = mechanism.model
    d = mechanism.driver.value if driver is None else check_number("driver", driver)
    # the rates are those of the solution through q (polished to full precision): a q that
    # closes no loop would silently get another position's rates, or be called singular
    from ..errors import InputError
    from ..solve import MAX_RELATIVE_TOL

    gap = max(map(abs, model.functions(d)[0](list(q))), default=0.0)
    allowed = MAX_RELATIVE_TOL * mechanism.length_scale
    if not gap <= allowed:
        unit = f" {mechanism.length_unit}" if mechanism.length_unit else ""
        raise InputError(f"q is not a solution at this driver value: it leaves the loops open by "
                         f"{gap:.3g}{unit}, more than the {allowed:.3g}{unit} (1% of the mechanism's "
                         "size) any solve's tolerance allows; solve first (solve_system)")
    return position_rates(model, q, d, speed, accel)
