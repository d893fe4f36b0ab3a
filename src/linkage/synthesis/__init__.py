"""Function generation: the student report's equation run backwards (Freudenstein's synthesis).

The seed solves R1 cos(alpha) - R2 cos(phi) + R3 - cos(alpha - phi) = 0 for phi given the
constants. Here the constants are the unknowns: a function y = f(x) over LO..HI is mapped
linearly onto the input angle alpha (LO -> A0, HI -> A1) and the output angle phi
(f(LO) -> P0, f(HI) -> P1), both in the student report's convention (alpha at O2, phi at O4, from
the line O4 -> O2), and at each precision point the equation is linear in (R1, R2, R3).
Three points give a 3x3 system; more a least-squares fit by orthogonal factorisation.

The linkage found is then analysed as a user's would be: the input-output equation is
followed with continuation (kinematics.equation_sweep, the four-bar equation's own solver) over the
whole x range on the branch through the first precision point, and its output compared
with the function asked for (the structural error). Defects are named, never hidden.

The rules live here once, each with its numpy twin where the search (many candidates at
a time) needs one: the precision points (:func:`precision_xs`), the linear system
(:func:`solve_coefficients`, :func:`solve_coefficients_np`), the linkage of a solution
(:func:`linkage_of`), the branch's closed form (freudenstein.branch_root and its twin) and
whether a precision point is off the followed branch (:func:`off_branch` and its twin).

The package, by what it does: :mod:`.request` (the request checked), :mod:`.solve` (the
linear system and the rules, each with its numpy twin), :mod:`.error_curve`,
:mod:`.defects`, :mod:`.function` (one design), :mod:`.remez` (optimal spacing),
:mod:`.search` (many candidates at once) and :mod:`.burmester` (motion generation's points).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from typing import Any

from ..errors import InputError
from .function import FunctionSynthesis, synthesize_at
from .remez import optimal
from .request import MIN_TRANSMISSION_DEG, TABLE_POINTS, Request, make_request
from .search import SearchResult, search
from .solve import precision_xs

__all__ = ["FunctionSynthesis", "SearchResult", "search", "synthesize", "synthesize_function"]


def synthesize(req: Request) -> FunctionSynthesis:
    """Synthesise, analyse and judge one function generator."""
    if req.spacing == "optimal":
        return optimal(req)
    return synthesize_at(req, precision_xs(req))



def synthesize_function(
    f: str | Callable[[float], float],
    x_range: Any,
    alpha_range: Any,
    phi_range: Any,
    points: int = 3,
    spacing: str = "chebyshev",
    *,
    at: Sequence[float] | None = None,
    ground: float = 1.0,
    min_transmission: float = MIN_TRANSMISSION_DEG,
    samples: int = TABLE_POINTS,
) -> FunctionSynthesis:
    """A four-bar function generator for y = f(x) over ``x_range``, x mapped onto the input
    angle ``alpha_range`` and y onto the output angle ``phi_range`` (degrees, the student report's
    convention), by Freudenstein's equation at ``points`` precision points spaced by
    ``spacing`` (chebyshev, uniform or optimal) or placed ``at``; analysed over the range
    with the four-bar equation's solver. ``f``: an expression in x (as ``--function``) or a callable."""
    try:
        req = make_request(f, x_range, alpha_range, phi_range, points=points, spacing=spacing, at=at,
                           ground=ground, min_transmission=min_transmission, table_points=samples)
    except InputError as exc:  # the messages name the command's options: here the arguments
        raise InputError(API_NAMES.sub(lambda m: API_ARGUMENTS[m.group(0)], str(exc))) from None
    return synthesize(req)


API_ARGUMENTS = {"--x": "x_range", "--alpha": "alpha_range", "--phi": "phi_range", "--points": "points",
                 "--spacing": "spacing", "--at": "at", "--ground": "ground",
                 "--min-transmission": "min_transmission", "--samples": "samples", "--rows": "samples",
                 "--function": "f"}
API_NAMES = re.compile("|".join(sorted(map(re.escape, API_ARGUMENTS), key=len, reverse=True)) + r"(?![\w-])")
