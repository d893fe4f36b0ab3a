"""The closed-form sweep engine: a dyadic mechanism over all its positions at once.

Where the mechanism's loops solve stepwise in closed form (``m.derivation.complete``),
a sweep that stays on one branch needs no continuation:

1. The followed branch, as signs (one per two-way step): ``branch`` names it, or, with
   none, the configuration Newton-Raphson finds from the file's guess at the first driver
   value (the one-at-a-time engine's start; also at the file's own driver value, where
   that engine seeds a mechanism without the old key: both must agree).
2. Every step's margin (:meth:`~linkage.problems.derive.Derivation.margins_np`) on that
   branch at every driver value: all above ``MARGIN_FLOOR`` means no limit position at a
   grid point, so each position is that branch's closed form
   (:meth:`~linkage.problems.derive.Derivation.solve_np`), for all positions at once.
3. The evidence that each is a root to the single solve's standard, without a Newton
   step: Phi and J evaluated at the closed form's own answer (the batch engine's
   :class:`~.vector_loops.VectorLoops`) and the Newton step they imply
   (:func:`~.vector_loops.solve_linear`), not taken. Where that step and max|Phi| meet the
   single solve's convergence test (:func:`linkage.rules.system_converged_array`: the step
   within tol, the residual within tol x length scale), the loop would stop there as
   converged, so the closed form is reported as it is: 0 iterations, and det J is J's at
   the reported position (what the one-at-a-time engine reports). The rare positions where
   it does not (rounding near a limit, a tolerance near rounding) take Newton steps from it
   under the single solve's stopping rule (:class:`~linkage.rules.SystemStops`), up to
   ``POLISH_ITER``: their iterations count those steps, and their det J is J's at the point
   the last step was taken from, as the scalar loop reports it. (An a-priori bound of the
   closed form's error would spare Phi and the step, but not J, whose trigonometry is most
   of the evidence's cost: det J and its ratio are read below.)
4. The checks that make it the one-at-a-time engine's answer: det J of one sign, no
   position where that engine would search for a touch of det J = 0 between grid points
   (a local minimum of |det J| with J near singular), one branch name throughout (a
   rocker-driven four-bar's name can change along one sign branch).

Anything else (a limit inside the sweep, a gap, a position the rule does not accept, a
name or det sign that changes) returns None, and the caller runs the one-at-a-time
engine unchanged. The result is a :class:`~.batch.BatchResult`: columns, with a position
built only when it is read, and the columns in display units (each angle unwrapped and
anchored to ``solve FILE``'s answer, :mod:`.angles`) worked out when first read.

What depends on the mechanism alone is derived once per mechanism (:class:`ClosedPlan`,
:func:`~.pose.implied`): its loop plan, names and units, the bound that spares the ratio of
J's near-singularity (:func:`far_from_touch`), the anchor; the branch to follow is kept per
first driver value (:func:`followed_signs`).
"""

from __future__ import annotations

import math
from functools import partial
from typing import Any

import numpy as np

from ..problems.derive import sign_text
from ..problems.loops import ANGLE_UNITS, Mechanism
from ..records import frozen
from ..rules import (
    GOING,
    SystemStops,
    converged_codes,
    residual_gate,
    step_scales,
    step_size_array,
    system_converged_array,
)
from ..units import degrees
from .angles import (
    anchor_index_array,
    closes_circle_array,
    continuous,
    driver_turn,
    turn_shift,
    unwrap_turns_array,
)
from .batch import STATUS_CODES, BatchResult, batch_result_to_show
from .continuation import Solver
from .limits import TOUCH_CANDIDATE
from .pose import implied, implied_recent, step_words
from .positions import check_driver_values, sweep_result
from .stepwise import classification_of
from .vector_loops import LoopPlan, VectorLoops, loop_plan, per_position, singular_of, solve_linear

MARGIN_FLOOR = 1e-8
"""The smallest relative margin of a step at a grid point for this engine: closer to a
limit than that, the one-at-a-time engine decides (continuation, step halving, gaps)."""

