"""Every assembly of a mechanism at one driver value, by polynomial homotopy continuation.

The loop equations become polynomials in isotropic coordinates: each unknown angle theta is
the pair z = e^(i theta), w = e^(-i theta) with z w = 1, each unknown length stays a
variable, and each loop's sum of vectors sign * length * e^(i (angle + offset)) is one
equation in the z's and its conjugate in the w's, of degree 1 (2 where a vector both turns
and slides). Every root of that system (:mod:`linkage.homotopy`) is an assembly: the real
ones (w = conj(z), |z| = 1) are the mechanism's, each polished by Newton's method on the
loop equations themselves and named as sweeps name it (its closed form's branch, or the
sign of det J); the complex ones are counted. The paths tracked are the roots of a
linear-product start system matched to the grouping {z}, {w}, {lengths}: the
multihomogeneous Bezout number or fewer, stated beside the total degree.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from ..errors import InputError
from ..homotopy import PolySystem, Solutions, condition, solve
from ..problems.loops import ANGLE_UNITS, DRIVER, Mechanism
from ..records import frozen
from ..units import degrees, radians
from .angles import nearest_turn

Monomials = dict[tuple[int, ...], complex]


@frozen
class Assembly:
    """One real assembly: the unknowns (internal units), its name, its residual."""

    q: tuple[float, ...]
    branch: str
    signs: str  # the closed form's signs ("" without a closed form)
    residual: float  # max |Phi| after polishing, relative to the mechanism's size
    condition: float  # homotopy.solve.condition of the polynomial system at this assembly
    singular: bool  # near_limit: condition above NEAR_LIMIT (two assemblies meet close by)
    joints: dict[str, tuple[float, float]]  # every named joint and point


@frozen
class Assemblies:
    mechanism: Mechanism
    driver: float  # internal units
    real: tuple[Assembly, ...]
    complex_count: int  # nonreal finite roots (pairs count as two)
    infinite: int
    failed: int
    solutions: Solutions
    multiplicity: tuple[int, ...] = ()  # of each real assembly: 2 for a double root
    unresolved: int = 0  # roots near a singular point neither found real nor shown complex
    continuum: bool = False  # the loops close all along a curve here: not isolated

    @property
    def bezout(self) -> int:
        """The total degree of the polynomial system."""
        return self.solutions.bezout

    @property
    def bound(self) -> int:
        """The paths tracked, the start system's root count: the bound on isolated assemblies."""
        return self.solutions.bound


def _variables(m: Mechanism) -> list[tuple[str, int]]:
    """(kind, first variable) of each unknown: an angle takes (z, w), a length one."""
    out, k = [], 0
    for u in m.unknowns:
        out.append((u.kind, k))
        k += 2 if u.kind == "angle" else 1
    return out


def assembly_system(m: Mechanism, driver: float) -> PolySystem:
    """The loop equations at ``driver`` (internal units) as polynomials in isotropic
    coordinates: z = e^(i theta) and w = e^(-i theta) per unknown angle, with z w = 1, and
    one variable per unknown length, in units of the mechanism's size (so that every
    variable is of order 1: a path tracker's steps and tests are relative to |X|, and a
    slide of 90 cm beside cosines would swamp them). Each loop's sum of vectors sign *
    length * e^(i (angle + offset)) = 0 is one equation in the z's and its conjugate one in
    the w's (Wampler, Morgan and Sommese, "Complete solution of the nine-point path
    synthesis problem for four-bar linkages", J. Mech. Des. 114, 1992, sec. 2). Grouped as
    {z}, {w}, {lengths}, the linear-product start (:mod:`linkage.homotopy.start`) has the
    multihomogeneous Bezout number of paths or fewer: 2 for a four-bar, 4 for the two
    four-bars of a Watt six-bar, at most C(4, 2) = 6 for a six-bar, against total degrees of
    4 and 16 (every path beyond the assemblies' own count goes to infinity)."""
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
        loop: Monomials = {}  # in z's; its conjugate swaps each z for its w
        swap: dict[tuple[int, ...], tuple[int, ...]] = {}

        def add(e: tuple[int, ...], c: complex, mirror: tuple[int, ...], loop: Monomials = loop,
                swap: dict[tuple[int, ...], tuple[int, ...]] = swap) -> None:
            loop[e] = loop.get(e, 0j) + c
            swap[e] = mirror

        for sign, lc, li, ac, ai, off in terms:
            length = (driver if li == DRIVER else lc) / size
            angle = driver if ai == DRIVER else ac
            if ai >= 0:
                rot = sign * complex(math.cos(off), math.sin(off))
                z, w = var[ai][1], var[ai][1] + 1
                if li >= 0:
                    add(mono(var[li][1], z), rot, mono(var[li][1], w))
                else:
                    add(mono(z), rot * length, mono(w))
            else:
                e = sign * complex(math.cos(angle + off), math.sin(angle + off))
                if li >= 0:
                    add(mono(var[li][1]), e, mono(var[li][1]))
                else:
                    add(mono(), e * length, mono())
        scale = max((abs(v) for v in loop.values()), default=1.0) or 1.0
        poly = {e: c / scale for e, c in loop.items() if c != 0}
        if not poly:
            raise InputError(f"{m.source}: a loop's equations are identically zero")
        polys += [poly, {swap[e]: c.conjugate() for e, c in poly.items()}]
    for kind, k in var:
        if kind == "angle":
            polys.append({mono(k, k + 1): 1 + 0j, mono(): -1 + 0j})
    angles = [k for kind, k in var if kind == "angle"]
    lengths = tuple(k for kind, k in var if kind != "angle")
    groups = tuple(g for g in (tuple(angles), tuple(k + 1 for k in angles), lengths) if g)
    conjugate = [0] * n
    for kind, k in var:
        if kind == "angle":
            conjugate[k], conjugate[k + 1] = k + 1, k
        else:
            conjugate[k] = k
    return PolySystem(n, tuple(polys), groups=groups, conjugate=tuple(conjugate))


