"""Where every named joint and point is, and how it moves: the one placing rule
(:func:`walk`) over one position (:func:`place`, :func:`place_bounded` with the error bounds
of each joint's velocity and acceleration) or a block of positions as numpy arrays
(:func:`place_np`, :func:`place_motion_np`, and :func:`place_bounded` with ``xp`` numpy).

Joints are the start points of the loops' vectors that the file names (``joints``): the
first loop starts at the file's ``origin`` ((0, 0) unless it says; a drawing's is where its
first ground joint is drawn), with x along the 0-degree direction; a later loop starts at
its first joint if an earlier loop placed it (a six-bar's second loop at the rocker pivot),
else at the origin too. A named point (``[points.P]``) starts at a joint and adds its own
vectors. Their velocities and accelerations are the same sums, differentiated.
"""

from __future__ import annotations

from typing import Any

from ..problems.loops import DRIVER, LoopModel
from .rate_bounds import Uncertainty, bounds_of, static_values
from .vectors import EPS, FIXED, SCALAR, rate_of, value_of


def place(model: LoopModel, q: Any, d: float, qd: Any = None, vd: float = 0.0, qdd: Any = None,
          vdd: float = 0.0) -> dict[str, tuple[complex, complex, complex]]:
    """Every named joint and point: name -> (position, velocity, acceleration), complex."""
    return {k: v[:3] for k, v in place_bounded(model, q, d, qd, vd, qdd, vdd, None).items()}


def place_bounded(model: LoopModel, q: Any, d: Any, qd: Any, vd: Any, qdd: Any, vdd: Any,
                  unc: Uncertainty | None, data: list[list[tuple[Any, ...]]] | None = None,
                  xp: Any = SCALAR) -> dict[str, tuple[Any, Any, Any, Any, Any]]:
    """:func:`place`, each joint and point with bounds on its velocity and acceleration
    (each of x and y) when ``unc`` gives the inputs' uncertainties (else 0). ``data``: the
    loops' :func:`~.rate_bounds.static_values` at these arguments, if already computed.
    With ``xp`` numpy, over a block of positions (arrays; :func:`place_np` is the cheaper
    twin of the positions alone)."""
    m = model.mechanism
    n = model.n
    qd = qd if qd is not None else [0.0] * n
    qdd = qdd if qdd is not None else [0.0] * n

    def part(t: Any, at: tuple[int, int] | None
             ) -> tuple[tuple[complex, complex, complex], tuple[float, float]]:
        if unc is None:
            return xp.term(t, q, d, qd, vd, qdd, vdd), (0.0, 0.0)
        st = (data[at[0]][at[1]] if data is not None and at is not None
              else static_values(t, q, d, qd, vd, qdd, vdd, xp))
        return st[5:8], (xp.maximum(*bounds_of(st, unc, 1)), xp.maximum(*bounds_of(st, unc, 2)))

    def add(start: tuple[complex, complex, complex, float, float], parts: Any, sign: float
            ) -> tuple[complex, complex, complex, float, float]:
        p, v, a, bv, ba = start
        for (dp, dv, da), (cv, ca) in parts:
            p, v, a = p + sign * dp, v + sign * dv, a + sign * da
            # each addition rounds by at most an ulp of the running sum
            # (not +=: a block's arrays are shared with the joint this one starts from)
            bv = bv + (cv + EPS * xp.hypot(v.real, v.imag) if unc is not None else 0.0)
            ba = ba + (ca + EPS * xp.hypot(a.real, a.imag) if unc is not None else 0.0)
        return p, v, a, bv, ba

    return walk(model, part, add, (complex(*m.origin), 0j, 0j, 0.0, 0.0),
                 lambda xy: (complex(*xy), 0j, 0j, 0.0, 0.0))


THREAD_FROM = 50_000
"""Positions from which :func:`place_np` computes each vector's column on a thread."""


def place_np(model: LoopModel, q: Any, d: Any) -> dict[str, tuple[Any, Any]]:
    """:func:`place`'s positions over arrays: every named joint and point, name -> (x, y)
    arrays, for ``q`` (one array per unknown, internal units) and driver values ``d``.
    The same sums in the same order as :func:`place_bounded` (each vector ``sign r e^(i theta)``,
    the joints by the one placing rule, :func:`walk`), so it agrees
    with the scalar definition to the last bits of numpy's cos and sin (tests check it)."""
    import numpy as np

    d = np.asarray(d, dtype=float)
    zero = np.zeros(d.shape)

    import threading

    def vector(sr: Any, th: Any, out: list[Any]) -> None:
        try:
            out[:] = sr * np.cos(th), sr * np.sin(th)
        except Exception:  # left empty: computed again in line, where the error is raised and named
            return

    def part(t: Any, _at: Any) -> Any:
        sign, lc, li, ac, ai, off = t
        r = q[li] if li >= 0 else (d if li == DRIVER else lc)
        th = (q[ai] if ai >= 0 else (d if ai == DRIVER else ac)) + off
        sr = sign * r  # as _term: (sign r) e^(i theta), e^(i theta) = cos + i sin
        if np.ndim(th) == 0 or th.size < THREAD_FROM:
            return sr * np.cos(th), sr * np.sin(th)
        # a long column's cosines and sines on a thread (numpy releases the GIL in them),
        # beside the loop's next vector: the same operations, so the same bits
        out: list[Any] = []
        thread = threading.Thread(target=vector, args=(sr, th, out), name="linkage-place")
        thread.start()
        return thread, out, sr, th

    def add(start: tuple[Any, Any], parts: Any, sign: float) -> tuple[Any, Any]:
        x, y = start
        for p in parts:
            if isinstance(p[0], threading.Thread):
                p[0].join()
                p = p[1] or (p[2] * np.cos(p[3]), p[2] * np.sin(p[3]))  # the thread failed: here
            dx, dy = p
            x, y = x + sign * dx, y + sign * dy
        return x, y

    origin0 = (zero + model.mechanism.origin[0], zero + model.mechanism.origin[1])
    placed = walk(model, part, add, origin0, lambda xy: (zero + xy[0], zero + xy[1]))
    # a constant joint (a ground pivot) as a full column, as every position has it; a
    # column already full and not another joint's too (a point without vectors is its
    # joint's sums) kept, not copied
    seen: set[int] = set()

    def column(v: Any) -> Any:
        if getattr(v, "shape", None) == d.shape and id(v) not in seen:
            seen.add(id(v))
            return v
        return v + zero

    return {k: (column(x), column(y)) for k, (x, y) in placed.items()}


