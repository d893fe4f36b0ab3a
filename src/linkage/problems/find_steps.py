"""Finding a mechanism's closed-form steps (the textbook's stepwise method, :mod:`.derive`):
a loop with exactly two unknowns in a classical case, loop by loop; where none has two,
the sum or difference of two loops; what remains is coupled."""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import Any

from .derive import Derivation
from .steps import DRIVER, ITS_LENGTH, OTHER_LENGTH, TWO_ANGLES, TWO_LENGTHS, FourbarLoop, Ref, Step, Term


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
