"""Every assembly of a mechanism at one driver value, by polynomial homotopy continuation.

The loop equations become polynomials: each unknown angle theta is the pair (c, s) =
(cos theta, sin theta) with c^2 + s^2 = 1, each unknown length stays a variable, and each
loop's sum of vectors sign * length * e^(i (angle + offset)) splits into its real and
imaginary parts, polynomials of degree 1 (2 where a vector both turns and slides). Every
root of that system (:mod:`linkage.homotopy`) is an assembly: the real ones are the
mechanism's, each polished by Newton's method on the loop equations themselves and named
as sweeps name it (its closed form's branch, or the sign of det J); the complex ones are
counted. Bezout's bound (the product of the degrees) is the number of paths tracked.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from ..homotopy import PolySystem, Solutions, solve
from ..problems.loops import ANGLE_UNITS, DRIVER, Mechanism
from .angles import nearest_turn

Monomials = dict[tuple[int, ...], complex]


@dataclass(frozen=True)
class Assembly:
    """One real assembly: the unknowns (internal units), its name, its residual."""

    q: tuple[float, ...]
    branch: str
    signs: str  # the closed form's signs ("" without a closed form)
    residual: float  # max |Phi| after polishing, relative to the mechanism's size
    condition: float  # the homotopy's condition number of the root
    singular: bool  # a double root: two assemblies meeting (a change point, a limit)
    joints: dict[str, tuple[float, float]]  # every named joint and point


@dataclass(frozen=True)
class Assemblies:
    mechanism: Mechanism
    driver: float  # internal units
    real: tuple[Assembly, ...]
    complex_count: int  # nonreal finite roots (pairs count as two)
    infinite: int
    failed: int
    solutions: Solutions

    @property
    def bezout(self) -> int:
        return self.solutions.bezout


def _variables(m: Mechanism) -> list[tuple[str, int]]:
    """(kind, first variable) of each unknown: an angle takes (c, s), a length one."""
    out, k = [], 0
    for u in m.unknowns:
        out.append((u.kind, k))
        k += 2 if u.kind == "angle" else 1
    return out


def assembly_system(m: Mechanism, driver: float) -> PolySystem:
    """The loop equations at ``driver`` (internal units) as polynomials in (c, s) per
    unknown angle and one variable per unknown length, in units of the mechanism's size
    (so that every variable is of order 1: a path tracker's steps and tests are relative
    to |X|, and a slide of 90 cm beside cosines would swamp them), with c^2 + s^2 - 1 per
    angle."""
    var = _variables(m)
    size = m.length_scale
    n = sum(2 if kind == "angle" else 1 for kind, _ in var)

    def mono(*idx: int) -> tuple[int, ...]:
        e = [0] * n
        for i in idx:
            e[i] += 1
        return tuple(e)

    polys: list[Monomials] = []
    for terms in m.model.terms:
        loop: Monomials = {}

        def add(e: tuple[int, ...], c: complex, loop: Monomials = loop) -> None:
            loop[e] = loop.get(e, 0j) + c

        for sign, lc, li, ac, ai, off in terms:
            length = (driver if li == DRIVER else lc) / size
            angle = driver if ai == DRIVER else ac
            if ai >= 0:
                rot = sign * complex(math.cos(off), math.sin(off))
                c, s = var[ai][1], var[ai][1] + 1
                if li >= 0:
                    j = var[li][1]
                    add(mono(j, c), rot)
                    add(mono(j, s), 1j * rot)
                else:
                    add(mono(c), rot * length)
                    add(mono(s), 1j * rot * length)
            else:
                e = sign * complex(math.cos(angle + off), math.sin(angle + off))
                if li >= 0:
                    add(mono(var[li][1]), e)
                else:
                    add(mono(), e * length)
        scale = max((abs(v) for v in loop.values()), default=1.0) or 1.0
        for part in (lambda z: z.real, lambda z: z.imag):
            poly = {e: complex(part(c) / scale) for e, c in loop.items()}
            poly = {e: c for e, c in poly.items() if c != 0}
            if not poly:
                raise InputError(f"{m.source}: a loop's equations are identically zero")
            polys.append(poly)
    for kind, k in var:
        if kind == "angle":
            polys.append({mono(k, k): 1 + 0j, mono(k + 1, k + 1): 1 + 0j, mono(): -1 + 0j})
    return PolySystem(n, tuple(polys))


RESIDUAL = 1e-12
"""A real root of the polynomials is an assembly when the loops close to this, relative to
the mechanism's size, after Newton's method on the loop equations themselves."""
POLISH_STEPS = 60
"""Newton converges only linearly at a double root (a limit position): half the distance a
step, so reaching rounding from the endgame's sqrt(eps) takes about 30."""


