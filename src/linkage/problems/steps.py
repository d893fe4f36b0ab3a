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


# A step's coefficients are sums of its terms. Each step's sums are written out once as
# straight-line text (:func:`coefficients_source`) and compiled into one function, run over
# a namespace's cos and sin (math's on the scalar path, numpy's for its twin): a call loops
# over no terms and calls no ref_value, and performs the operations of summing term by term
# in the same order (tests/test_step_coefficients.py holds the two equal bit for bit).

def _read(ref: Ref, consts: list[Any]) -> str:
    """:func:`ref_value` of ``ref`` as text over the generated function's arguments
    (``params``, ``d``, ``q``); a number becomes a constant of the function."""
    if ref.__class__ is int:
        return "d" if ref == DRIVER else f"q[{int(ref)}]"
    if ref.__class__ is str:
        return f"params[{str(ref)!r}]"
    return _constant(ref, consts)


def _constant(value: Any, consts: list[Any]) -> str:
    consts.append(value)
    return f"c{len(consts) - 1}"


def _sum_text(x: str, y: str, terms: Sequence[Term], kind: str, consts: list[Any]) -> list[str]:
    """The lines that sum ``terms`` into ``x`` and ``y``. ``kind``: ``known`` (sign * length *
    e^(i (angle + offset)), K), ``angle`` (sign * length * e^(i offset): the coefficient of
    e^(i angle)), ``length`` (sign * e^(i offset)) or ``length angle`` (sign * e^(i (angle +
    offset))): the coefficient of a length."""
    out = [f"{x} = {y} = 0.0"]
    for sign, lr, ar, off in terms:
        if kind in ("known", "angle"):
            out.append(f"r = {_constant(sign, consts)} * {_read(lr, consts)}")
        if kind in ("known", "length angle"):
            at = _read(ar, consts)
            out.append(f"t = {at} + {_constant(off, consts)}" if off else f"t = {at}")
        if kind == "known":
            out += [f"{x} = {x} + r * cos(t)", f"{y} = {y} + r * sin(t)"]
        elif kind == "length angle":
            sg = _constant(sign, consts)
            out += [f"{x} = {x} + {sg} * cos(t)", f"{y} = {y} + {sg} * sin(t)"]
        elif off:  # a fixed offset: its cosine and sine are numbers, taken once here
            head = "r" if kind == "angle" else _constant(sign, consts)
            c, s = _constant(math.cos(off), consts), _constant(math.sin(off), consts)
            out += [f"{x} = {x} + {head} * {c}", f"{y} = {y} + {head} * {s}"]
        else:
            out.append(f"{x} = {x} + {'r' if kind == 'angle' else _constant(sign, consts)}")
    return out


CASE_KINDS = {TWO_ANGLES: ("angle", "angle"), ITS_LENGTH: ("angle", "length"),
              OTHER_LENGTH: ("angle", "length angle"), TWO_LENGTHS: ("length angle", "length angle")}
"""The coefficients of each case's two unknowns (:func:`_sum_text`'s kinds): P and Q, P and
D, P and E, or E and F."""


def coefficients_source(step: Step) -> tuple[str, list[Any]]:
    """The text of ``step``'s coefficients function, ``coefficients(params, d, q, cos,
    sin) -> (first, second, K)``, and its constants (``c0``, ``c1``, ... in its namespace):
    K first, then first and second, each summed term by term as written."""
    consts: list[Any] = []
    first_kind, second_kind = CASE_KINDS.get(step.case, CASE_KINDS[TWO_LENGTHS])
    lines = [*_sum_text("kx", "ky", step.known, "known", consts),
             *_sum_text("ax", "ay", step.first, first_kind, consts),
             *_sum_text("bx", "by", step.second, second_kind, consts),
             "return (ax, ay), (bx, by), (kx, ky)"]
    body = "".join(f"\n    {line}" for line in lines)
    return f"def coefficients(params, d, q, cos, sin):{body}\n", consts


_GENERATED: dict[int, tuple[Step, Any]] = {}
"""Each step's compiled coefficients function, by the step's id (the step kept with it, so
an id is never another step's)."""


def _generated(step: Step) -> Any:
    source, consts = coefficients_source(step)
    namespace = {f"c{i}": v for i, v in enumerate(consts)}
    # compiled in each process, never kept: the text is a mechanism's (as a model's loop)
    exec(compile(source, "<linkage-step>", "exec"), namespace)
    if len(_GENERATED) > 4096:  # designs of a scan share their steps: this is a bound, not a cache policy
        _GENERATED.clear()
    _GENERATED[id(step)] = (step, namespace["coefficients"])
    return namespace["coefficients"]


def coefficients(step: Step, params: Mapping[str, Any], d: Any, q: Sequence[Any],
                  xp: Any) -> tuple[tuple[Any, Any], tuple[Any, Any], tuple[Any, Any]]:
    """(first, second, K) of a step at known values (``xp``: math, or numpy for arrays)."""
    got = _GENERATED.get(id(step))
    fn = got[1] if got is not None and got[0] is step else _generated(step)
    return fn(params, d, q, xp.cos, xp.sin)  # type: ignore[no-any-return]


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
