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

This is the model half of code generation (layer 1, beside problems/): straight-line
residual and Jacobian code, no iteration. The loops that run on it are generated from the
stopping rule in :mod:`linkage.iterate` (:mod:`linkage.methods.newton_two` for two
unknowns), from the pieces :func:`model_pieces` returns.
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


Terms = tuple[tuple[tuple[float, float, int, float, int, float], ...], ...]


def model_pieces(terms: Terms, n: int) -> tuple[list[str], list[str], list[str], list[list[str]], list[str]]:
    """The model as source pieces: (driver-only trigonometry lines for ``make(d)``,
    unknown-angle trigonometry lines for each function, Phi's rows, J's rows (one
    expression per entry), dPhi/d(driver)'s rows); expressions read ``q[i]`` and ``d``."""
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
    j_entries = [[total(row.get(c, [])) for c in range(n)] for row in jac]
    return pre, body, f_rows, j_entries, [total(p) for p in dvd]


def source(terms: Terms, n: int) -> str:
    """The factory's source for a model's terms (see :class:`LoopModel`)."""
    pre, body, f_rows, j_entries, v_rows = model_pieces(terms, n)
    j_rows = ["[" + ", ".join(row) + "]" for row in j_entries]
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


def build(terms: Terms, n: int) -> Callable[..., Any]:
    """Compile the factory for a model's terms (see :func:`source`)."""
    namespace: dict[str, Any] = {"_cos": math.cos, "_sin": math.sin, "__builtins__": {}}
    exec(compile(source(terms, n), "<linkage-model>", "exec"), namespace)
    return namespace["make"]  # type: ignore[no-any-return]
