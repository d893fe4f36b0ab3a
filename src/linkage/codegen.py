"""Mechanism models compiled once into straight-line Python.

A validated loop model (:class:`~linkage.problems.loops.LoopModel`: per loop, terms
``sign * r * e^(i (theta + offset))`` whose length and angle are each a constant, the
driver or an unknown) becomes the source of one *factory*::

    def make(d):                 # d: the driver value (rad or length)
        ...trigonometry of the driver, once per position...
        def F(q): ...            # Phi(q), 2 per loop (x then y)
        def J(q): ...            # dPhi/dq, exact
        def V(q): ...            # dPhi/d(driver), exact
        return F, J, V

Each distinct angle (an unknown, the driver or a constant, plus its offset) has its
cosine and sine computed once per call and shared by every term that uses it;
constant angles are folded at compile time; terms with a constant length and angle
fold into one number per equation. The source is generated from the model's numbers
and indices only, never from user text, and can be printed (:func:`source`,
``LoopModel.source``) to inspect what runs.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from typing import Any

DRIVER = -2
FIXED = -1


def _lit(v: float) -> str:
    return repr(float(v)) if v >= 0.0 else f"({float(v)!r})"


def _angle_key(ai: int, ac: float, off: float) -> tuple[int, float]:
    """Angles are keyed by their source and the constant added to it."""
    return (ai, off) if ai != FIXED else (FIXED, ac + off)


def source(terms: tuple[tuple[tuple[float, float, int, float, int, float], ...], ...], n: int,
           newton: bool = False) -> str:
    """The factory's source for a model's terms (see :class:`LoopModel`); ``newton``:
    instead, for two unknowns, Newton-Raphson at one driver value as one function (see
    :func:`_newton_two`)."""
    angles: dict[tuple[int, float], str] = {}
    pre: list[str] = []   # in make(d): driver-only trigonometry
    body: list[str] = []  # in each function: unknown-angle trigonometry

    def trig(ai: int, ac: float, off: float) -> tuple[str, str]:
        key = _angle_key(ai, ac, off)
        if key in angles:
            name = angles[key]
            return f"c{name}", f"s{name}"
        name = str(len(angles))
        angles[key] = name
        if ai == FIXED:
            pre.append(f"    c{name} = {_lit(math.cos(key[1]))}; s{name} = {_lit(math.sin(key[1]))}")
        elif ai == DRIVER:
            arg = f"d + {_lit(off)}" if off else "d"
            pre.append(f"    c{name} = _cos({arg}); s{name} = _sin({arg})")
        else:
            arg = f"q[{ai}] + {_lit(off)}" if off else f"q[{ai}]"
            body.append(f"        c{name} = _cos({arg}); s{name} = _sin({arg})")
        return f"c{name}", f"s{name}"

    def length(li: int, lc: float) -> str:
        if li == DRIVER:
            return "d"
        if li >= 0:
            return f"q[{li}]"
        return _lit(lc)

    phi: list[tuple[list[str], list[str]]] = []
    jac: list[dict[int, list[str]]] = []   # per equation row: column -> terms
    dvd: list[list[str]] = []              # per equation row: d/d(driver) terms
    for loop in terms:
        fx: list[str] = []
        fy: list[str] = []
        jx: dict[int, list[str]] = {}
        jy: dict[int, list[str]] = {}
        vx: list[str] = []
        vy: list[str] = []
        const_x = const_y = 0.0
        for sign, lc, li, ac, ai, off in loop:
            if li == FIXED and ai == FIXED:
                const_x += sign * lc * math.cos(ac + off)
                const_y += sign * lc * math.sin(ac + off)
                continue
            c, s = trig(ai, ac, off)
            r = length(li, lc)
            k = "" if sign == 1.0 else "-"
            fx.append(f"{k}{r} * {c}")
            fy.append(f"{k}{r} * {s}")
            neg = "-" if sign == 1.0 else ""
            if ai >= 0:  # d/dtheta r e^(i theta) = i r e^(i theta)
                jx.setdefault(ai, []).append(f"{neg}{r} * {s}")
                jy.setdefault(ai, []).append(f"{k}{r} * {c}")
            elif ai == DRIVER:
                vx.append(f"{neg}{r} * {s}")
                vy.append(f"{k}{r} * {c}")
            if li >= 0:  # d/dr r e^(i theta) = e^(i theta)
                jx.setdefault(li, []).append(f"{k}{c}")
                jy.setdefault(li, []).append(f"{k}{s}")
            elif li == DRIVER:
                vx.append(f"{k}{c}")
                vy.append(f"{k}{s}")
        if const_x:
            fx.append(_lit(const_x))
        if const_y:
            fy.append(_lit(const_y))
        phi.append((fx, fy))
        jac += [jx, jy]
        dvd += [vx, vy]

    def total(parts: list[str]) -> str:
        return " + ".join(parts).replace("+ -", "- ") if parts else "0.0"

    f_rows = [total(p) for fx, fy in phi for p in (fx, fy)]
    j_rows = ["[" + ", ".join(total(row.get(c, [])) for c in range(n)) + "]" for row in jac]
    v_rows = [total(p) for p in dvd]
    if newton:
        return _newton_two(pre, body, f_rows, [[total(row.get(c, [])) for c in range(n)] for row in jac],
                           v_rows)
    lines = ["def make(d):", *pre]
    for name, rows in (("F", f_rows), ("J", j_rows), ("V", v_rows)):
        lines.append(f"    def {name}(q):")
        text = " ".join(rows)
        # only the trigonometry this function reads
        lines.extend(b for b in body if re.search(rf"\b{b.split()[0]}\b", text)
                     or re.search(rf"\bs{b.split()[0][1:]}\b", text))
        lines.append("        return [")
        lines.extend(f"            {row}," for row in rows)
        lines.append("        ]")
    lines.append("    return F, J, V")
    return "\n".join(lines) + "\n"


def build(terms: Any, n: int, newton: bool = False) -> Callable[..., Any]:
    """Compile the factory for a model's terms, or its Newton function (see :func:`source`)."""
    namespace: dict[str, Any] = {"_cos": math.cos, "_sin": math.sin, "__builtins__": {}}
    if newton:  # the stopping rules' constants, from where the other loops read them
        from .iterate import DIVERGE_STREAK, ROUNDING, RUNAWAY, rounding_stall
        from .methods.newton_system import SINGULAR_RATIO

        namespace.update(__builtins__={"range": range}, _nan=math.nan, _inf=math.inf, _stall=rounding_stall,
                         _RUNAWAY=RUNAWAY, _SINGULAR=SINGULAR_RATIO, _DIVERGE=DIVERGE_STREAK,
                         _ROUNDING=ROUNDING)
    exec(compile(source(terms, n, newton), "<linkage-model>", "exec"), namespace)
    return namespace["newton2" if newton else "make"]  # type: ignore[no-any-return]


