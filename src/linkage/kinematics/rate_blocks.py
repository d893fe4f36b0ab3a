"""A block of positions' rates at once: :func:`block_rates` is
:func:`~.rates.position_rates` over numpy arrays, step for step (polish, the two linear
solves, the bounds, the placing rule, the ``ill_conditioned`` judgement), so a sweep's
rates cost what its positions do (docs/performance_loads.md). The answer,
:class:`RateBlock`, holds one array per rate; :meth:`RateBlock.rates` gives any position's
:class:`~.rates.Rates`, the same numbers as the scalar definition to its last bits (numpy's
cos and sin need not be the C library's; tests/test_rate_blocks.py holds the two
together). :func:`with_rates` gives a sweep's positions their rates, a block at a time
from RATES_BLOCK_ABOVE solved positions.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from ..problems.loops import ANGLE_UNITS, LoopModel
from ..records import frozen
from ..units import radians
from .labels import rate_label
from .placing import place_bounded
from .rate_bounds import SAFETY, rate_bounds_np, static_values
from .rates import RATE_RTOL, Rates, compiled_np, polish_np, position_rates, rates_from_jacobian_np
from .vectors import numpy_kit

if TYPE_CHECKING:  # a solve's rates do not load the sweep's types
    from .positions import SweepResult

OK, ILL, UNDEFINED = "ok", "ill_conditioned", "undefined"


@frozen
class RateBlock:
    """Rates at a block of positions, one array entry per position (internal units, as
    :class:`~.rates.Rates`), NaN where a rate is absent (``status`` undefined: then only
    the joints are numbers). ``flags``: each rate's label with where it is ill-conditioned,
    in the order :class:`~.rates.Rates` lists them."""

    status: Any
    """Text per position (object array): ok, ill_conditioned, undefined."""
    joints: dict[str, tuple[Any, Any]]
    velocities: dict[str, Any]
    accelerations: dict[str, Any]
    joint_velocities: dict[str, tuple[Any, Any]]
    joint_accelerations: dict[str, tuple[Any, Any]]
    velocity_bounds: dict[str, Any]
    acceleration_bounds: dict[str, Any]
    joint_velocity_bounds: dict[str, Any]
    joint_acceleration_bounds: dict[str, Any]
    flags: tuple[tuple[str, Any], ...]

    def __len__(self) -> int:
        return len(self.status)

    def rates(self) -> list[Rates | None]:
        """Each position's :class:`~.rates.Rates` (plain floats, as the scalar definition
        gives them); None where the position is absent (unsolved, :meth:`spread`)."""
        n = len(self)
        status = self.status.tolist()
        joints = _pairs(self.joints)
        names = list(self.velocities)
        vel, acc = _lists(self.velocities), _lists(self.accelerations)
        vb, ab = _lists(self.velocity_bounds), _lists(self.acceleration_bounds)
        jv, ja = _pairs(self.joint_velocities), _pairs(self.joint_accelerations)
        jvb, jab = _lists(self.joint_velocity_bounds), _lists(self.joint_acceleration_bounds)
        flags = [(label, where.tolist()) for label, where in self.flags]
        out = []
        for i in range(n):
            if status[i] is None:
                out.append(None)
                continue
            placed = {k: (x[i], y[i]) for k, (x, y) in joints.items()}
            if status[i] == UNDEFINED:
                out.append(Rates(placed, status=UNDEFINED))
                continue
            if not names:
                out.append(Rates(placed))
                continue
            out.append(Rates(
                placed, {k: v[i] for k, v in vel.items()}, {k: v[i] for k, v in acc.items()},
                {k: (x[i], y[i]) for k, (x, y) in jv.items()}, {k: (x[i], y[i]) for k, (x, y) in ja.items()},
                status[i], {k: v[i] for k, v in vb.items()}, {k: v[i] for k, v in ab.items()},
                {k: v[i] for k, v in jvb.items()}, {k: v[i] for k, v in jab.items()},
                tuple(label for label, where in flags if where[i])))
        return out

    def spread(self, rows: Any, size: int) -> RateBlock:
        """This block's positions placed at ``rows`` of a block of ``size`` positions, the
        others absent (status None, every number NaN: an unsolved position)."""
        import numpy as np

        def put(a: Any) -> Any:
            out = np.full(size, np.nan)
            out[rows] = a
            return out

        status = np.full(size, None, dtype=object)
        status[rows] = self.status
        flags = []
        for label, where in self.flags:
            f = np.zeros(size, dtype=bool)
            f[rows] = where
            flags.append((label, f))
        return RateBlock(
            status, _each(self.joints, put), _each(self.velocities, put), _each(self.accelerations, put),
            _each(self.joint_velocities, put), _each(self.joint_accelerations, put),
            _each(self.velocity_bounds, put), _each(self.acceleration_bounds, put),
            _each(self.joint_velocity_bounds, put), _each(self.joint_acceleration_bounds, put),
            tuple(flags))

    def take(self, key: Any) -> RateBlock:
        """The positions ``key`` (a slice or an integer array) of this block."""
        def pick(a: Any) -> Any:
            return a[key]

        return RateBlock(
            pick(self.status), _each(self.joints, pick), _each(self.velocities, pick),
            _each(self.accelerations, pick), _each(self.joint_velocities, pick),
            _each(self.joint_accelerations, pick), _each(self.velocity_bounds, pick),
            _each(self.acceleration_bounds, pick), _each(self.joint_velocity_bounds, pick),
            _each(self.joint_acceleration_bounds, pick), tuple((k, pick(v)) for k, v in self.flags))

    @staticmethod
    def join(blocks: list[RateBlock]) -> RateBlock:
        """Blocks one after another, as one."""
        import numpy as np

        first = blocks[0]
        if len(blocks) == 1:
            return first

        def cat(get: Any) -> Any:
            maps = [get(b) for b in blocks]
            return {k: (tuple(np.concatenate([m[k][p] for m in maps]) for p in range(2))
                        if isinstance(v, tuple) else np.concatenate([m[k] for m in maps]))
                    for k, v in maps[0].items()}

        return RateBlock(
            np.concatenate([b.status for b in blocks]), cat(lambda b: b.joints),
            cat(lambda b: b.velocities), cat(lambda b: b.accelerations),
            cat(lambda b: b.joint_velocities), cat(lambda b: b.joint_accelerations),
            cat(lambda b: b.velocity_bounds), cat(lambda b: b.acceleration_bounds),
            cat(lambda b: b.joint_velocity_bounds), cat(lambda b: b.joint_acceleration_bounds),
            tuple((label, np.concatenate([dict(b.flags)[label] for b in blocks]))
                  for label, _ in first.flags))

    def flagged(self, label: str) -> Any:
        """Where the rate labelled ``label`` is ill-conditioned (a bool array)."""
        return dict(self.flags)[label]


def _lists(m: dict[str, Any]) -> dict[str, list[float]]:
    return {k: v.tolist() for k, v in m.items()}


def _pairs(m: dict[str, tuple[Any, Any]]) -> dict[str, tuple[list[float], list[float]]]:
    return {k: (x.tolist(), y.tolist()) for k, (x, y) in m.items()}


def _each(m: dict[str, Any], f: Any) -> dict[str, Any]:
    return {k: (f(v[0]), f(v[1])) if isinstance(v, tuple) else f(v) for k, v in m.items()}


def block_rates(model: LoopModel, q: Any, d: Any, speed: float | None = None,
                accel: float = 0.0) -> RateBlock:
    """:func:`~.rates.position_rates` at a block of solved positions (``q`` one array per
    unknown, ``d`` the driver's array, internal units): every step the same, by masks."""
    import numpy as np

    d = np.asarray(d, dtype=float)
    names = [u.name for u in model.mechanism.unknowns]
    zero = [np.zeros(d.shape)] * model.n
    if speed is None:
        pts = place_bounded(model, q, d, zero, 0.0, zero, 0.0, None, xp=numpy_kit())
        return RateBlock(np.full(d.shape, OK, dtype=object), {k: _xy(p[0], d) for k, p in pts.items()},
                         {}, {}, {}, {}, {}, {}, {}, {}, ())
    q = polish_np(model, q, d)
    _, jac, dv = compiled_np(model, d, q)
    qd, qdd, ok = rates_from_jacobian_np(jac, dv, model, q, d, speed, accel)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        kit = numpy_kit()
        data = [[static_values(t, q, d, qd, speed, qdd, accel, kit) for t in terms] for terms in model.terms]
        rows = [[jac[..., i, j] for j in range(model.n)] for i in range(jac.shape[-2])]
        bounds, usable = rate_bounds_np(model, q, d, speed, accel, rows, data)
        ok &= usable
        pts = place_bounded(model, q, d, qd, speed, qdd, accel, bounds.uncertainty, data, kit)
    return _judged(model, names, d, speed, accel, ok, qd, qdd, bounds, pts)


def _judged(model: LoopModel, names: list[str], d: Any, speed: float, accel: float, ok: Any, qd: Any,
            qdd: Any, bounds: Any, pts: Any) -> RateBlock:
    """The block's rates with their bounds, each judged against ``RATE_RTOL`` as
    :func:`~.rates.position_rates` judges one position's (the same floors, the same order)."""
    import numpy as np

    m = model.mechanism
    size = m.length_scale
    omega = abs(speed) / (1.0 if m.driver.kind == "angle" else size)
    alpha = abs(accel) / (1.0 if m.driver.kind == "angle" else size) + omega * omega
    nan = np.full(d.shape, np.nan)

    def keep(a: Any) -> Any:
        return np.where(ok, np.broadcast_to(a, d.shape), nan)

    flags: list[tuple[str, Any]] = []

    def judge(label: str, value: Any, bound: Any, floor: float) -> None:
        with np.errstate(invalid="ignore"):
            flags.append((label, ok & ~(bound <= RATE_RTOL * np.maximum(np.abs(value), floor))))

    vb = [keep(SAFETY * b) for b in bounds.velocity]
    ab = [keep(SAFETY * b) for b in bounds.acceleration]
    qd, qdd = [keep(v) for v in qd], [keep(a) for a in qdd]
    for name, u, v, a, bv, ba in zip(names, m.unknowns, qd, qdd, vb, ab):
        unit = 1.0 if u.kind == "angle" else size
        judge(rate_label(name, 1), v, bv, omega * unit)
        judge(rate_label(name, 2), a, ba, alpha * unit)
    jvb = {k: keep(SAFETY * p[3]) for k, p in pts.items()}
    jab = {k: keep(SAFETY * p[4]) for k, p in pts.items()}
    for k, (_, v, a, _, _) in pts.items():
        judge(rate_label(k, 1, joint=True), np.hypot(v.real, v.imag), jvb[k], omega * size)
        judge(rate_label(k, 2, joint=True), np.hypot(a.real, a.imag), jab[k], alpha * size)
    flagged = np.logical_or.reduce([f for _, f in flags]) if flags else np.zeros(d.shape, dtype=bool)
    status = np.where(ok, np.where(flagged, ILL, OK), UNDEFINED).astype(object)
    return RateBlock(
        status, {k: _xy(p[0], d) for k, p in pts.items()}, dict(zip(names, qd)), dict(zip(names, qdd)),
        {k: tuple(keep(c) for c in _xy(p[1], d)) for k, p in pts.items()},
        {k: tuple(keep(c) for c in _xy(p[2], d)) for k, p in pts.items()},
        dict(zip(names, vb)), dict(zip(names, ab)), jvb, jab, tuple(flags))


def _xy(c: Any, like: Any) -> tuple[Any, Any]:
    """A complex array (or a joint's constant) as full (x, y) columns shaped as ``like``."""
    import numpy as np

    c = np.broadcast_to(np.asarray(c, dtype=complex), np.shape(like))
    return c.real.copy(), c.imag.copy()


def sweep_block(m: Any, solution: Any, driver: Any, solved: Any, speed: float | None,
                accel: float) -> RateBlock:
    """A block of a sweep's positions' rates (``solution`` (N, n) in display units, as a
    batch result holds it, ``driver`` display units, ``solved`` where converged): the
    solved positions by :func:`block_rates`, the others absent."""
    import numpy as np

    rows = np.flatnonzero(solved)
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    q = [radians(solution[rows, j]) if u.kind == "angle" else solution[rows, j].astype(float)
         for j, u in enumerate(m.unknowns)]
    d = np.asarray(driver, dtype=float)[rows] * scale
    return block_rates(m.model, q, d, speed, accel).spread(rows, len(solved))


RATES_BLOCK_ABOVE = 1000
"""From this many solved positions :func:`with_rates` computes their rates as one block
(kinematics.rate_blocks: numpy, the same numbers); below, one at a time (a small sweep's
command does not pay numpy's import)."""


def with_rates(m: Any, result: SweepResult, speed: float | None, accel: float) -> SweepResult:
    """Joints, and with a driver speed velocities and accelerations, at every solved position."""
    from dataclasses import replace

    from .positions import with_position_rates

    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    solved = [p.solution is not None for p in result.positions]
    if sum(solved) >= RATES_BLOCK_ABOVE:
        import numpy as np

        sol = np.array([[p.solution[u.name] for u in m.unknowns] if p.solution is not None
                        else [math.nan] * len(m.unknowns) for p in result.positions], dtype=float)
        inputs = np.array([p.input for p in result.positions], dtype=float)
        block = sweep_block(m, sol.reshape(len(solved), len(m.unknowns)), inputs, np.array(solved),
                            speed, accel)
        rates = block.rates()
        positions = tuple(with_position_rates(p, r) if ok else p
                          for p, r, ok in zip(result.positions, rates, solved))
    else:
        kinds = [u.kind for u in m.unknowns]
        positions = tuple(
            p if p.solution is None else with_position_rates(p, position_rates(
                m.model, [radians(p.solution[u.name]) if k == "angle" else p.solution[u.name]
                        for u, k in zip(m.unknowns, kinds)], p.input * scale, speed, accel))
            for p in result.positions)
    motion = (speed, accel) if speed is not None else None
    return replace(result, positions=positions, motion=motion)