def _polish(m: Mechanism, driver: float, q: list[float]) -> tuple[list[float], float]:
    """Newton's method on the loop equations, each step kept only if it lowers max|Phi|
    (near a singular J rounding throws a step anywhere): (q, max|Phi| / size)."""
    F, J = m.model.functions(driver)
    q = [float(v) for v in q]
    res = max(abs(v) for v in F(q))
    for _ in range(POLISH_STEPS):
        try:
            dq = np.linalg.solve(np.array(J(q)), np.array(F(q)))
        except np.linalg.LinAlgError:
            break
        trial = [a - b for a, b in zip(q, dq)]
        r = max(abs(v) for v in F(trial))
        if not r < res:
            break
        q, res = trial, r
    return q, res / m.length_scale


def _name(m: Mechanism, driver: float, q: list[float]) -> tuple[str, str]:
    der = m.derivation
    if der.complete:
        from ..problems.derive import sign_text

        return der.name_of(q, driver), sign_text(der.signs_of(q, driver))
    _, J = m.model.functions(driver)
    det = float(np.linalg.det(np.array(J(q))))
    return ("det J > 0" if det > 0 else "det J < 0" if det < 0 else "det J = 0"), ""


def _joints(m: Mechanism, driver: float, q: list[float]) -> dict[str, tuple[float, float]]:
    """Every named joint and point, by the one placing rule (rates.place: a drawing's fixed
    joints where they were drawn)."""
    from .rates import place

    return {name: (p.real, p.imag) for name, (p, _, _) in place(m.model, q, driver).items()}


def assemblies(m: Mechanism, driver: float | None = None, seed: int = 0) -> Assemblies:
    """Every assembly of ``m`` at ``driver`` (internal units; default the file's value)."""
    d = m.driver.value if driver is None else driver
    system = assembly_system(m, d)
    if len(system.polynomials) != system.n:
        raise InputError(f"{m.source}: {len(system.polynomials)} equations in {system.n} polynomial "
                         "unknowns: the loops do not fix the unknowns (mobility is not 1)")
    sols = solve(system, seed=seed)
    var = _variables(m)

    def decode(x: np.ndarray) -> list[float]:
        return [math.atan2(x[k + 1], x[k]) if kind == "angle" else float(x[k]) * m.length_scale
                for kind, k in var]

    real: list[Assembly] = []

    def keep(q: list[float], e: Any, singular: bool) -> bool:
        q = [math.radians(nearest_turn(math.degrees(u.value), math.degrees(v))) if u.kind == "angle" else v
             for u, v in zip(m.unknowns, q)]  # angles in the turn of the file's guess
        if any(_same(q, a.q, m) for a in real):
            return False
        branch, signs = _name(m, d, q)
        residual = max(abs(v) for v in m.model.functions(d)[0](q)) / m.length_scale
        real.append(Assembly(tuple(q), branch, signs, residual, e.condition, singular, _joints(m, d, q)))
        return True

    nonreal = 0
    clusters: list[tuple[np.ndarray, list[Any]]] = []
    for e in sols.endpoints:
        if e.kind == "finite" and e.x is not None:
            if not e.real:
                nonreal += 1
                continue
            q, residual = _polish(m, d, decode(e.x.real))
            if residual <= RESIDUAL:
                keep(q, e, False)
            else:
                nonreal += 1
        elif e.kind == "singular" and e.x is not None:
            for x, members in clusters:
                if np.linalg.norm(x - e.x) <= 1e-6 * max(1.0, float(np.linalg.norm(x))):
                    members.append(e)
                    break
            else:
                clusters.append((e.x, [e]))
    # a singular endpoint is two (or more) roots that meet, or nearly meet (a limit
    # position): which of them are real is decided on the loops themselves
    for x, members in clusters:
        found = sum(keep(q, members[0], True) for q in _split(m, d, decode(x.real))[: len(members)])
        nonreal += len(members) - found
    return Assemblies(m, d, tuple(real), nonreal, sols.count("infinite"), sols.count("failed"), sols)