RESIDUAL = 1e-12
"""A real root of the polynomials is an assembly when the loops close to this, relative to
the mechanism's size, after Newton's method on the loop equations themselves."""
POLISH_STEPS = 80
"""Newton converges only linearly at a double root (a limit position): half the distance a
step, so reaching rounding from the endgame's sqrt(eps) takes about 30."""
DOUBLE = 1e-14
"""Two assemblies that touch without crossing (a limit position exactly): the loops must
close to this, relative to the size, where they meet. A driver 1e-10 deg past a limit
leaves a gap of about 1e-12: no assembly."""
NEAR_LIMIT = 1e6
"""An assembly whose own condition (homotopy.solve.condition, at the assembly) exceeds this
is flagged near_limit: two assemblies meet close by, and its last six digits are not
significant."""


def _polish(m: Mechanism, driver: float, q: list[float]) -> tuple[list[float], float]:
    """Newton's method on the loop equations with backtracking (a step is halved until it
    lowers max|Phi|: near a singular J a full step overshoots), until the steps stop
    shrinking: (q, max|Phi| / size)."""
    F, J = m.model.functions(driver)
    q = [float(v) for v in q]
    res = max(abs(v) for v in F(q))
    for _ in range(POLISH_STEPS):
        try:
            dq = np.linalg.solve(np.array(J(q)), np.array(F(q)))
        except np.linalg.LinAlgError:
            break
        factor = 1.0
        while factor > 1e-6:
            trial = [a - factor * b for a, b in zip(q, dq)]
            r = max(abs(v) for v in F(trial))
            if r < res:
                break
            factor *= 0.5
        else:
            break
        q, res = trial, r
        if res == 0.0:
            break
    return q, res / m.length_scale