POLISH_ITER = 3
"""The most Newton steps from the closed form where the evidence does not certify it
(one is all such a position needs; a second only where rounding left the first's
residual above the gate)."""

BLOCK = 65_536
"""Positions per block (the temporaries stay small for a million positions)."""


@frozen
class ClosedPlan:
    """What this engine reads of a mechanism, whatever the values: derived once per
    mechanism (:func:`~.pose.implied`; a Mechanism is frozen), not on every sweep."""

    applies: bool
    """The loops solve stepwise in closed form with a choice of sign, on an angle or length driver."""
    scale: float
    """Internal units per display unit of the driver (rad per deg, or 1)."""
    turn: float
    """The driver's full turn in its display unit (an angle driver)."""
    kinds: tuple[str, ...]
    angles: tuple[int, ...]
    """The unknowns that are angles (their indexes)."""
    steps: tuple[float, ...] | None
    """The step scales (:func:`~linkage.rules.step_scales`)."""
    names_are_signs: bool
    """:attr:`~linkage.problems.derive.Derivation.names_are_signs`."""
    words: tuple[tuple[str, str], ...]
    """Each two-way step's two names (:func:`~.pose.step_words`)."""
    units: tuple[str, ...]
    """Each unknown's display unit."""
    names: tuple[str, ...]
    """Each unknown's name."""
    loops: LoopPlan
    """The loop model's terms as the evidence reads them (:func:`~.vector_loops.loop_plan`)."""
    far_from_touch: float | None
    """A bound on |det J| above which J is not near singular at any position
    (:func:`far_from_touch`), or None where J's column lengths vary."""


def closed_plan(m: Mechanism) -> ClosedPlan:
    """``m``'s :class:`ClosedPlan`, derived once per mechanism."""
    return implied(m, "closed_plan", _closed_plan)


def _closed_plan(m: Mechanism) -> ClosedPlan:
    d = m.derivation
    applies = bool(d.complete and d.two_way and m.driver.kind in ("angle", "length"))
    kinds = tuple(u.kind for u in m.unknowns)
    angles = tuple(j for j, k in enumerate(kinds) if k == "angle")
    return ClosedPlan(applies, ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0,
                      driver_turn(m.driver.unit), kinds, angles,
                      step_scales(kinds, m.length_scale), bool(applies and d.names_are_signs),
                      tuple(step_words(m)) if applies else (),
                      tuple("deg" if k == "angle" else m.length_unit for k in kinds),
                      tuple(u.name for u in m.unknowns), loop_plan(m), far_from_touch(loop_plan(m)))


TOUCH_SLACK = 1e-9
"""The relative slack of :func:`far_from_touch`'s bound: far above the rounding of J's
entries and column lengths (a few ulp, 1e-15), so the bound never claims a position that
the ratio itself would call near singular."""


def far_from_touch(loops: LoopPlan) -> float | None:
    """A number B such that |det J| > B at a position means the ratio :func:`_touch_candidate`
    reads there (|det J| over the product of J's columns' lengths) is above TOUCH_CANDIDATE,
    without computing the ratio: TOUCH_CANDIDATE times that product (and ``TOUCH_SLACK``),
    where the product is the same at every position. It is where each unknown appears at
    most once in each loop, as an angle on a fixed length r (its column gets r (-sin, cos)
    there: length |r|) or as a length (sign (cos, sin): length 1), and never as an angle on
    an unknown or driven length; else None (the ratio is then computed). Derived once per
    mechanism (:class:`ClosedPlan`)."""
    squares = [0.0] * loops.n
    seen: set[tuple[int, int]] = set()
    for li, loop in enumerate(loops.loops):
        for term in loop:
            if len(term) == 2:
                continue
            _, r, lidx, _, aidx, _ = term
            for j, part in ((aidx, r if lidx == -1 else None), (lidx, 1.0)):
                if j < 0:
                    continue
                if (li, j) in seen or part.__class__ is not float:
                    return None  # two terms on one unknown, or an angle on a varying length
                seen.add((li, j))
                squares[j] += part * part
    if not all(squares):
        return None
    return TOUCH_CANDIDATE * math.prod(math.sqrt(x) for x in squares) * (1.0 + TOUCH_SLACK)