def walk(model: LoopModel, part: Any, add: Any, origin0: Any, at_rest: Any) -> dict[str, Any]:
    """The placing rule, over any values: each loop from its first joint if an earlier loop
    placed it (else the origin), a joint reached along the side of its loop with fewer
    moving vectors (a ground pivot then has exactly zero velocity, and fewer terms round),
    a point from its joint; a joint of ``model.drawn`` (a fixed joint of a drawing) where it
    was drawn, exactly. ``part(term, (loop, index))`` is a vector's value (``None`` for a
    point's; computed once, and only for a vector a joint's side reads: a four-bar's
    coupler vector, say, places no joint), ``add(start, parts, sign)`` their sum,
    ``at_rest((x, y))`` a joint standing still there."""
    placed: dict[str, Any] = {}
    for i, (loop, terms) in enumerate(zip(model.mechanism.loops, model.terms)):
        names = loop.joints
        if names and names[0] in model.drawn and names[0] not in placed:
            placed[names[0]] = at_rest(model.drawn[names[0]])
        start = placed.get(names[0]) if names and names[0] else None
        origin = start if start is not None else origin0
        moving = [t[2] != FIXED or t[4] != FIXED for t in terms]
        sides: dict[str, tuple[range, float] | None] = {}  # None: a drawn joint, at rest
        for k in range(len(terms)):
            if not names or not names[k] or names[k] in placed or names[k] in sides:
                continue
            if names[k] in model.drawn:
                sides[names[k]] = None
                continue
            forward, backward = range(k), range(k, len(terms))
            ahead = sum(moving[j] for j in forward) <= sum(moving[j] for j in backward)
            sides[names[k]] = (forward, 1.0) if ahead else (backward, -1.0)
        # each vector's value once, only where a joint reads it, all of them before any sum
        # (a part may be computing on a thread: place_np)
        read = sorted({j for side in sides.values() if side is not None for j in side[0]})
        parts = {j: part(terms[j], (i, j)) for j in read}
        for name, side in sides.items():
            placed[name] = (at_rest(model.drawn[name]) if side is None
                            else add(origin, [parts[j] for j in side[0]], side[1]))
    for name, (origin_name, terms) in model.point_terms.items():
        placed[name] = add(placed.get(origin_name, origin0), [part(t, None) for t in terms], 1.0)
    return placed


def place_motion_np(model: LoopModel, q: Any, d: Any, qd: Any, vd: float, qdd: Any, vdd: float
                    ) -> dict[str, tuple[Any, Any, Any]]:
    """:func:`place`'s twin over arrays: every named joint and point, name -> (position,
    velocity, acceleration) as complex arrays, each vector by :func:`~.vectors.term`'s formulas and
    the joints by the one placing rule (:func:`walk`). With ``qdd`` None the accelerations
    are not computed and are None (a static load needs positions and velocities only)."""
    import numpy as np

    d = np.asarray(d, dtype=float)
    zero = np.zeros(d.shape, dtype=complex)
    with_acc = qdd is not None

    def part(t: Any, _at: Any) -> tuple[Any, Any, Any]:
        sign, lc, li, ac, ai, off = t
        r, th = value_of(li, lc, q, d), value_of(ai, ac, q, d) + off
        r1, w = rate_of(li, qd, vd), rate_of(ai, qd, vd)
        e = np.exp(1j * th)
        if not with_acc:
            return sign * r * e, sign * (r1 + 1j * r * w) * e, zero
        r2, al = rate_of(li, qdd, vdd), rate_of(ai, qdd, vdd)
        return (sign * r * e, sign * (r1 + 1j * r * w) * e,
                sign * (r2 + 1j * r * al + 2j * r1 * w - r * w * w) * e)

    def add(start: Any, parts: Any, sign: float) -> tuple[Any, Any, Any]:
        p, v, a = start
        for dp, dv, da in parts:
            p, v = p + sign * dp, v + sign * dv
            a = a + sign * da if with_acc else a
        return p, v, a

    origin0 = (zero + complex(*model.mechanism.origin), zero, zero)
    placed = walk(model, part, add, origin0, lambda xy: (zero + complex(*xy), zero, zero))
    if not with_acc:
        return {k: (p + zero, v + zero, None) for k, (p, v, _) in placed.items()}
    return {k: (p + zero, v + zero, a + zero) for k, (p, v, a) in placed.items()}