def _local_roots(m: Mechanism, driver: float, q0: list[float]) -> tuple[list[list[float]], str]:
    """The real roots of the loop equations near a singular point q0, and what was found:
    "roots", "double" (one root where two meet, to rounding), "continuum" (the loops close
    all along a curve: not isolated) or "none".

    Lyapunov-Schmidt: with J(q0) = U S V^T, v its null direction and u its left null
    vector, every q near q0 is q0 + s v + W y (W the other directions); for each s the
    n - 1 equations P Phi = 0 (P the other left directions) fix y by Newton, and the roots
    are where the one equation left, g(s) = u . Phi, vanishes. Two assemblies that meet
    at a limit or cross at a change point are the roots of g, a fold or a crossing alike;
    g is scanned on s = +-10^-12 .. 10^-1 (the roots sit about sqrt(gap) apart) and each
    sign change bisected."""
    F, J = m.model.functions(driver)
    size = m.length_scale
    scale = np.array([1.0 if u.kind == "angle" else size for u in m.unknowns])
    base = np.array(q0, dtype=float)
    try:
        U, _, Vt = np.linalg.svd(np.array(J(list(base))) * scale[None, :] / size)
    except np.linalg.LinAlgError:
        return [], "none"
    v, u = Vt[-1], U[:, -1]
    W, P = Vt[:-1].T, U[:, :-1].T

    def at(s: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        for _ in range(30):
            q = base + scale * (s * v + W @ y)
            if len(y) == 0:
                break
            Fq = np.array(F(list(q))) / size
            A = P @ (np.array(J(list(q))) * scale[None, :] / size) @ W
            try:
                dy = np.linalg.solve(A, P @ Fq)
            except np.linalg.LinAlgError:
                break
            y = y - dy
            if np.abs(dy).max() <= 1e-16:
                break
        q = base + scale * (s * v + W @ y)
        return q, y, float(u @ np.array(F(list(q)))) / size

    grid = np.logspace(-12, -1, 45)
    ss = np.concatenate([-grid[::-1], [0.0], grid])
    ys, gs, qs = [], [], []
    y = np.zeros(len(base) - 1)
    for s in ss[len(grid)::-1]:  # from 0 outwards, each start the last solution
        q, y, g = at(float(s), y)
        ys.append(y), gs.append(g), qs.append(q)
    ys, gs, qs = ys[::-1], gs[::-1], qs[::-1]
    y = ys[-1]
    for s in ss[len(grid) + 1:]:
        q, y, g = at(float(s), y)
        ys.append(y), gs.append(g), qs.append(q)
    g_arr = np.array(gs)
    far = np.abs(ss) >= 1e-3
    if np.all(np.abs(g_arr[far]) <= 1e-14):  # the loops close all along the curve, far out too
        return [list(qs[len(grid)])], "continuum"
    roots: list[list[float]] = []
    for k in range(len(ss) - 1):
        if g_arr[k] == 0.0 or g_arr[k] * g_arr[k + 1] < 0:
            lo, hi, glo, yl = ss[k], ss[k + 1], g_arr[k], ys[k]
            q = qs[k]
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                q, ym, gm = at(float(mid), yl)
                if gm == 0.0:
                    break
                if (gm < 0) == (glo < 0):
                    lo, glo, yl = mid, gm, ym
                else:
                    hi = mid
            q, res = _polish(m, driver, list(q))
            if res <= RESIDUAL and not any(same_configuration(q, tuple(o), m, 1e-12) for o in roots):
                roots.append(q)
    if len(roots) > 1:
        # roots closer than their own uncertainty (rounding times the condition of J there)
        # are one double root: at a change point exactly, the two assemblies are one
        Js = np.array(J(roots[0])) * scale[None, :] / size
        blur = 1e-14 * float(np.linalg.cond(Js)) if np.all(np.isfinite(Js)) else np.inf
        if all(same_configuration(a, tuple(b), m, blur) for a in roots for b in roots):
            return [roots[0]], "double"
    if roots:
        return roots, "roots"
    k = int(np.argmin(np.abs(g_arr)))
    q, res = _polish(m, driver, list(qs[k]))
    if abs(g_arr[k]) <= DOUBLE and res <= DOUBLE:
        return [q], "double"
    return [], "none"


def branch_names(m: Mechanism, driver: float, qs: list[list[float]]) -> list[tuple[str, str]]:
    """Each assembly's (branch name, signs) as sweeps and ``--branch`` name them: with a closed
    form, the key of Derivation.named_solutions it is (the mirror image of a rocker-driven
    four-bar is ``open (mirror)``), else its configuration's name; without one, the sign of
    det J."""
    der = m.derivation
    if der.complete:
        from ..problems.derive import Indeterminate, sign_text

        try:
            named = der.named_solutions(driver)
        except Indeterminate:  # the closed form's own degenerate case: names by the configuration
            named = {}
        out = []
        for q in qs:
            key = next((k for k, (_, nq) in named.items() if same_configuration(q, tuple(nq), m, 1e-7)), None)
            try:
                out.append((key or der.name_of(q, driver), sign_text(der.signs_of(q, driver))))
            except (Indeterminate, ZeroDivisionError, ValueError):
                out.append(("indeterminate", ""))
        return out
    _, J = m.model.functions(driver)
    dets = [float(np.linalg.det(np.array(J(q)))) for q in qs]
    return [("det J > 0" if d > 0 else "det J < 0" if d < 0 else "det J = 0", "") for d in dets]


def encode(m: Mechanism, q: list[float] | tuple[float, ...]) -> list[complex]:
    """The polynomial system's variables at q: (e^(i theta), e^(-i theta)) per angle, a
    length over the size."""
    out: list[complex] = []
    for u, v in zip(m.unknowns, q):
        out += [complex(math.cos(v), math.sin(v)), complex(math.cos(v), -math.sin(v))] if u.kind == "angle" \
            else [complex(v / m.length_scale)]
    return out


def decode(m: Mechanism, x: np.ndarray) -> list[float]:
    """The unknowns at the real point nearest x (the system's variables): theta = arg of
    (z + conj(w)) / 2, a length the real part times the size."""
    out = []
    for u, k in zip(m.unknowns, [k for _, k in _variables(m)]):
        if u.kind == "angle":
            e = (complex(x[k]) + complex(x[k + 1]).conjugate()) / 2
            out.append(math.atan2(e.imag, e.real))
        else:
            out.append(float(complex(x[k]).real) * m.length_scale)
    return out


def _joints(m: Mechanism, driver: float, q: list[float]) -> dict[str, tuple[float, float]]:
    """Every named joint and point, by the one placing rule (rates.place: a drawing's fixed
    joints where they were drawn)."""
    from .placing import place

    return {name: (p.real, p.imag) for name, (p, _, _) in place(m.model, q, driver).items()}


def assemblies(m: Mechanism, driver: float | None = None, seed: int = 0) -> Assemblies:
    """Every assembly of ``m`` at ``driver`` (internal units; default the file's value)."""
    d = m.driver.value if driver is None else driver
    system = assembly_system(m, d)
    if len(system.polynomials) != system.n:
        raise InputError(f"{m.source}: {len(system.polynomials)} equations in {system.n} polynomial "
                         "unknowns: the loops do not fix the unknowns (mobility is not 1)")
    sols = solve(system, seed=seed)

    real: list[Assembly] = []
    multiplicity: list[int] = []

    def keep(q: list[float], times: int = 1) -> bool:
        q = [radians(nearest_turn(degrees(u.value), degrees(v))) if u.kind == "angle" else v
             for u, v in zip(m.unknowns, q)]  # angles in the turn of the file's guess
        if any(same_configuration(q, a.q, m) for a in real):
            return False
        residual = max(abs(v) for v in m.model.functions(d)[0](q)) / m.length_scale
        cond = condition(system, np.array(encode(m, q), dtype=complex))
        real.append(Assembly(tuple(q), "", "", residual, cond, not cond <= NEAR_LIMIT, _joints(m, d, q)))
        multiplicity.append(times)
        return True

    nonreal = unresolved = 0
    continuum = False
    clusters: list[tuple[np.ndarray, list[Any]]] = []
    for e in sols.endpoints:
        if e.kind == "finite" and e.x is not None:
            if not e.real:
                nonreal += 1
                continue
            q, residual = _polish(m, d, decode(m, e.x))
            if residual <= RESIDUAL:
                keep(q)
            else:
                unresolved += 1
        elif e.kind == "singular" and e.x is not None:
            for x, members in clusters:
                if np.linalg.norm(x - e.x) <= 1e-5 * max(1.0, float(np.linalg.norm(x))):
                    members.append(e)
                    break
            else:
                clusters.append((e.x, [e]))
    # a singular endpoint is two (or more) roots that meet, or nearly meet (a limit
    # position, a change point): which of them are real is decided on the loops themselves
    for x, members in clusters:
        roots, how = _local_roots(m, d, decode(m, x))
        k = len(members)
        if how == "continuum":
            continuum = True
            unresolved += k
        elif how == "double":
            keep(roots[0], times=k)
        elif how == "roots":
            found = sum(keep(q) for q in roots[:k])
            unresolved += k - found if found < k else 0
        else:
            nonreal += k  # g has no root and does not touch zero: a complex pair past a limit
    named = branch_names(m, d, [list(a.q) for a in real])
    real = [replace(a, branch=n, signs=s) for a, (n, s) in zip(real, named)]
    return Assemblies(m, d, tuple(real), nonreal, sols.count("infinite"), sols.count("failed"), sols,
                      tuple(multiplicity), unresolved, continuum)


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
    from .loading import mechanism_of

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


def same_configuration(a: tuple[float, ...] | list[float], b: tuple[float, ...], m: Mechanism,
                       tol: float = 1e-9) -> bool:
    """Whether two configurations are one, to ``tol`` (rad, or of the mechanism's size)."""
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