def closed_sweep(m: Mechanism, values: Any, *, branch: str | None = None, tol: float = 1e-12,
                 max_iter: int = 50, speed: float | None = None, accel: float = 0.0,
                 joints: bool = False) -> BatchResult | None:
    """The sweep of ``m`` over ``values`` (finite reals in display units, as the front
    door leaves them; this engine takes them strictly ascending) by its closed form, or
    None where this engine does not apply (see the module). The other arguments are
    :func:`~.sweep.sweep_mechanism`'s, checked there."""
    plan = closed_plan(m)
    if not plan.applies:
        return None
    vals = np.asarray(values, dtype=float)
    n_pos = len(vals)
    if vals.ndim != 1 or n_pos < 2:
        return None
    # np.diff's subtraction without its wrapper (b - a > 0 exactly where b > a: IEEE
    # subtraction underflows gradually)
    diff = vals[1:] - vals[:-1]
    if not _every(diff > 0.0):
        return None
    # the driver's magnitude, refused as the one-at-a-time engine refuses it
    check_driver_values(m, [float(vals[0]), float(vals[-1])])
    scale = plan.scale
    signs = followed_signs(m, tol, max_iter, float(vals[0]), scale, branch)
    if signs is None:
        return None
    got = _blocks(m, plan, vals, signs, tol, min(max_iter, POLISH_ITER))
    if got is None:
        return None
    cols, det, iters, ratio, words = got
    closes = m.driver.kind == "angle" and closes_circle_array(vals, plan.turn, diff, ascending=True)
    if _touch_candidate(closes, det, ratio):
        return None
    label = "/".join(words)
    # the followed branch as the one-at-a-time engine reports it: its name where each name
    # is one sign branch, else its signs (each position still carries its name)
    followed = label if plan.names_are_signs else sign_text(signs)
    meta = sweep_result(m.name, m.driver.name, m.driver.unit, plan.names, plan.units, (),
                        ((float(vals[0]), float(vals[-1])),), (), followed, classification_of(m),
                        "newton (closed form)", None, m.length_unit, ())
    rates = (speed, accel) if speed is not None or joints else None
    # the columns in display units when first read (unwrapped and anchored: _display); the
    # anchor, a Newton solve once per mechanism and criteria, now, as the sweep's own work
    ref = implied(m, ("closed_anchor", tol, max_iter), lambda m: _anchor(m, tol, max_iter))
    return batch_result_to_show(vals, np.full(n_pos, STATUS_CODES["converged"], dtype=np.int8),
                                partial(_shown, m, plan, ref, vals, cols, closes), det, iters,
                                label, meta, 0, m, rates)


def _shown(m: Mechanism, plan: ClosedPlan, ref: tuple[float, ...] | None, vals: np.ndarray, cols: np.ndarray,
           closes: bool) -> np.ndarray:
    """:func:`_display` as the result keeps it: one row per position."""
    return np.ascontiguousarray(_display(m, plan, ref, vals, cols, closes).T)