# The convergence test below, "err <= tol and resid <= gate", is
# linkage.rules.system_converged written in (the hottest loop; no call per iteration):
# tests/test_compile.py holds this Newton equal, bit for bit, to
# methods.newton_system.newton_2x2, which calls the rule.
_NEWTON_TWO = """\
def newton2(d, x0, x1, tol, gate, max_iter):
    # Newton-Raphson on the loop equations at driver value d from (x0, x1), with damping
    # off and recording off: the stopping rules of linkage.iterate as
    # methods.newton_system.newton_2x2 applies them (the same operations in the same
    # order). Returns (iterations, x0, x1, J row by row, dPhi/dv) at a root whose
    # max|Phi| is within gate; None for any other outcome, which the caller hands to the
    # full solver. |v| is written "v if v >= 0.0 else -v" (no call; NaN stays NaN).
{pre}
{point4}
    prev_err = err = _inf
    growth = stalls = rounding_steps = 0
    a0 = x0 if x0 >= 0.0 else -x0
    a1 = x1 if x1 >= 0.0 else -x1
    runaway = _RUNAWAY * (1.0 + (_nan if a0 != a0 or a1 != a1 else (a0 if a0 >= a1 else a1)))
    for k in range(1, max_iter + 1):
        a0 = p0 if p0 >= 0.0 else -p0
        a1 = p1 if p1 >= 0.0 else -p1
        resid = (a0 if a0 >= a1 else a1) if a0 == a0 and a1 == a1 else _nan
        ad = j00 * j11
        bc = j01 * j10
        det = ad - bc
        size = (ad if ad >= 0.0 else -ad) + (bc if bc >= 0.0 else -bc)
        if not (size > 0.0 and (det if det >= 0.0 else -det) > _SINGULAR * size and det - det == 0.0):
            return None
        h0 = (j01 * p1 - j11 * p0) / det
        h1 = (j10 * p0 - j00 * p1) / det
        x0 = x0 + h0
        x1 = x1 + h1
{point8}
        e0 = h0 if h0 >= 0.0 else -h0
        e1 = h1 if h1 >= 0.0 else -h1
        err = (e0 if e0 >= e1 else e1) if e0 == e0 and e1 == e1 else _nan
        if not (err - err == 0.0 and resid - resid == 0.0):
            return None
        if resid == 0.0 or (err <= tol and resid <= gate):
            break
        e0 = x0 if x0 >= 0.0 else -x0
        e1 = x1 if x1 >= 0.0 else -x1
        size_q = _nan if e0 != e0 or e1 != e1 else (e0 if e0 >= e1 else e1)
        growth = growth + 1 if err > prev_err else 0
        if growth >= _DIVERGE and size_q > runaway:
            return None
        if err <= _ROUNDING * size_q:
            why, rounding_steps, stalls = _stall(err, prev_err, tol, rounding_steps, stalls)
            if why is not None:
                return None
        prev_err = err
    else:
        return None
    if not ((p0 if p0 >= 0.0 else -p0) <= gate and (p1 if p1 >= 0.0 else -p1) <= gate):
        return None
{velocity}
    return k, x0, x1, j00, j01, j10, j11, w0, w1
"""


def _newton_two(pre: list[str], body: list[str], f_rows: list[str], j_rows: list[list[str]],
                v_rows: list[str]) -> str:
    """Newton for two unknowns with the model's Phi and J written in where it evaluates
    them (each angle's trigonometry once per iterate), and dPhi/dv at the root (for the
    continuation's next tangent)."""
    def at(text: str) -> str:
        return re.sub(r"q\[(\d+)\]", r"x\1", text)

    values = [("p0", f_rows[0]), ("p1", f_rows[1]), ("j00", j_rows[0][0]), ("j01", j_rows[0][1]),
              ("j10", j_rows[1][0]), ("j11", j_rows[1][1])]
    point = [at(b.strip()) for b in body] + [f"{name} = {at(e)}" for name, e in values]
    velocity = [f"w{i} = {at(e)}" for i, e in enumerate(v_rows)]
    return _NEWTON_TWO.format(pre="\n".join(pre), point4="\n".join("    " + x for x in point),
                              point8="\n".join("        " + x for x in point),
                              velocity="\n".join("    " + x for x in velocity))
