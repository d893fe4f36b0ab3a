"""Closed forms derived from the loops: the textbook's stepwise method.

"Usually such a solution can be found if in each loop closure equation there are two
unknowns" (the textbook section behind our system solver). After substituting what is
known (parameters, the driver, unknowns already solved) we look for a loop with exactly
two unknowns in one of the four classical cases (:mod:`.dyads`), solve it, and repeat
loop by loop. When no single loop has two, the sum or difference of two loops may (the
vectors they share cancel). What remains when nothing has two is coupled and stays with
Newton-Raphson, and :attr:`Derivation.summary` says so.

Each two-way step (two circles, a line and a circle) has a choice, its sign sigma; a
configuration's branch is the tuple of those signs, written ``+-`` (one character per
two-way step). Where a name is conventional it is named in words (:func:`Derivation.name_of`):
a loop that is a four-bar (four links of fixed length, one of them ground) is ``open``
where the output link turns anticlockwise from the coupler (sin(theta_out - theta_coupler)
> 0, worked example P3, docs/worked_examples.md) and ``crossed`` otherwise, read with the loop as
written and its
ground last: input, coupler, output. That is a property of the configuration, so it is the
same whichever joint drives. A slider-crank loop is open where the coupler points the way
the slide grows.

Everything here is symbolic until evaluated: the scalar path (:meth:`Derivation.solve`)
and its numpy twin (:meth:`Derivation.solve_np`) share the term sums below and call the
cases of :mod:`.dyads`, scalar and numpy side by side. Parameters are read by name at
evaluation, so one derivation serves every design of a scan.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

from . import dyads
from .assembly import TANGENT_SLACK

DRIVER = -2
"""The reference of the driver; an int >= 0 is an unknown, a str a parameter, a float a number."""

Ref = int | str | float
Term = tuple[float, Ref, Ref, float]
"""(sign, length, angle, offset): the vector sign * length * e^(i (angle + offset))."""

TWO_ANGLES = "two angles"
ITS_LENGTH = "an angle and its own length"
OTHER_LENGTH = "an angle and another vector's length"
TWO_LENGTHS = "two lengths"


class Indeterminate(ValueError):
    """A step whose known vectors leave every value of an unknown a solution (coincident
    circles, parallel slides): a change point, not a position."""


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


def _val(ref: Ref, params: Mapping[str, Any], d: Any, q: Sequence[Any]) -> Any:
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
        r = sign * _val(lr, params, d, q)
        t = _val(ar, params, d, q) + off if off else _val(ar, params, d, q)
        x = x + r * xp.cos(t)
        y = y + r * xp.sin(t)
    return x, y


def _angle_coefficient(terms: Sequence[Term], params: Mapping[str, Any], d: Any,
                       q: Sequence[Any], xp: Any) -> tuple[Any, Any]:
    """sum sign * length * e^(i offset): the coefficient of e^(i angle)."""
    x = y = 0.0
    for sign, lr, _, off in terms:
        r = sign * _val(lr, params, d, q)
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
            t = _val(ar, params, d, q) + off if off else _val(ar, params, d, q)
            x = x + sign * xp.cos(t)
            y = y + sign * xp.sin(t)
        elif off:
            x = x + sign * math.cos(off)
            y = y + sign * math.sin(off)
        else:
            x = x + sign
    return x, y


def _coefficients(step: Step, params: Mapping[str, Any], d: Any, q: Sequence[Any],
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


class Derivation(NamedTuple):
    """The stepwise closed form of a mechanism's loops, or why there is none.

    (FourbarLoop, Step, Derivation and BranchText are NamedTuples, not frozen dataclasses:
    built at import, a frozen dataclass costs 1.6 ms against 0.2 ms, and every mechanism
    command's start pays for it.)"""

    steps: tuple[Step, ...]
    n: int
    names: tuple[str, ...]  # the unknowns
    loop_names: tuple[str, ...]
    coupled: tuple[tuple[int, int], ...] = ()  # (loop, unknowns left) that no step solved
    fourbars: tuple[FourbarLoop, ...] = ()
    params: Mapping[str, float] | None = None  # the mechanism's parameter values (internal units)
    loops: tuple[tuple[Term, ...], ...] = ()  # every loop's terms (loop_terms)

    @property
    def complete(self) -> bool:
        """Every unknown has a closed form."""
        return not self.coupled and sum(2 for _ in self.steps) == self.n

    @property
    def two_way(self) -> tuple[int, ...]:
        """The indexes of the steps with a choice of sign."""
        return tuple(i for i, s in enumerate(self.steps) if s.two_way)

    @property
    def branches(self) -> tuple[tuple[float, ...], ...]:
        """Every sign tuple, ``+`` before ``-`` in each place."""
        return tuple(itertools.product((1.0, -1.0), repeat=len(self.two_way)))

    @property
    def summary(self) -> str:
        """One line for ``solve``'s header: which loops are closed-form and which coupled."""
        def where(step: Step) -> str:
            return "+".join(str(i + 1) for i in step.loops)

        solved = [where(s) for s in self.steps]
        head = ""
        if solved:
            head = f"loop{'s' if len(solved) > 1 else ''} {', '.join(solved)}"
            if len(solved) > 1:
                head += " (stepwise)"
        if self.complete:
            return f"closed form: {head}"
        if head:
            return f"closed form: {head}; no closed form for the rest: {self.coupled_text}"
        return f"no closed form: {self.coupled_text}"

    @property
    def coupled_text(self) -> str:
        """What no step solves, and why: "loop 1 has 3 unknowns, loop 2 has 3 unknowns
        (coupled)"; "" when every unknown has a closed form."""
        if self.complete:
            return ""
        left = ", ".join(f"loop {i + 1} has {k} unknown{'s' if k != 1 else ''}"
                         for i, k in self.coupled)
        return f"{left} (coupled)"

    def branch_refusal(self, source: str) -> str | None:
        """Why ``--branch`` cannot choose an assembly of this mechanism (None: it can)."""
        if not self.complete:
            return f"--branch needs a closed form; {source} has none: {self.coupled_text}"
        if not self.two_way:
            return f"--branch has nothing to choose: {source} has one assembly (its closed form is linear)"
        return None

    def _params(self, params: Mapping[str, Any] | None) -> Mapping[str, Any]:
        return self.params if params is None else params  # type: ignore[return-value]

    # --- the scalar path -------------------------------------------------------------------
    def solve(self, driver: float, signs: Sequence[float],
              params: Mapping[str, float] | None = None) -> list[float] | None:
        """The unknowns (internal units, the mechanism's order) on the branch ``signs``,
        or None where it cannot be assembled. Raises :class:`Indeterminate` at a change
        point."""
        p = self._params(params)
        q: list[float] = [math.nan] * self.n
        signs_left = iter(signs)
        for step in self.steps:
            sigma = next(signs_left) if step.two_way else 0.0
            first, second, k = _coefficients(step, p, driver, q, math)
            try:
                got = _solve_step(step.case, first, second, k, sigma)
            except ZeroDivisionError as exc:
                raise Indeterminate(f"loop {'+'.join(str(i + 1) for i in step.loops)}: {exc}") from None
            if got is None:
                return None
            q[step.unknowns[0]], q[step.unknowns[1]] = got
        return q

    def solutions(self, driver: float, params: Mapping[str, float] | None = None
                  ) -> list[tuple[tuple[float, ...], list[float]]]:
        """Every assembly at a driver value: (signs, unknowns), distinct configurations only
        (at a limit the two signs of a step give one), in :attr:`branches` order."""
        out: list[tuple[tuple[float, ...], list[float]]] = []
        for signs in self.branches:
            q = self.solve(driver, signs, params)
            if q is not None and not any(q == other for _, other in out):
                out.append((signs, q))
        return out

    def signs_of(self, q: Sequence[float], driver: float,
                 params: Mapping[str, float] | None = None) -> tuple[float, ...]:
        """The branch of a configuration (solved by any means): each two-way step's sign
        (0 exactly at its limit)."""
        p = self._params(params)
        out = []
        for step in self.steps:
            if not step.two_way:
                continue
            first, second, k = _coefficients(step, p, driver, q, math)
            out.append(_side(step.case, first, second, k, q[step.unknowns[0]], q[step.unknowns[1]]))
        return tuple(out)

    def meets(self, q: Sequence[float], driver: float,
              params: Mapping[str, float] | None = None) -> tuple[bool, ...]:
        """Whether each two-way step's two assemblies meet at a configuration, to rounding:
        its margin within :data:`~.assembly.TANGENT_SLACK` of zero (a limit position, or a
        four-bar's change point, s + l = p + q, where all four joints are collinear). There
        the step's sign and its open/crossed word are a matter of rounding: the one
        configuration is on both branches (Norton, Design of Machinery, section 2.8)."""
        p = self._params(params)
        out = []
        for step in self.steps:
            if step.two_way:
                first, second, k = _coefficients(step, p, driver, q, math)
                out.append(abs(_margin(step.case, first, second, k)) <= TANGENT_SLACK)
        return tuple(out)

    def meets_np(self, q: Sequence[Any], driver: Any, params: Mapping[str, Any] | None = None) -> list[Any]:
        """:meth:`meets` over arrays (NaN: False)."""
        import numpy as np

        p = self._params(params)
        out = []
        with np.errstate(invalid="ignore", divide="ignore"):
            for step in self.steps:
                if step.two_way:
                    first, second, k = _coefficients(step, p, np.asarray(driver, float), q, np)
                    out.append(np.abs(_margin_np(step.case, first, second, k)) <= TANGENT_SLACK)
        return out

    def on_branch(self, q: Sequence[float], driver: float, want: BranchText,
                  params: Mapping[str, float] | None = None) -> bool:
        """Whether a configuration is on the branch ``want`` (:func:`read_branch`): each
        two-way step on its sign (0, on the line, counts as either) or its word, except
        where the step's assemblies meet (:meth:`meets`), which is on either. Which of two
        assemblies of one name (a mirror) a position is on is the continuity test's to
        decide. The one rule of every engine; :meth:`on_branch_np` is its twin."""
        meets = self.meets(q, driver, params)
        if want.signs is not None:
            sides = self.signs_of(q, driver, params)
            return all(s == w or s == 0.0 or m for s, w, m in zip(sides, want.signs, meets))
        words = self.words_of(q, driver, params)
        return all((w in ("open", "+")) == wanted or m for w, wanted, m in zip(words, want.words, meets))

    def on_branch_np(self, q: Sequence[Any], driver: Any, want: BranchText,
                     params: Mapping[str, Any] | None = None) -> Any:
        """:meth:`on_branch` over arrays."""
        import numpy as np

        meets = self.meets_np(q, driver, params)
        ok: Any = True
        with np.errstate(invalid="ignore"):
            if want.signs is not None:
                for side, sign, m in zip(self.signs_of_np(q, driver, params), want.signs, meets):
                    ok = ok & ((side == sign) | (side == 0.0) | m)
            else:
                for word, wanted, m in zip(self.words_of_np(q, driver, params), want.words, meets):
                    ok = ok & ((word == wanted) | m)
        return ok

    def margins(self, driver: float, signs: Sequence[float],
                params: Mapping[str, float] | None = None) -> list[float]:
        """Each two-way step's margin on branch ``signs`` (relative; negative where it
        does not assemble, NaN after the first that does not)."""
        p = self._params(params)
        q: list[float] = [math.nan] * self.n
        out: list[float] = []
        signs_left = iter(signs)
        for step in self.steps:
            sigma = next(signs_left) if step.two_way else 0.0
            first, second, k = _coefficients(step, p, driver, q, math)
            if step.two_way:
                out.append(_margin(step.case, first, second, k))
            try:
                got = _solve_step(step.case, first, second, k, sigma)
            except ZeroDivisionError:
                got = None
            if got is None:
                out += [math.nan] * (len(self.two_way) - len(out))
                return out
            q[step.unknowns[0]], q[step.unknowns[1]] = got
        return out

    # --- the numpy twin --------------------------------------------------------------------
    def solve_np(self, driver: Any, signs: Sequence[float],
                 params: Mapping[str, Any] | None = None) -> tuple[list[Any], Any]:
        """:meth:`solve` over arrays (drivers and, for a scan, parameters broadcast
        together): (unknowns, ok); NaN where ``ok`` is False."""
        q, ok, _ = self.solve_margins_np(driver, signs, params)
        return q, ok

    def solve_margins_np(self, driver: Any, signs: Sequence[float],
                         params: Mapping[str, Any] | None = None) -> tuple[list[Any], Any, list[Any]]:
        """:meth:`solve_np` and :meth:`margins_np` in one pass (a sweep needs both):
        (unknowns, ok, margins)."""
        import numpy as np

        p = self._params(params)
        d = np.asarray(driver, float)
        q: list[Any] = [None] * self.n
        ok = np.ones(np.broadcast_shapes(d.shape, *(np.shape(v) for v in p.values())), bool)
        out = []
        signs_left = iter(signs)
        with np.errstate(invalid="ignore", divide="ignore"):
            for step in self.steps:
                sigma = next(signs_left) if step.two_way else 0.0
                first, second, k = _coefficients(step, p, d, q, np)
                if step.two_way:
                    out.append(_margin_np(step.case, first, second, k))
                a, b, fine = _solve_step_np(step.case, first, second, k, sigma)
                ok = ok & fine
                q[step.unknowns[0]], q[step.unknowns[1]] = a, b
        shape = ok.shape
        # a step the driver does not reach (two loops whose difference drops it) has one
        # margin for every driver: give it the drivers' shape like the other columns
        return ([np.where(ok, np.broadcast_to(x, shape), np.nan) for x in q], ok,
                [np.broadcast_to(x, shape).copy() for x in out])

    def signs_of_np(self, q: Sequence[Any], driver: Any,
                    params: Mapping[str, Any] | None = None) -> list[Any]:
        """:meth:`signs_of` over arrays."""
        import numpy as np

        p = self._params(params)
        out = []
        with np.errstate(invalid="ignore", divide="ignore"):
            for step in self.steps:
                if step.two_way:
                    first, second, k = _coefficients(step, p, np.asarray(driver, float), q, np)
                    out.append(_side_np(step.case, first, second, k, q[step.unknowns[0]],
                                        q[step.unknowns[1]]))
        return out

    def margins_np(self, driver: Any, signs: Sequence[float],
                   params: Mapping[str, Any] | None = None) -> list[Any]:
        """:meth:`margins` over arrays."""
        return self.solve_margins_np(driver, signs, params)[2]

    def transmission(self, q: Sequence[float], driver: float,
                     params: Mapping[str, float] | None = None) -> float | None:
        """The transmission angle of a configuration (rad, folded into [0, pi/2]): of its
        four-bar loop, or with several the one farthest from pi/2 (the loop that transmits
        worst); None with no four-bar loop."""
        p = self._params(params)
        worst = None
        for view in self.fourbars:
            mu = fourbar_transmission(view, self.loops[view.loop], p, driver, q)
            if worst is None or abs(mu - 0.5 * math.pi) > abs(worst - 0.5 * math.pi):
                worst = mu
        return worst

    def transmission_np(self, q: Sequence[Any], driver: Any,
                        params: Mapping[str, Any] | None = None) -> Any:
        """:meth:`transmission` over arrays (None with no four-bar loop)."""
        import numpy as np

        p = self._params(params)
        worst = None
        for view in self.fourbars:
            mu = fourbar_transmission(view, self.loops[view.loop], p, driver, q, np)
            worst = mu if worst is None else np.where(
                np.abs(mu - 0.5 * math.pi) > np.abs(worst - 0.5 * math.pi), mu, worst)
        return worst

    # --- names -----------------------------------------------------------------------------
    def words_of(self, q: Sequence[float], driver: float,
                 params: Mapping[str, float] | None = None) -> list[str]:
        """Each two-way step's name for a configuration: open/crossed for a four-bar or
        slider-crank loop, its sign (+ or -) otherwise."""
        p = self._params(params)
        out = []
        for step in self.steps:
            if not step.two_way:
                continue
            if step.word_rule:
                out.append("open" if _is_open(step, p, driver, q) else "crossed")
            else:  # the sign, computed only here: a sweep names every position
                first, second, k = _coefficients(step, p, driver, q, math)
                sigma = _side(step.case, first, second, k, q[step.unknowns[0]], q[step.unknowns[1]])
                out.append("+" if sigma >= 0.0 else "-")
        return out

    def words_of_np(self, q: Sequence[Any], d: Any, params: Mapping[str, Any] | None = None) -> list[Any]:
        """:meth:`words_of` over arrays: each two-way step's word as a bool, True for open
        (a four-bar or slider-crank loop) or + (the step's sign, 0 counting as +)."""
        p = self._params(params)
        sides = iter(self.signs_of_np(q, d, p))
        out = []
        for step in self.steps:
            if not step.two_way:
                continue
            side = next(sides)
            out.append(is_open_np(step, p, d, q) if step.word_rule else side >= 0.0)
        return out

    @property
    def names_are_signs(self) -> bool:
        """Whether each branch name is one sign branch, whatever the design and the driver
        value: every two-way step's word is a function of its sign alone (a four-bar step
        that solves the coupler and the output, whose open/crossed is the side of the
        coupler from the diagonal; a slider step; a step named by its sign). Not so for a
        four-bar driven by its rocker or coupler: its step solves two other links, and open
        and crossed cut across the signs."""
        for i in self.two_way:
            step = self.steps[i]
            if step.word_rule == "fourbar":
                assert step.word_terms is not None
                if {t[2] for t in step.word_terms} != set(step.unknowns):
                    return False
        return True

    def name_of(self, q: Sequence[float], driver: float,
                params: Mapping[str, float] | None = None) -> str:
        """A configuration's branch name: its steps' words joined by "/"."""
        return "/".join(self.words_of(q, driver, params))

    def named_solutions(self, driver: float, params: Mapping[str, float] | None = None
                        ) -> dict[str, tuple[tuple[float, ...], list[float]]]:
        """Every assembly keyed by its name; a second assembly of one name (the two mirror
        images of a rocker-driven four-bar can both be open) is keyed ``NAME (mirror)``. A
        configuration where a step's assemblies meet (:meth:`meets`: a change point) is on
        both of that step's branches, so it is keyed by the other word there too, where no
        assembly has that name."""
        out: dict[str, tuple[tuple[float, ...], list[float]]] = {}
        sols = self.solutions(driver, params)
        # the mirror key goes to the later in :attr:`branches` order ("+" before "-")
        for signs, q in sols:
            name = self.name_of(q, driver, params)
            key = name
            while key in out:
                key += MIRROR
            out[key] = (signs, q)
        for signs, q in sols:
            names = [self.words_of(q, driver, params)]
            for i, meet in enumerate(self.meets(q, driver, params)):
                if meet:
                    names += [[*w[:i], _OTHER_WORD[w[i]], *w[i + 1:]] for w in names]
            for words in names[1:]:
                out.setdefault("/".join(words), (signs, q))
        return out


    def branch_signs(self, text: str, driver: float,
                     params: Mapping[str, float] | None = None) -> tuple[float, ...]:
        """The branch a ``--branch`` names, as signs: a sign string (``+-``, one character
        per two-way step) or a name at this driver value (``open``, ``open/crossed``,
        ``open (mirror)``). Raises ValueError saying what the choices are."""
        count = len(self.two_way)
        signs = parse_signs(text, count)
        if signs is not None:
            return signs
        named = self.named_solutions(driver, params)
        if text in named:
            return named[text][0]
        where = ", ".join(named) or "none: it cannot be assembled there"
        raise ValueError(f"no {text!r} assembly here (assemblies: {where}; or their signs, one + "
                         f"or - per closed-form step with two roots, e.g. {'+' * count})")


MIRROR = " (mirror)"
_OTHER_WORD = {"open": "crossed", "crossed": "open", "+": "-", "-": "+"}


def sign_text(signs: Sequence[float]) -> str:
    """``+-`` for (1, -1)."""
    return "".join("+" if s >= 0.0 else "-" for s in signs)


def parse_signs(text: str, count: int) -> tuple[float, ...] | None:
    """(1, -1) for ``+-`` when it has ``count`` characters of + and -; else None."""
    if len(text) != count or any(c not in "+-" for c in text):
        return None
    return tuple(1.0 if c == "+" else -1.0 for c in text)


class BranchText(NamedTuple):
    """A ``--branch`` text read against a derivation: the signs themselves (``+-``), or a
    name: one word per two-way step (True for open or +) and how many ``(mirror)``
    suffixes it carries (the second assembly of one name at a driver value)."""

    signs: tuple[float, ...] | None
    words: tuple[bool, ...] = ()
    mirrors: int = 0


def read_branch(der: Derivation, text: str) -> BranchText:
    """What a ``--branch`` text asks of this derivation (:meth:`Derivation.branch_signs`
    reads the same texts); a ValueError saying what the choices are otherwise."""
    count = len(der.two_way)
    signs = parse_signs(text, count)
    if signs is not None:
        return BranchText(signs)
    base, mirrors = text, 0
    while base.endswith(MIRROR):
        base, mirrors = base[: -len(MIRROR)], mirrors + 1
    parts = base.split("/") if count else []
    choices = [("open", "crossed") if der.steps[i].word_rule else ("+", "-") for i in der.two_way]
    if len(parts) != count or any(w not in c for w, c in zip(parts, choices)):
        example = "/".join(a for a, _ in choices)
        if count == 1:
            named = f"{choices[0][0]} or {choices[0][1]}"
        else:
            named = (f"a name, one word per two-way step joined by / "
                     f"({' / '.join(f'{a} or {b}' for a, b in choices)}, e.g. {example})")
        raise ValueError(f"{text!r} is not a branch of this mechanism: give {named}, or the signs "
                         f"of its {count} two-way step{'s' if count != 1 else ''} (e.g. {'+' * count}); "
                         f"a second assembly of one name is NAME{MIRROR}")
    return BranchText(None, tuple(w in ("open", "+") for w in parts), mirrors)


def _is_open(step: Step, params: Mapping[str, Any], d: Any, q: Sequence[Any], xp: Any = math) -> Any:
    """The conventional open/crossed rule of a step's loop at a configuration."""
    assert step.word_terms is not None
    (s2, _, a2, o2), (s3, _, a3, o3) = step.word_terms
    t2 = _val(a2, params, d, q) + o2
    t3 = _val(a3, params, d, q) + o3
    if step.word_rule == "fourbar":
        # the coupler as traversed (sign s2) and the output from its ground pivot (-s3):
        # open where the output turns anticlockwise from the coupler
        return s2 * -s3 * xp.sin(t3 - t2) > 0.0
    # slider: the coupler as traversed against the slide's direction of growth (-s3)
    return s2 * -s3 * xp.cos(t3 - t2) > 0.0


def is_open_np(step: Step, params: Mapping[str, Any], d: Any, q: Sequence[Any]) -> Any:
    """:func:`_is_open` over arrays."""
    import numpy as np

    return _is_open(step, params, d, q, np)


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
    t2 = _val(a2, params, d, q) + o2 + (0.0 if s2 > 0 else math.pi)
    t3 = _val(a3, params, d, q) + o3 + (math.pi if s3 > 0 else 0.0)
    diff = t3 - t2
    if xp is not math:
        return folded_transmission_np(xp.abs(xp.arctan2(xp.sin(diff), xp.cos(diff))), math.pi)
    return folded_transmission(abs(math.atan2(math.sin(diff), math.cos(diff))), math.pi)


def _solve_step(case: str, first: Any, second: Any, k: Any, sigma: float) -> tuple[float, float] | None:
    if case == TWO_ANGLES:
        return dyads.two_angles(first, second, k, sigma)
    if case == ITS_LENGTH:
        return dyads.angle_and_its_length(first, second, k, sigma)
    if case == OTHER_LENGTH:
        return dyads.angle_and_other_length(first, second, k, sigma)
    return dyads.two_lengths(first, second, k)


def _solve_step_np(case: str, first: Any, second: Any, k: Any, sigma: float) -> tuple[Any, Any, Any]:
    if case == TWO_ANGLES:
        return dyads.two_angles_np(first, second, k, sigma)
    if case == ITS_LENGTH:
        return dyads.angle_and_its_length_np(first, second, k, sigma)
    if case == OTHER_LENGTH:
        return dyads.angle_and_other_length_np(first, second, k, sigma)
    return dyads.two_lengths_np(first, second, k)


def _side(case: str, first: Any, second: Any, k: Any, a: float, b: float) -> float:
    if case == TWO_ANGLES:
        return dyads.two_angles_side(first, k, a)
    if case == ITS_LENGTH:
        return dyads.line_side(dyads.cdiv(first, second), b)
    return dyads.line_side(dyads.cdiv(k, second), b)


def _side_np(case: str, first: Any, second: Any, k: Any, a: Any, b: Any) -> Any:
    if case == TWO_ANGLES:
        return dyads.two_angles_side_np(first, k, a)
    if case == ITS_LENGTH:
        return dyads.line_side_np(dyads.cdiv(first, second), b)
    return dyads.line_side_np(dyads.cdiv(k, second), b)


def _margin(case: str, first: Any, second: Any, k: Any) -> float:
    if case == TWO_ANGLES:
        return dyads.two_angles_margin(first, second, k)
    try:
        if case == ITS_LENGTH:
            return dyads.line_circle_margin(dyads.cdiv(first, second),
                                            dyads.norm(*k) / dyads.norm(*second))
        return dyads.line_circle_margin(dyads.cdiv(k, second), dyads.norm(*first) / dyads.norm(*second))
    except ZeroDivisionError:
        return math.nan


def _margin_np(case: str, first: Any, second: Any, k: Any) -> Any:
    if case == TWO_ANGLES:
        return dyads.two_angles_margin_np(first, second, k)
    norm = dyads.norm_np
    if case == ITS_LENGTH:
        return dyads.line_circle_margin_np(dyads.cdiv(first, second),
                                           norm(k[0], k[1]) / norm(second[0], second[1]))
    return dyads.line_circle_margin_np(dyads.cdiv(k, second),
                                       norm(first[0], first[1]) / norm(second[0], second[1]))


# --- the derivation --------------------------------------------------------------------------

def loop_terms(m: Any) -> list[list[Term]]:
    """The mechanism's loops with each name resolved: an unknown to its index, the driver
    to DRIVER, a parameter to its name, a number to itself."""
    index = {u.name: i for i, u in enumerate(m.unknowns)}

    def ref(x: str | float) -> Ref:
        if isinstance(x, str):
            if x in index:
                return index[x]
            return DRIVER if x == m.driver.name else x
        return float(x)

    return [[(t.sign, ref(t.length), ref(t.angle), t.offset) for t in loop.vectors] for loop in m.loops]


def _is(ref: Ref, unknown: int) -> bool:
    """``ref`` is that unknown (not a number that equals its index: 0.0 == 0)."""
    return ref.__class__ is int and ref == unknown


def _key(ref: Ref) -> tuple[str, Ref]:
    return ref.__class__.__name__, ref


def _is_unknown(ref: Ref, known: set[int]) -> bool:
    return ref.__class__ is int and ref != DRIVER and ref not in known  # type: ignore[operator]


def _combine(a: Sequence[Term], b: Sequence[Term], c: float) -> list[Term]:
    """The loop a + c b, a vector that appears in both with opposite net sign cancelled."""
    net: dict[Any, float] = {}
    order: dict[Any, tuple[Ref, Ref, float]] = {}
    for w, terms in ((1.0, a), (c, b)):
        for sign, lr, ar, off in terms:
            key = (_key(lr), _key(ar), off)
            order.setdefault(key, (lr, ar, off))
            net[key] = net.get(key, 0.0) + w * sign
    return [(net[key], *vec) for key, vec in order.items() if net[key] != 0.0]


def _classify(terms: Sequence[Term], known: set[int], loops: tuple[int, ...],
              weights: tuple[float, ...]) -> Step | None:
    """The step that solves a loop (or combination) with exactly two unknowns in a
    classical case, or None."""
    unknown: list[int] = []
    for _, lr, ar, _ in terms:
        for r in (lr, ar):
            if _is_unknown(r, known) and r not in unknown:
                unknown.append(r)  # type: ignore[arg-type]
    if len(unknown) != 2:
        return None
    angles = [u for u in unknown if any(_is(ar, u) for _, _, ar, _ in terms)]
    lengths = [u for u in unknown if any(_is(lr, u) for _, lr, _, _ in terms)]
    if len(angles) + len(lengths) != 2:  # an unknown is an angle or a length, never both
        return None
    known_terms = tuple(t for t in terms if not (_is_unknown(t[1], known) or _is_unknown(t[2], known)))

    def having(pred: Any) -> tuple[Term, ...]:
        return tuple(t for t in terms if pred(t))

    if len(angles) == 2 and not lengths:
        a, b = angles
        return Step(TWO_ANGLES, loops, weights, (a, b), known_terms,
                    having(lambda t: _is(t[2], a)), having(lambda t: _is(t[2], b)))
    if len(lengths) == 2 and not angles:
        s, t_ = lengths
        return Step(TWO_LENGTHS, loops, weights, (s, t_), known_terms,
                    having(lambda t: _is(t[1], s)), having(lambda t: _is(t[1], t_)))
    if len(angles) == 1 and len(lengths) == 1 and angles[0] != lengths[0]:
        a, s = angles[0], lengths[0]
        with_both = having(lambda t: _is(t[1], s) and _is(t[2], a))
        length_only = having(lambda t: _is(t[1], s) and not _is(t[2], a))
        angle_only = having(lambda t: _is(t[2], a) and not _is(t[1], s))
        if with_both and not length_only:
            return Step(ITS_LENGTH, loops, weights, (a, s), known_terms, angle_only, with_both)
        if length_only and not with_both and angle_only:
            word = ()
            if len(length_only) == 1 and len(angle_only) == 1 and len(loops) == 1:
                word = (angle_only[0], length_only[0])
            return Step(OTHER_LENGTH, loops, weights, (a, s), known_terms, angle_only, length_only,
                        "slider" if word else "", word or None)
    return None


def fourbar_view(terms: Sequence[Term], loop: int) -> FourbarLoop | None:
    """The loop as a four-bar (input, coupler, output, ground) when it is one: four links
    of fixed length (parameters or numbers) on four distinct angles, exactly one of them
    fixed (the ground)."""
    if len(terms) != 4:
        return None
    if any(lr.__class__ is int for _, lr, _, _ in terms):
        return None
    angles = [ar for _, _, ar, _ in terms]
    fixed = [i for i, ar in enumerate(angles) if ar.__class__ is not int]
    moving = [ar for ar in angles if ar.__class__ is int]
    if len(fixed) != 1 or len(set(moving)) != 3:
        return None
    g = fixed[0]
    i, c, o = ((g + 1) % 4, (g + 2) % 4, (g + 3) % 4)
    return FourbarLoop(loop, i, c, o, g)


def derive(m: Any) -> Derivation:
    """The stepwise closed form of a mechanism's loops (see the module's docstring)."""
    loops = loop_terms(m)
    views = tuple(v for v in (fourbar_view(t, i) for i, t in enumerate(loops)) if v is not None)
    by_loop = {v.loop: v for v in views}
    pool = list(range(len(loops)))
    known: set[int] = set()
    steps: list[Step] = []
    n = len(m.unknowns)
    while pool and len(known) < n:
        step = None
        for i in pool:
            step = _classify(loops[i], known, (i,), (1.0,))
            if step is not None:
                pool.remove(i)
                view = by_loop.get(i)
                if view is not None and step.case == TWO_ANGLES:
                    t = loops[i]
                    step = Step(step.case, step.loops, step.weights, step.unknowns, step.known,
                                step.first, step.second, "fourbar", (t[view.coupler], t[view.output]))
                break
        if step is None:
            for i, j in itertools.permutations(pool, 2):
                for c in (1.0, -1.0):
                    step = _classify(_combine(loops[i], loops[j], c), known, (i, j), (1.0, c))
                    if step is not None:
                        pool.remove(j)  # i stays: the pair's second equation
                        break
                if step is not None:
                    break
        if step is None:
            break
        steps.append(step)
        known.update(step.unknowns)
    coupled = tuple((i, len({r for _, lr, ar, _ in loops[i] for r in (lr, ar) if _is_unknown(r, known)}))
                    for i in pool) if len(known) < n else ()
    return Derivation(tuple(steps), n, tuple(u.name for u in m.unknowns),
                      tuple(loop.name for loop in m.loops), coupled, views,
                      {k: q.value for k, q in m.parameters.items()}, tuple(map(tuple, loops)))