def _blocks(m: Mechanism, plan: ClosedPlan, vals: np.ndarray, signs: tuple[float, ...], tol: float,
            max_iter: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None, list[str]] | None:
    """:func:`_block` over every ``BLOCK`` of the driver values (display units), joined:
    None where a block is None or two name the branch or sign det J differently. One block
    (up to ``BLOCK`` positions) is its own answer, not copied."""
    n_pos = len(vals)
    if n_pos <= BLOCK:
        return _block(m, plan, vals * plan.scale, signs, tol, max_iter)
    cols = np.empty((len(plan.kinds), n_pos))
    det = np.empty(n_pos)
    iters = np.empty(n_pos, dtype=np.int32)
    ratio = np.empty(n_pos)
    words: list[str] | None = None
    det_sign = 0.0
    for lo in range(0, n_pos, BLOCK):
        got = _block(m, plan, vals[lo:lo + BLOCK] * plan.scale, signs, tol, max_iter)
        if got is None:
            return None
        q, dt, it, rt, w = got
        s = float(np.sign(dt[0]))
        if words is None:
            words, det_sign = w, s
        elif w != words or s != det_sign:
            return None
        cols[:, lo:lo + BLOCK] = q
        det[lo:lo + BLOCK] = dt
        iters[lo:lo + BLOCK] = it
        ratio[lo:lo + BLOCK] = np.inf if rt is None else rt  # (None: every ratio above the bar)
    assert words is not None
    return cols, det, iters, ratio, words


def followed_signs(m: Mechanism, tol: float, max_iter: int, first: float, scale: float,
                   branch: str | None) -> tuple[float, ...] | None:
    """The signs of the branch to follow from the first driver value ``first`` (display
    units), or None (this engine then does not apply): a function of the mechanism and the
    arguments alone, so kept on the mechanism for the most recent of them
    (:func:`~.pose.implied_recent`: a mechanism swept from many first values keeps a few),
    not solved again on every sweep. ``first``'s sign is part of the key: -0.0 and 0.0 are
    equal but not the same driver value to the solve."""
    key = (first, math.copysign(1.0, first), tol, max_iter, branch)
    return implied_recent(m, "closed_followed_signs", key,
                          lambda m: followed_signs_uncached(m, tol, max_iter, first, scale, branch))


def followed_signs_uncached(m: Mechanism, tol: float, max_iter: int, first: float, scale: float,
                            branch: str | None) -> tuple[float, ...] | None:
    """:func:`followed_signs` solved afresh."""
    d = m.derivation
    if branch is not None:
        try:
            return d.branch_signs(branch, first * scale)
        except (ValueError, ArithmeticError):
            return None  # the one-at-a-time engine says what is wrong, as it always has
    guess = tuple(u.value for u in m.unknowns)
    starts = [first]
    if m.driver.value / scale != first:
        starts.append(m.driver.value / scale)  # where it seeds a mechanism without the old key
    found = []
    solver = Solver(m, "newton", tol, max_iter)
    for v in starts:
        # the one-at-a-time engine's first solve (Solver.solve: textbook Newton), on
        # compiled functions (solve_lean: the same iterates and verdict)
        got = solver.solve_lean(v, guess)
        if got is None:
            return None
        found.append(d.signs_of(got[1], v * scale))
    if any(f != found[0] for f in found) or 0.0 in found[0]:
        return None
    return found[0]


def _block(m: Mechanism, plan: ClosedPlan, drv: np.ndarray, signs: tuple[float, ...], tol: float,
           max_iter: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None, list[str]] | None:
    """One block of driver values (internal units): (unknowns (n, k) internal, det J,
    Newton steps taken, |det J| over J's columns' lengths (None where
    :func:`far_from_touch` shows it above TOUCH_CANDIDATE everywhere), the branch's words),
    or None where the engine does not apply."""
    d = m.derivation
    # the driver's cosine and sine, taken once for the closed form and the loop equations
    plan_loops = plan.loops
    trig = (np.cos(drv), np.sin(drv)) if plan_loops.driver_angle else None
    q, ok, margins = d.solve_margins_np(drv, signs, driver_trig=trig)  # (fresh arrays, this block's own)
    if not _every(ok) or not all(_every(margin > MARGIN_FLOOR) for margin in margins):  # (NaN too)
        return None
    k = len(drv)
    loops = VectorLoops(plan_loops, drv, trig)
    # the evidence: Phi and J at the closed form's own answer and the Newton step they
    # imply (not taken), judged by the single solve's convergence test (linkage.rules)
    phi, jac = loops.evaluate(q, None)
    dq, det = solve_linear(jac, phi, k)
    gate = residual_gate(tol, m.length_scale)
    with np.errstate(invalid="ignore"):  # (NaN: not certified)
        certified = system_converged_array(step_size_array(dq, plan.steps), step_size_array(phi, None),
                                           tol, gate)
    iters = np.zeros(k, dtype=np.int32)
    ratio: np.ndarray | None = None
    if not _every(certified):
        ratio = np.abs(det) / _column_lengths(jac, k)
        if not _polish(loops, q, det, ratio, iters, np.flatnonzero(~certified), plan.steps, tol, gate,
                       max_iter):
            return None
    elif plan.far_from_touch is None or not np.abs(det).min() > plan.far_from_touch:
        ratio = np.abs(det) / _column_lengths(jac, k)
    # else every position's ratio is above TOUCH_CANDIDATE (far_from_touch): None says so
    if not (_every(det > 0.0) or _every(det < 0.0)):
        return None  # det J changes sign: a toggle, the one-at-a-time engine's to locate
    words = _words(m, plan, drv, q)
    if words is None:
        return None
    return np.array(q), det, iters, ratio, words


