"""Newton-Raphson at one driver value for a compiled model of two unknowns, with the
model's Phi and J written in where the loop evaluates them (each angle's trigonometry
once per iterate), generated from the stopping rule of :mod:`linkage.iterate` around the
model's source pieces (:func:`linkage.codegen.model_pieces`).

``newton_two_of(model)(d, x0, x1, tol, gate, max_iter)`` returns (iterations, x0, x1, J
row by row, dPhi/dv) at a root whose max|Phi| is within ``gate``, with damping and
recording off and the whole step always taken; ``None`` for any other outcome, which the
caller hands to the full solver. The same operations in the same order as
:func:`~linkage.methods.newton_system.newton_2x2`, so the same iterates wherever this
returns (tests/test_compile.py). |v| is written ``v if v >= 0.0 else -v`` (no call; NaN
stays NaN).
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable
from typing import Any

from ..codegen import Terms, model_pieces
from ..iterate import Loop, build_loop
from ..rules import invertible_source
from .newton_system import larger_of


def _at(text: str) -> str:
    return re.sub(r"q\[(\d+)\]", r"x\1", text)


def newton_two_loop(terms: Terms, n: int) -> Loop:
    """The loop for a model's terms (two unknowns)."""
    pre, body, f_rows, j_rows, v_rows = model_pieces(terms, n)
    values = [("p0", f_rows[0]), ("p1", f_rows[1]), ("j00", j_rows[0][0]), ("j01", j_rows[0][1]),
              ("j10", j_rows[1][0]), ("j11", j_rows[1][1])]
    point = "\n".join([_at(b.strip()) for b in body] + [f"{name} = {_at(e)}" for name, e in values])
    velocity = "\n".join(f"w{i} = {_at(e)}" for i, e in enumerate(v_rows))
    return Loop(
        signature="newton2(d, x0, x1, tol, gate, max_iter)",
        setup="\n".join(line.strip() for line in pre) + "\n" + point + """
err = fx = _inf
a0 = x0 if x0 >= 0.0 else -x0
a1 = x1 if x1 >= 0.0 else -x1
runaway = _RUNAWAY * (1.0 + """ + larger_of("a0", "a1") + """)
""",
        step="""\
a0 = p0 if p0 >= 0.0 else -p0
a1 = p1 if p1 >= 0.0 else -p1
fx = """ + larger_of("a0", "a1") + """
ad = j00 * j11
bc = j01 * j10
det = ad - bc
if not """ + invertible_source("det", "(ad if ad >= 0.0 else -ad) + (bc if bc >= 0.0 else -bc)") + """:
    return None
h0 = (j01 * p1 - j11 * p0) / det
h1 = (j10 * p0 - j00 * p1) / det
x0 = x0 + h0
x1 = x1 + h1
""" + point + "\n",
        after="""\
e0 = h0 if h0 >= 0.0 else -h0
e1 = h1 if h1 >= 0.0 else -h1
err = """ + larger_of("e0", "e1") + """
e0 = x0 if x0 >= 0.0 else -x0
e1 = x1 if x1 >= 0.0 else -x1
size_q = """ + larger_of("e0", "e1") + """
""",
        tail="""\
if status is _S.MAX_ITER:
    return None
if not ((p0 if p0 >= 0.0 else -p0) <= gate and (p1 if p1 >= 0.0 else -p1) <= gate):
    return None
""" + velocity + """
return k, x0, x1, j00, j01, j10, j11, w0, w1
""",
        residual_test=False, step_test="system", diverge="runaway", magnitude="size_q", limit="tol",
        failure="return None")


@functools.lru_cache(maxsize=64)
def compiled_newton_two(terms: Terms, n: int) -> Callable[..., Any]:
    """The compiled loop for a model's terms (once per model per process)."""
    return build_loop(newton_two_loop(terms, n), {"_cos": math.cos, "_sin": math.sin})


def newton_two_of(model: Any) -> Callable[..., Any]:
    """``newton2`` for a :class:`~linkage.problems.loops.LoopModel` of two unknowns."""
    return compiled_newton_two(model.terms, model.n)