def _split(m: Mechanism, driver: float, q0: list[float]) -> list[list[float]]:
    """The real roots of the loop equations near a singular point q0: Newton's method from
    q0, and from q0 +- s v along J's null direction v for s from 1e-9 to 1e-2 (two roots
    that nearly meet sit on either side of it, sqrt(gap) apart), each kept if the loops
    close to :data:`RESIDUAL`."""
    _, J = m.model.functions(driver)
    scale = np.array([1.0 if u.kind == "angle" else m.length_scale for u in m.unknowns])
    try:
        v = np.linalg.svd(np.array(J(q0)) * scale[None, :])[2][-1] * scale
    except np.linalg.LinAlgError:
        v = np.zeros(len(q0))
    out: list[list[float]] = []
    starts = [np.array(q0)] + [np.array(q0) + sign * s * v for s in np.logspace(-9, -2, 15)
                                for sign in (1.0, -1.0)]
    for start in starts:
        q, residual = _polish(m, driver, list(start))
        if residual <= RESIDUAL and not any(_same(q, tuple(o), m) for o in out):
            out.append(q)
        if len(out) >= 2 and start is not starts[0]:
            break
    return out


def every_assembly(mechanism: Mechanism | str | Any, driver: float | None = None, *,
                   seed: int = 0) -> Assemblies:
    """Every assembly of a mechanism at one driver value; the public ``linkage.assemblies``.

    ``mechanism``: a :class:`~linkage.problems.loops.Mechanism` or a path to a file.
    ``driver``: the driver's value in the file's units (degrees for an angle in deg);
    default the file's. ``seed``: the homotopy's random gamma and patch. The result's
    ``real`` lists each real assembly (``q`` in internal units, ``branch``, ``residual``,
    ``joints``); ``complex_count``, ``infinite`` and ``failed`` count the other paths, and
    ``solutions`` has every path's endpoint and its steps. Every argument is checked
    first: a misuse raises :class:`~linkage.errors.InputError` naming it."""
    from ..arguments import MAX_SEED, check_number, check_whole
    from ..problems.loops import mechanism_of

    m = mechanism_of("mechanism", mechanism)
    seed = check_whole("seed", seed, 0, MAX_SEED)
    if driver is not None:
        if isinstance(driver, bool):
            raise InputError(f"driver must be a number, got {driver!r}")
        value = check_number("driver", driver)
        try:
            m = m.with_values({m.driver.name: value}, {})
        except InputError as exc:
            raise InputError(f"driver: {exc}") from None
    return assemblies(m, seed=seed)


def _same(a: tuple[float, ...] | list[float], b: tuple[float, ...], m: Mechanism) -> bool:
    tol = 1e-7
    for u, x, y in zip(m.unknowns, a, b):
        if u.kind == "angle":
            if abs(math.remainder(x - y, 2 * math.pi)) > tol:
                return False
        elif abs(x - y) > tol * m.length_scale:
            return False
    return True


def display(m: Mechanism, q: tuple[float, ...]) -> list[float]:
    """The unknowns in the file's units (degrees for angles in deg)."""
    return [v / ANGLE_UNITS[u.unit] if u.kind == "angle" else v for u, v in zip(m.unknowns, q)]