def _polish(loops: VectorLoops, q: list[np.ndarray], det: np.ndarray, ratio: np.ndarray,
            iters: np.ndarray, active: np.ndarray, steps: tuple[float, ...] | None, tol: float, gate: float,
            max_iter: int) -> bool:
    """Newton-Raphson from the closed form at the positions ``active`` (where the
    evidence of :func:`_block` does not certify it), each stopped as the single solve's
    loop stops it (:class:`~linkage.rules.SystemStops`); ``q``, ``det``, ``ratio`` and
    ``iters`` updated there in place (det J and the ratio of the point the last step was
    taken from, as that loop reports them). False where a position does not converge in
    ``max_iter`` steps or the loop stops it unconverged: the one-at-a-time engine decides."""
    q0 = [c.copy() for c in q]  # (the runaway bound's base: the closed form)
    stops = SystemStops(tol, gate, partial(step_size_array, q0, None))
    it = 0
    while active.size:
        if it >= max_iter:
            return False
        it += 1
        sub = [c[active] for c in q]
        phi, jac = loops.evaluate(sub, active)
        dq, dt = solve_linear(jac, phi, active.size)
        singular = singular_of(jac, dt)
        moved = [s + np.where(singular, 0.0, d) for s, d in zip(sub, dq)]
        codes = stops.judge(step_size_array(dq, steps), step_size_array(phi, None),
                            singular if singular.any() else None, partial(step_size_array, moved, None),
                            active)
        going = codes == GOING
        if not (converged_codes(codes) | going).all():
            return False
        for j in range(len(q)):
            q[j][active] = moved[j]
        det[active], ratio[active], iters[active] = dt, np.abs(dt) / _column_lengths(jac, active.size), it
        active = active[going]
    return True


def _every(mask: np.ndarray) -> bool:
    """Whether every entry of a boolean array is True: ``mask.all()``, counted (np.count_nonzero
    takes a fifth of ndarray.all's time on a block of hundreds, and a sweep asks several times)."""
    return bool(np.count_nonzero(mask) == mask.size)


def _touch_candidate(closes: bool, det: np.ndarray, ratio: np.ndarray | None) -> bool:
    """Whether the one-at-a-time engine would search for a touch of det J = 0 here
    (:func:`~.limits.toggles`): a local minimum of |det J| where J is near singular, the
    neighbours taken around the circle where the grid closes it (more often than that
    engine: a candidate only sends the sweep to it). ``ratio`` None: J is near singular
    nowhere (:func:`far_from_touch`)."""
    if ratio is None:
        return False
    close = ~(ratio > TOUCH_CANDIDATE)  # J near singular (NaN too): rare, so tested first
    if not np.count_nonzero(close if closes else close[1:-1]):
        return False
    a = np.abs(det)
    if closes:
        left, right, mid, near = np.roll(a, 1), np.roll(a, -1), a, ratio
    else:
        left, right, mid, near = a[:-2], a[2:], a[1:-1], ratio[1:-1]
    return bool(((mid <= left) & (mid <= right) & ~(near > TOUCH_CANDIDATE)).any())


