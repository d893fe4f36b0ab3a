"""A closed-form step of a derivation (:mod:`.derive`): its four classical cases, its
coefficients at known values, and its solution, side, margin, open/crossed rule and
transmission angle, each written once with its numpy twin beside it (or over a namespace
``xp``, math or numpy). The cases themselves are :mod:`.dyads`."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from ..records import NamedTuple
from . import assembly, dyads

DRIVER = -2
"""The reference of the driver; an int >= 0 is an unknown, a str a parameter, a float a number."""

Ref = int | str | float
Term = tuple[float, Ref, Ref, float]
"""(sign, length, angle, offset): the vector sign * length * e^(i (angle + offset))."""

TWO_ANGLES = "two angles"
ITS_LENGTH = "an angle and its own length"
OTHER_LENGTH = "an angle and another vector's length"
TWO_LENGTHS = "two lengths"


class FourbarLoop(NamedTuple):
    """A loop of four links of fixed length, one of them ground: the terms (indexes into
    the loop's vectors) of the input, coupler, output and ground, in the loop's order
    with the ground last."""

    loop: int
    input: int
    coupler: int
    output: int
    ground: int


class Step(NamedTuple):
    """One closed-form step: ``unknowns`` from ``loops`` (one loop, or two combined with
    ``weights``), in ``case``. ``known`` sums to K; ``first`` and ``second`` are the
    coefficients of the two unknowns (P and Q, P and D, P and E, or E and F)."""

    case: str
    loops: tuple[int, ...]
    weights: tuple[float, ...]
    unknowns: tuple[int, int]
    known: tuple[Term, ...]
    first: tuple[Term, ...]
    second: tuple[Term, ...]
    word_rule: str = ""  # "fourbar" or "slider": the step's loop has a conventional name
    word_terms: tuple[Term, Term] | None = None  # (coupler, output or slide) for the word

    @property
    def two_way(self) -> bool:
        return self.case != TWO_LENGTHS


def ref_value(ref: Ref, params: Mapping[str, Any], d: Any, q: Sequence[Any]) -> Any:
    if ref.__class__ is int:
        return d if ref == DRIVER else q[ref]  # type: ignore[index]
    if ref.__class__ is str:
        return params[ref]  # type: ignore[index]
    return ref


# The sums of a step's terms, written once over a namespace (math or numpy): the scalar
# path and its numpy twin evaluate the same expressions in the same order.
def _known_sum(terms: Sequence[Term], params: Mapping[str, Any], d: Any, q: Sequence[Any],
               xp: Any) -> tuple[Any, Any]:
    x = y = 0.0
    for sign, lr, ar, off in terms:
        r = sign * ref_value(lr, params, d, q)
        t = ref_value(ar, params, d, q) + off if off else ref_value(ar, params, d, q)
        x = x + r * xp.cos(t)
        y = y + r * xp.sin(t)
    return x, y


def _angle_coefficient(terms: Sequence[Term], params: Mapping[str, Any], d: Any,
                       q: Sequence[Any], xp: Any) -> tuple[Any, Any]:
    """sum sign * length * e^(i offset): the coefficient of e^(i angle)."""
    x = y = 0.0
    for sign, lr, _, off in terms:
        r = sign * ref_value(lr, params, d, q)
        if off:
            x = x + r * math.cos(off)
            y = y + r * math.sin(off)
        else:
            x = x + r
    return x, y


def _length_coefficient(terms: Sequence[Term], params: Mapping[str, Any], d: Any,
                        q: Sequence[Any], xp: Any, with_angle: bool) -> tuple[Any, Any]:
    """sum sign * e^(i (angle + offset)) (``with_angle``) or sign * e^(i offset): the
    coefficient of a length."""
    x = y = 0.0
    for sign, _, ar, off in terms:
        if with_angle:
            t = ref_value(ar, params, d, q) + off if off else ref_value(ar, params, d, q)
            x = x + sign * xp.cos(t)
            y = y + sign * xp.sin(t)
        elif off:
            x = x + sign * math.cos(off)
            y = y + sign * math.sin(off)
        else:
            x = x + sign
    return x, y


def coefficients(step: Step, params: Mapping[str, Any], d: Any, q: Sequence[Any],
                  xp: Any) -> tuple[tuple[Any, Any], tuple[Any, Any], tuple[Any, Any]]:
    """(first, second, K) of a step at known values."""
    k = _known_sum(step.known, params, d, q, xp)
    case = step.case
    if case == TWO_ANGLES:
        return (_angle_coefficient(step.first, params, d, q, xp),
                _angle_coefficient(step.second, params, d, q, xp), k)
    if case == ITS_LENGTH:
        return (_angle_coefficient(step.first, params, d, q, xp),
                _length_coefficient(step.second, params, d, q, xp, False), k)
    if case == OTHER_LENGTH:
        return (_angle_coefficient(step.first, params, d, q, xp),
                _length_coefficient(step.second, params, d, q, xp, True), k)
    return (_length_coefficient(step.first, params, d, q, xp, True),
            _length_coefficient(step.second, params, d, q, xp, True), k)


def is_open(step: Step, params: Mapping[str, Any], d: Any, q: Sequence[Any], xp: Any = math) -> Any:
    """The conventional open/crossed rule of a step's loop at a configuration."""
    assert step.word_terms is not None
    (s2, _, a2, o2), (s3, _, a3, o3) = step.word_terms
    t2 = ref_value(a2, params, d, q) + o2
    t3 = ref_value(a3, params, d, q) + o3
    # the coupler as traversed (sign s2) and the output from its ground pivot, or the
    # slide's direction of growth (-s3)
    return assembly.open_rule(step.word_rule, s2 * -s3, t2, t3, xp)


def is_open_np(step: Step, params: Mapping[str, Any], d: Any, q: Sequence[Any]) -> Any:
    """:func:`is_open` over arrays."""
    import numpy as np

    return is_open(step, params, d, q, np)


def folded_transmission(mu: float, half_turn: float = 180.0) -> float:
    """The transmission angle, the one rule every engine reads: the angle ``mu`` in
    [0, half_turn] between the coupler's direction and the output link's, folded into
    [0, half_turn / 2] - the acute angle between the two links' lines, 90 deg transmitting
    best and 0 a toggle, whichever way the linkage is assembled (Norton, Design of
    Machinery, "the absolute value of the acute angle of the pair of angles at the
    intersection of the two links"; Shigley and Uicker's |90 - mu| criterion reads the
    same). The unfolded angle is theta_output - theta_coupler, in the same tables. Exact:
    half_turn - mu is exact for mu >= half_turn / 2 (Sterbenz); NaN stays NaN."""
    return min(mu, half_turn - mu)


def folded_transmission_np(mu: Any, half_turn: float = 180.0) -> Any:
    """:func:`folded_transmission` over arrays."""
    import numpy as np

    return np.minimum(mu, half_turn - mu)


def fourbar_transmission(view: FourbarLoop, loop: Sequence[Term], params: Mapping[str, Any],
                         d: Any, q: Sequence[Any], xp: Any = math) -> Any:
    """The transmission angle of a four-bar loop (rad, folded into [0, pi/2] by the one rule,
    :func:`folded_transmission`): between the coupler as traversed and the output link
    from its ground pivot."""
    s2, _, a2, o2 = loop[view.coupler]
    s3, _, a3, o3 = loop[view.output]
    t2 = ref_value(a2, params, d, q) + o2 + (0.0 if s2 > 0 else math.pi)
    t3 = ref_value(a3, params, d, q) + o3 + (math.pi if s3 > 0 else 0.0)
    diff = t3 - t2
    if xp is not math:
        return folded_transmission_np(xp.abs(xp.arctan2(xp.sin(diff), xp.cos(diff))), math.pi)
    return folded_transmission(abs(math.atan2(math.sin(diff), math.cos(diff))), math.pi)


def solve_step(case: str, first: Any, second: Any, k: Any, sigma: float) -> tuple[float, float] | None:
    if case == TWO_ANGLES:
        return dyads.two_angles(first, second, k, sigma)
    if case == ITS_LENGTH:
        return dyads.angle_and_its_length(first, second, k, sigma)
    if case == OTHER_LENGTH:
        return dyads.angle_and_other_length(first, second, k, sigma)
    return dyads.two_lengths(first, second, k)


def solve_step_np(case: str, first: Any, second: Any, k: Any, sigma: float) -> tuple[Any, Any, Any]:
    if case == TWO_ANGLES:
        return dyads.two_angles_np(first, second, k, sigma)
    if case == ITS_LENGTH:
        return dyads.angle_and_its_length_np(first, second, k, sigma)
    if case == OTHER_LENGTH:
        return dyads.angle_and_other_length_np(first, second, k, sigma)
    return dyads.two_lengths_np(first, second, k)


def solve_step_margin_np(case: str, first: Any, second: Any, k: Any,
                         sigma: float) -> tuple[Any, Any, Any, Any]:
    """:func:`solve_step_np` and :func:`step_margin_np` of one step in one pass: (a, b, ok,
    margin), the two-circle case's three distances computed once for both."""
    if case == TWO_ANGLES:
        return dyads.two_angles_with_margin_np(first, second, k, sigma)
    return (*solve_step_np(case, first, second, k, sigma), step_margin_np(case, first, second, k))


def step_side(case: str, first: Any, second: Any, k: Any, a: float, b: float) -> float:
    if case == TWO_ANGLES:
        return dyads.two_angles_side(first, k, a)
    if case == ITS_LENGTH:
        return dyads.line_side(dyads.cdiv(first, second), b)
    return dyads.line_side(dyads.cdiv(k, second), b)


def step_side_np(case: str, first: Any, second: Any, k: Any, a: Any, b: Any) -> Any:
    if case == TWO_ANGLES:
        return dyads.two_angles_side_np(first, k, a)
    if case == ITS_LENGTH:
        return dyads.line_side_np(dyads.cdiv(first, second), b)
    return dyads.line_side_np(dyads.cdiv(k, second), b)


def step_margin(case: str, first: Any, second: Any, k: Any) -> float:
    if case == TWO_ANGLES:
        return dyads.two_angles_margin(first, second, k)
    try:
        if case == ITS_LENGTH:
            return dyads.line_circle_margin(dyads.cdiv(first, second),
                                            dyads.norm(*k) / dyads.norm(*second))
        return dyads.line_circle_margin(dyads.cdiv(k, second), dyads.norm(*first) / dyads.norm(*second))
    except ZeroDivisionError:
        return math.nan


def step_margin_np(case: str, first: Any, second: Any, k: Any) -> Any:
    if case == TWO_ANGLES:
        return dyads.two_angles_margin_np(first, second, k)
    norm = dyads.norm_np
    if case == ITS_LENGTH:
        return dyads.line_circle_margin_np(dyads.cdiv(first, second),
                                           norm(k[0], k[1]) / norm(second[0], second[1]))
    return dyads.line_circle_margin_np(dyads.cdiv(k, second),
                                       norm(first[0], first[1]) / norm(second[0], second[1]))
