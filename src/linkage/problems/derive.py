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
and its numpy twin (:meth:`Derivation.solve_np`) share the term sums of :mod:`.steps` and call the
cases of :mod:`.dyads`, scalar and numpy side by side. Parameters are read by name at
evaluation, so one derivation serves every design of a scan.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from typing import Any

from ..records import NamedTuple
from .assembly import MIRROR, TANGENT_SLACK, Indeterminate
from .steps import (
    FourbarLoop,
    Step,
    Term,
    coefficients,
    fourbar_transmission,
    is_open,
    is_open_np,
    solve_step,
    solve_step_margin_np,
    solve_step_np,
    step_margin,
    step_margin_np,
    step_side,
    step_side_np,
)


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
            first, second, k = coefficients(step, p, driver, q, math)
            try:
                got = solve_step(step.case, first, second, k, sigma)
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
            first, second, k = coefficients(step, p, driver, q, math)
            out.append(step_side(step.case, first, second, k, q[step.unknowns[0]], q[step.unknowns[1]]))
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
                first, second, k = coefficients(step, p, driver, q, math)
                out.append(abs(step_margin(step.case, first, second, k)) <= TANGENT_SLACK)
        return tuple(out)

    def two_way_coefficients_np(self, q: Sequence[Any], driver: Any, params: Mapping[str, Any] | None = None,
                                driver_trig: tuple[Any, Any] | None = None) -> list[Any]:
        """Each two-way step's (first, second, K) over arrays at a configuration: what
        :meth:`meets_np`, :meth:`signs_of_np` and :meth:`words_of_np` read, computed once
        where one caller asks for several (``coefs``). ``driver_trig`` as for
        :meth:`solve_margins_np`."""
        import numpy as np

        p = self._params(params)
        d = np.asarray(driver, float)
        xp: Any = np if driver_trig is None else GivenTrig(d, *driver_trig)
        with np.errstate(invalid="ignore", divide="ignore"):
            return [coefficients(step, p, d, q, xp) for step in self.steps if step.two_way]

    def meets_np(self, q: Sequence[Any], driver: Any, params: Mapping[str, Any] | None = None,
                 coefs: list[Any] | None = None) -> list[Any]:
        """:meth:`meets` over arrays (NaN: False)."""
        import numpy as np

        if coefs is None:
            coefs = self.two_way_coefficients_np(q, driver, params)
        cases = [step.case for step in self.steps if step.two_way]
        with np.errstate(invalid="ignore", divide="ignore"):
            return [np.abs(step_margin_np(case, *c)) <= TANGENT_SLACK for case, c in zip(cases, coefs)]

    def on_branch(self, q: Sequence[float], driver: float, want: BranchText,
                  params: Mapping[str, float] | None = None, words: Sequence[str] | None = None) -> bool:
        """Whether a configuration is on the branch ``want`` (:func:`read_branch`): each
        two-way step on its sign (0, on the line, counts as either) or its word, except
        where the step's assemblies meet (:meth:`meets`), which is on either. Which of two
        assemblies of one name (a mirror) a position is on is the continuity test's to
        decide. The one rule of every engine; :meth:`on_branch_np` is its twin. As there, a
        meeting is read only where a step's sign or word is not the one wanted (a sweep on
        its branch, every position, does not pay for it): the same verdict as reading it
        always. ``words``: the configuration's :meth:`words_of` here, where the caller has
        them (a sweep names every position)."""
        if want.signs is not None:
            sides = self.signs_of(q, driver, params)
            hits = [s == w or s == 0.0 for s, w in zip(sides, want.signs)]
        else:
            if words is None:
                words = self.words_of(q, driver, params)
            hits = [(w in ("open", "+")) == wanted for w, wanted in zip(words, want.words)]
        if all(hits):
            return True
        return all(h or m for h, m in zip(hits, self.meets(q, driver, params)))

    def on_branch_np(self, q: Sequence[Any], driver: Any, want: BranchText,
                     params: Mapping[str, Any] | None = None,
                     driver_trig: tuple[Any, Any] | None = None) -> Any:
        """:meth:`on_branch` over arrays. A step's meeting is read only where its sign or
        word is not the one wanted (where every position has them, not at all: a sweep on
        its branch pays nothing for the rule), with the same verdict as reading it everywhere.
        ``driver_trig`` as for :meth:`solve_margins_np` (read with signs wanted)."""
        import numpy as np

        coefs = None if want.signs is None else self.two_way_coefficients_np(q, driver, params, driver_trig)
        with np.errstate(invalid="ignore"):
            if want.signs is not None:
                sides = self.signs_of_np(q, driver, params, coefs)
                hits = [(side == sign) | (side == 0.0) for side, sign in zip(sides, want.signs)]
            else:
                words = self.words_of_np(q, driver, params)
                hits = [word == wanted for word, wanted in zip(words, want.words)]
        ok: Any = True
        for hit in hits:
            ok = ok & hit
        if np.all(ok):
            return ok  # every step as wanted: a meeting changes nothing
        ok = True
        for hit, m in zip(hits, self.meets_np(q, driver, params, coefs)):
            ok = ok & (hit | m)
        return ok

    def margins(self, driver: float, signs: Sequence[float],
                params: Mapping[str, float] | None = None) -> list[float]:
        """Each two-way step's margin on branch ``signs`` (relative; negative where it
        does not assemble, NaN after the first that does not)."""
        p = self._params(params)
        q: list[float] = [math.nan] * self.n
        out: list[float] = []
        signs_left = iter(signs)
        last = self.steps[-1] if self.steps else None
        for step in self.steps:
            sigma = next(signs_left) if step.two_way else 0.0
            first, second, k = coefficients(step, p, driver, q, math)
            if step.two_way:
                out.append(step_margin(step.case, first, second, k))
            if step is last:
                break  # no later step reads its unknowns (a limit scan's every call)
            try:
                got = solve_step(step.case, first, second, k, sigma)
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

    def solve_margins_np(self, driver: Any, signs: Sequence[float], params: Mapping[str, Any] | None = None,
                         driver_trig: tuple[Any, Any] | None = None) -> tuple[list[Any], Any, list[Any]]:
        """:meth:`solve_np` and :meth:`margins_np` in one pass (a sweep needs both):
        (unknowns, ok, margins). ``driver_trig``: np.cos and np.sin of ``driver`` (an angle,
        a float array), where the caller takes them for its own use too (the closed-form
        sweep's loop equations); taken here when not given."""
        import numpy as np

        p = self._params(params)
        d = np.asarray(driver, float)
        xp: Any = np if driver_trig is None else GivenTrig(d, *driver_trig)
        q: list[Any] = [None] * self.n
        # a float parameter broadcasts to anything: only arrays (a scan's designs) are
        # asked (np.broadcast_shapes costs microseconds a call, a sweep's every call)
        shapes = [np.shape(v) for v in p.values() if v.__class__ is not float]
        shape = np.broadcast_shapes(d.shape, *shapes) if shapes else d.shape
        ok: Any = None
        out = []
        signs_left = iter(signs)
        with np.errstate(invalid="ignore", divide="ignore"):
            for step in self.steps:
                sigma = next(signs_left) if step.two_way else 0.0
                first, second, k = coefficients(step, p, d, q, xp)
                if step.two_way:
                    a, b, fine, margin = solve_step_margin_np(step.case, first, second, k, sigma)
                    out.append(margin)
                else:
                    a, b, fine = solve_step_np(step.case, first, second, k, sigma)
                ok = fine if ok is None else ok & fine
                q[step.unknowns[0]], q[step.unknowns[1]] = a, b
        if ok is None or np.shape(ok) != shape:
            ok = np.ones(shape, bool) if ok is None else np.broadcast_to(ok, shape).copy()
        # a step the driver does not reach (two loops whose difference drops it) has one
        # value for every driver: give it the drivers' shape like the other columns (fresh
        # arrays, a caller's to keep); where every position assembled, NaN replaces nothing
        every = bool(np.count_nonzero(ok) == ok.size)  # (ok.all(), counted: a fifth of its time)
        return ([(x.copy() if every else np.where(ok, x, np.nan)) if np.shape(x) == shape else
                 np.where(ok, np.broadcast_to(x, shape), np.nan) for x in q], ok,
                [x if np.shape(x) == shape else np.broadcast_to(x, shape).copy() for x in out])

    def signs_of_np(self, q: Sequence[Any], driver: Any, params: Mapping[str, Any] | None = None,
                    coefs: list[Any] | None = None) -> list[Any]:
        """:meth:`signs_of` over arrays."""
        import numpy as np

        if coefs is None:
            coefs = self.two_way_coefficients_np(q, driver, params)
        two_way = [step for step in self.steps if step.two_way]
        with np.errstate(invalid="ignore", divide="ignore"):
            return [_side_np(step, c, q) for step, c in zip(two_way, coefs)]

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
                out.append("open" if is_open(step, p, driver, q) else "crossed")
            else:  # the sign, computed only here: a sweep names every position
                first, second, k = coefficients(step, p, driver, q, math)
                sigma = step_side(step.case, first, second, k, q[step.unknowns[0]], q[step.unknowns[1]])
                out.append("+" if sigma >= 0.0 else "-")
        return out

    def words_of_np(self, q: Sequence[Any], d: Any, params: Mapping[str, Any] | None = None,
                    coefs: list[Any] | None = None) -> list[Any]:
        """:meth:`words_of` over arrays: each two-way step's word as a bool, True for open
        (a four-bar or slider-crank loop) or + (the step's sign, 0 counting as +)."""
        import numpy as np

        p = self._params(params)
        two_way = [step for step in self.steps if step.two_way]
        if all(step.word_rule for step in two_way):
            return [is_open_np(step, p, d, q) for step in two_way]  # no side is read
        if coefs is None:
            coefs = self.two_way_coefficients_np(q, d, p)
        out = []
        with np.errstate(invalid="ignore", divide="ignore"):
            for step, c in zip(two_way, coefs):
                out.append(is_open_np(step, p, d, q) if step.word_rule else _side_np(step, c, q) >= 0.0)
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


class GivenTrig:
    """numpy as :func:`~.steps.coefficients` reads it (``xp``), with the cosine and sine of
    one array as a caller already took them (np.cos and np.sin of that very array: the
    same bits); np.cos and np.sin of anything else."""

    __slots__ = ("c", "of", "s")

    def __init__(self, of: Any, c: Any, s: Any) -> None:
        self.of, self.c, self.s = of, c, s

    def cos(self, t: Any) -> Any:
        import numpy as np

        return self.c if t is self.of else np.cos(t)

    def sin(self, t: Any) -> Any:
        import numpy as np

        return self.s if t is self.of else np.sin(t)

    def __getattr__(self, name: str) -> Any:
        import numpy as np

        return getattr(np, name)


def _side_np(step: Step, coefs: Any, q: Sequence[Any]) -> Any:
    """A two-way step's side (its sign) over arrays, from its coefficients."""
    return step_side_np(step.case, *coefs, q[step.unknowns[0]], q[step.unknowns[1]])


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