def _column_lengths(jac: list[list[Any]], k: int) -> np.ndarray:
    """The product of J's columns' Euclidean lengths, position by position (each sum of
    squares begun from its first term: 0 + x and 1 * x are x, so no pass adds a zero)."""
    out: Any = None
    for j in range(len(jac[0])):
        sq: Any = None
        for row in jac:
            sq = np.square(row[j]) if sq is None else sq + np.square(row[j])
        length = np.sqrt(sq)
        out = length if out is None else out * length
    return per_position(out, k)


def _words(m: Mechanism, plan: ClosedPlan, drv: np.ndarray, q: list[np.ndarray]) -> list[str] | None:
    """Each two-way step's name for the block, by the derivation's own rule
    (:meth:`~linkage.problems.derive.Derivation.words_of_np`), or None where one changes
    within it. Where every name is a function of the signs alone
    (:attr:`~linkage.problems.derive.Derivation.names_are_signs`), the block, all on
    ``signs``, has its first position's names throughout."""
    d = m.derivation
    if plan.names_are_signs:
        return d.words_of([float(c[0]) for c in q], float(drv[0]))
    out = []
    for (first, second), word in zip(plan.words, d.words_of_np(q, drv)):
        if word.all():
            out.append(first)
        elif not word.any():
            out.append(second)
        else:
            return None
    return out


def _display(m: Mechanism, plan: ClosedPlan, ref: tuple[float, ...] | None, vals: np.ndarray,
             cols: np.ndarray, closes: bool) -> np.ndarray:
    """The unknowns in display units, each angle continuous along the cycle and anchored to
    what ``solve FILE`` gives (``ref``: :func:`_anchor`; the rule of :mod:`.angles`, as the
    one-at-a-time engine)."""
    kinds, angles = plan.kinds, list(plan.angles)
    every = len(angles) == len(kinds)
    if every:
        out = degrees(cols)  # every unknown an angle: one pass
    else:
        out = cols.copy()
        for j in angles:
            out[j] = degrees(cols[j])
    if not angles:
        return out
    turns = unwrap_turns_array(out if every else out[angles], closes, all_solved=True)
    # (every position solved: the anchor is the grid point nearest the file's driver value)
    near = int(anchor_index_array(vals, True, m.driver.value / plan.scale, closes, plan.turn)[0])
    shift = np.zeros(len(angles))
    if ref is not None:
        for a, j in enumerate(angles):
            at = continuous(float(out[j, near]), float(turns[a, near]))
            shift[a] = turn_shift(degrees(ref[j]), at)
    if every:
        # elementwise: the rows' own values; no shift adds nothing (turns are never -0.0:
        # floor(x) is -0.0 only for x = -0.0, and (prev + 180) - a is never -0.0)
        return continuous(out, turns + shift[:, None] if shift.any() else turns)
    for a, j in enumerate(angles):
        out[j] = continuous(out[j], turns[a] + shift[a])
    return out


def _anchor(m: Mechanism, tol: float, max_iter: int) -> tuple[float, ...] | None:
    """``solve FILE``'s answer (internal units), as the one-at-a-time engine anchors its
    angles: solve_system's damped Newton from the file's guess at its driver value, on
    compiled functions (the same iterates and verdict); None where it does not converge.
    Solved once per mechanism and criteria (:func:`~.pose.implied`)."""
    scale = ANGLE_UNITS[m.driver.unit] if m.driver.kind == "angle" else 1.0
    got = Solver(m, "newton", tol, max_iter).solve_lean(m.driver.value / scale,
                                                         tuple(u.value for u in m.unknowns), damped=True)
    return None if got is None else tuple(got[1])
