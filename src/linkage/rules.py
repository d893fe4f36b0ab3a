"""The stopping and continuity rules, each defined once: a scalar function and its numpy
twin side by side. Every loop calls these (the generic loop, the lean loops, the batch
and design engines); tests/test_batch_parity.py holds each twin equal to its scalar on
random inputs, NaN and infinities included.

A system of loop equations has converged (worked example P3, docs/worked_examples.md, the textbook
section 3.9) when the
step just taken and the residual it was taken from are both within tolerance, measured
so that the answer does not depend on the mechanism's size or units:

- the step, max |dq_i| / scale_i: angles in radians, lengths relative to the mechanism's
  length scale (its longest length);
- the residual, max |Phi_i| <= tol x length scale (Phi is a length).

A mechanism scaled by 1e6 therefore takes the same iterations as the original, on every
engine. NaN anywhere fails every test (a comparison with NaN is False).

Continuity: a continuation step from (v_last, q_last) through the tangent prediction
``pred`` to the solution ``q`` stays on its branch when the correction is at most half
the predicted change plus a term in dv^2 (the path's curvature) and rounding, relative to
the size of q.

The open scalar methods' guard (:func:`worse_than_seen`): a small step to a point worse
than one already seen is not convergence.

This module imports nothing at load time: the numpy twins take numpy arrays and import
numpy only when called.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

# --- the system convergence test ------------------------------------------------------------

def residual_gate(tol: float, length_scale: Any) -> Any:
    """The residual tolerance: ``tol`` times the mechanism's length scale (a float, or an
    array of scales, one per design, for the numpy engines)."""
    return tol * length_scale


def step_scales(kinds: Sequence[str], length_scale: float) -> tuple[float, ...] | None:
    """Per-unknown step scales (lengths by the length scale, angles by 1), or None where
    every scale is 1 (the step is then measured as it is)."""
    if length_scale == 1.0 or "length" not in kinds:
        return None
    return tuple(length_scale if k == "length" else 1.0 for k in kinds)


def step_size(step: Sequence[float], scales: Sequence[float] | None) -> float:
    """max |dq_i| / scale_i; NaN if any entry is NaN (the builtin max would skip it)."""
    out = 0.0
    for i, d in enumerate(step):
        a = abs(d) if scales is None else abs(d) / scales[i]
        if a != a:
            return a
        if a > out:
            out = a
    return out


def step_size_array(step: Sequence[Any], scales: Sequence[Any] | None) -> Any:
    """:func:`step_size` position by position: ``step`` one array per unknown; a scale may
    be a float or an array (one per position)."""
    import numpy as np

    out = None
    for i, d in enumerate(step):
        a = np.abs(d) if scales is None else np.abs(d) / scales[i]
        out = a if out is None else np.maximum(out, a)  # (NaN propagates, as in the scalar)
    return np.zeros(0) if out is None else out


def step_limit(tol: float, rtol: float, size_q: Any) -> Any:
    """The step tolerance: ``tol``, plus ``rtol`` times the iterate's size when given."""
    return tol + rtol * size_q if rtol else tol


def system_converged(err: float, resid: float, limit: float, gate: float) -> bool:
    """The step ``err`` (see :func:`step_size`) within ``limit`` and the residual max|Phi|
    at the point it was taken from within ``gate`` (:func:`residual_gate`)."""
    return err <= limit and resid <= gate


def system_converged_source(err: str, resid: str, limit: str, gate: str) -> str:
    """Source of :func:`system_converged` for generated loops, on names: the same test
    without the call (once a solve, about 1% of a two-unknown Newton solve);
    tests/test_newton_system_loops.py holds the two to the same verdicts."""
    return f"({err} <= {limit} and {resid} <= {gate})"


def system_converged_array(err: Any, resid: Any, limit: Any, gate: Any) -> Any:
    """:func:`system_converged` position by position (numpy booleans)."""
    return (err <= limit) & (resid <= gate)


# --- the singularity test -----------------------------------------------------------------------

SINGULAR_RATIO = 1e-12
"""Smallest |det J| / (|ad| + |bc|) of a 2x2 J, or smallest / largest |pivot| of an
equilibrated LU, before a Newton step is refused as singular."""


def invertible(det: float, size: float) -> bool:
    """A 2x2 J = [[a, b], [c, d]] is usable for a Newton step: |det| > SINGULAR_RATIO x
    size with size = |ad| + |bc| (invariant under row and column scaling). Since
    |fl(ad - bc)| <= fl(|ad| + |bc|), this fails for size 0, a NaN and an overflow alike."""
    return abs(det) > SINGULAR_RATIO * size


def invertible_source(det: str, size: str) -> str:
    """Source of :func:`invertible` for generated loops, on ``det`` (a name: it is read up
    to three times) and ``size`` (an expression, evaluated once): the same test without
    the call, which is 40 ns of a 2x2 Newton step's 500. ``|det|`` is written ``det if
    det > 0.0 else 0.0 - det``, the bits of abs (-0.0 and NaN included);
    tests/test_singularity_rule.py holds the two to the same verdicts."""
    return f"({det} if {det} > 0.0 else 0.0 - {det}) > {SINGULAR_RATIO!r} * ({size})"


def invertible_array(det: Any, size: Any) -> Any:
    """:func:`invertible` position by position (numpy booleans)."""
    import numpy as np

    return np.abs(det) > SINGULAR_RATIO * size


def pivots_invertible(ratio: Any) -> Any:
    """An n x n J is usable: the equilibrated LU's smallest/largest |pivot| is at least
    SINGULAR_RATIO (NaN fails); on a float, or on numpy arrays position by position."""
    return ratio >= SINGULAR_RATIO


# --- the open scalar methods' guard on a small step ---------------------------------------------

FAR_SLOPE = 1e-8
"""Below this fraction of the starting |f|, a residual worse than the best seen is rounding."""


def worse_than_seen(size: float, best: float, start: float) -> bool:
    """A step within tolerance is no convergence for an open scalar method (Newton, secant,
    fixed point; iterate.py test 5) when it lands where |f| = ``size`` is worse than the
    ``best`` |f| already seen and still above FAR_SLOPE times the ``start``'s: the slope
    came from far away (a secant chord through a huge f). Scalar only: no array engine
    runs these methods."""
    return size > best and size > FAR_SLOPE * start


# --- the continuity test ----------------------------------------------------------------------

CONTINUITY_ROUNDING = 1e-7
"""The rounding allowance of the continuity test, relative to 1 + max|q|."""

CONTINUITY_CURVATURE = 10.0
"""The allowance for the path's curvature, times dv^2 (rad^2 of driver), relative to 1 + max|q|."""


def continues(correction: float, moved: float, dv: float, size: float) -> bool:
    """A continuation step stays on its branch: the correction max|q - pred| is at most
    half the predicted change max|pred - q_last| plus (1e-7 + 10 dv^2) x size, with dv
    the driver step (rad, or length units) and size 1 + max|q|. NaN fails."""
    return correction <= 0.5 * moved + (CONTINUITY_ROUNDING + CONTINUITY_CURVATURE * dv * dv) * size


def continues_array(correction: Any, moved: Any, dv: Any, size: Any) -> Any:
    """:func:`continues` position by position (numpy booleans)."""
    return correction <= 0.5 * moved + (CONTINUITY_ROUNDING + CONTINUITY_CURVATURE * dv * dv) * size


def continuity_measures(q_last: Sequence[float], pred: Sequence[float],
                        q: Sequence[float]) -> tuple[float, float, float]:
    """(correction, moved, size) of :func:`continues` from the three points."""
    correction = max(abs(a - b) for a, b in zip(q, pred))
    moved = max(abs(a - b) for a, b in zip(pred, q_last))
    size = 1.0 + max(abs(c) for c in q)
    return correction, moved, size


def continuity_measures_array(q_last: Sequence[Any], pred: Sequence[Any],
                              q: Sequence[Any]) -> tuple[Any, Any, Any]:
    """:func:`continuity_measures` position by position: each point one array per unknown."""
    import numpy as np

    correction = np.max(np.abs(np.stack(q) - np.stack(pred)), axis=0)
    moved = np.max(np.abs(np.stack(pred) - np.stack(q_last)), axis=0)
    size = 1.0 + np.max(np.abs(np.stack(q)), axis=0)
    return correction, moved, size


# --- a grid that double precision resolves -----------------------------------------------------

GRID_RESOLUTION = 1e6
"""Doubles that at least separate two neighbouring values of a grid (a sweep's driver values,
a simulation's output times): a spacing of fewer than this many units in the last place of
its largest value leaves each value rounded by more than a millionth of the spacing."""


def grid_resolved(start: float, stop: float, spacing: float) -> tuple[bool, float]:
    """(whether values ``spacing`` apart from ``start`` to ``stop`` are resolved in double
    precision, the spacing of doubles at the larger end): the one rule for driver grids and
    output times."""
    import math

    ulp = math.ulp(max(abs(start), abs(stop)))
    return spacing >= GRID_RESOLUTION * ulp, ulp


# --- the array engines' stopping order ---------------------------------------------------------
# The numpy twin of the ordered stopping tests iterate.run applies to Newton-Raphson on a
# system (iterate.py's module docstring lists them; methods/newton_system.newton_2x2 is the
# same order unrolled), for the array engines (kinematics: batch, closed, designs): one
# block function for every engine, each position judged as the scalar loop judges it.

SYSTEM_DIVERGE_STREAK = 5
"""Consecutive growing steps after which an undamped system Newton has diverged (once its
iterate runs away): iterate.DIVERGE_STREAK, held equal by tests/test_array_stops.py."""

SYSTEM_RUNAWAY = 1e8
"""Growing steps are divergence only once max|q| exceeds this times 1 + max|q0|
(iterate.RUNAWAY)."""

SYSTEM_ROUNDING = 4.0 * 2.220446049250313e-16
"""A step within this times max|q| is rounding noise (iterate.ROUNDING)."""

(GOING, CONVERGED_STEP, CONVERGED_EXACT, CONVERGED_RESIDUAL, SINGULAR, NON_FINITE, DIVERGED,
 PRECISION_LIMIT) = range(8)
"""The array verdicts, one int8 per position: going on, or the scalar loop's status
(``linkage.result.Status``) of the same name. The iteration cap is the engine's loop's."""

ARRAY_STATUS = ("going", "converged_step", "converged_exact", "converged_residual", "singular_jacobian",
                "non_finite", "diverged", "precision_limit")
"""Each verdict code's ``Status`` value (``Status(ARRAY_STATUS[code])``)."""


def converged_codes(codes: Any) -> Any:
    """Where a verdict is a convergence (a step, an exact zero, or a singular J with the
    residual already within the gate), position by position."""
    return (codes >= CONVERGED_STEP) & (codes <= CONVERGED_RESIDUAL)


class SystemStops:
    """The stopping tests of Newton-Raphson on a system, in the scalar loop's order, for
    many positions at once (a block function: :meth:`judge` after every step). Per
    position it keeps what the scalar loop keeps between steps: the last error, the
    growing-step streak, the rounding-level steps and stalls.

    After a step from q (where max|Phi| = ``resid``, J singular or not) to q_new, with
    ``err`` = max|dq_i| / scale_i (:func:`step_size_array`), the first that holds:

    1. J singular (the step's own failure): CONVERGED_RESIDUAL where ``resid`` is within
       the gate already (solve.system_verdict: a root to the tolerance, ill-conditioned),
       else SINGULAR;
    2. ``err`` or ``resid`` not finite: NON_FINITE;
    3. ``resid`` exactly 0: CONVERGED_EXACT;
    4. the step and the residual within tolerance (:func:`system_converged_array`):
       CONVERGED_STEP;
    5. (``can_diverge``: the textbook iteration) ``SYSTEM_DIVERGE_STREAK`` growing steps
       in a row with max|q_new| past the runaway bound: DIVERGED;
    6. a step at rounding level (``err`` <= ``SYSTEM_ROUNDING`` max|q_new|) that stopped
       shrinking twice, or six such steps: PRECISION_LIMIT;

    else GOING. ``tol`` is the step limit (rtol 0, as every engine runs), ``gate`` the
    residual's (:func:`residual_gate`; a float, or one per position); ``q0_size``: max|q0|
    per position (the runaway bound's base), or a function giving it, called only where
    a position goes on after its first step."""

    def __init__(self, tol: float, gate: Any, q0_size: Any, can_diverge: bool = True) -> None:
        import numpy as np

        self.tol = tol
        self.gate = gate
        self.can_diverge = can_diverge
        self.q0_size = q0_size
        self.kept: tuple[Any, Any, Any, Any, Any] | None = None  # made when first needed
        self.first: tuple[Any, Any] | None = None  # (error, rounding) of a first step of all
        # finite limits: a step and a residual within them are finite (what judge's short
        # way reads); a limit of inf leaves test 2 to the ordered tests
        self.bounded = bool(np.isfinite(tol) and np.isfinite(gate).all())

    def _kept(self) -> tuple[Any, Any, Any, Any, Any]:
        """(last error, growing streak, rounding-level steps, stalls, runaway bound) per
        position: what the scalar loop keeps between steps; made at the first step that
        does not stop every position (a block that converges at once never pays for it)."""
        import numpy as np

        if self.kept is None:
            q0 = np.asarray(self.q0_size() if callable(self.q0_size) else self.q0_size, dtype=float)
            k = q0.shape[0]
            with np.errstate(invalid="ignore", over="ignore"):
                runaway = SYSTEM_RUNAWAY * (1.0 + q0)
            self.kept = (np.full(k, np.inf), np.zeros(k, dtype=np.int32), np.zeros(k, dtype=np.int32),
                         np.zeros(k, dtype=np.int32), runaway)
            if self.first is not None:  # what a first step of every position left (judge)
                self.kept[0][...], self.kept[2][...] = self.first
                self.first = None
        return self.kept

    def judge(self, err: Any, resid: Any, singular: Any, q_size: Any, rows: Any = None) -> Any:
        """The verdict codes (int8) of one step at the positions ``rows`` (None: all),
        ``singular`` a boolean array or None (no J singular), ``q_size`` max|q_new| at
        them (or a function giving it, called only where a test reads it); updates their
        kept state."""
        import numpy as np

        def at(a: Any) -> Any:
            return a if rows is None else a[rows]

        gate = self.gate if np.ndim(self.gate) == 0 else at(self.gate)
        if self.bounded and (singular is None or not singular.any()):
            # the usual verdict, the short way: every step and residual within the (finite)
            # limits, so finite, and tests 1-2 hold nowhere; test 3 before test 4 as below.
            # Nothing kept is read again (every position stopped)
            with np.errstate(invalid="ignore"):
                if system_converged_array(err, resid, self.tol, gate).all():
                    codes = np.full(np.shape(err), CONVERGED_STEP, dtype=np.int8)
                    codes[resid == 0.0] = CONVERGED_EXACT
                    return codes
        codes = np.zeros(np.shape(err), dtype=np.int8)
        with np.errstate(invalid="ignore"):
            pending = np.ones(codes.shape, dtype=bool)
            if singular is not None and singular.any():
                within = resid <= gate
                codes[singular] = np.where(within[singular], CONVERGED_RESIDUAL, SINGULAR)
                pending &= ~singular
            for code, hit in ((NON_FINITE, ~(np.isfinite(err) & np.isfinite(resid))),
                              (CONVERGED_EXACT, resid == 0.0),
                              (CONVERGED_STEP, system_converged_array(err, resid, self.tol, gate))):
                codes[pending & hit] = code
                pending &= ~hit
            if not pending.any():
                return codes  # every position stopped: nothing kept is read again
            if self.kept is None and self.first is None and rows is None:
                # the first step of every position: nothing kept yet (no last error, streak,
                # rounding steps or stalls), so tests 5 and 6 cannot hold (a streak of 0, at
                # most one rounding step, no stall: a step's error is finite here). What the
                # loop keeps is this step's error and rounding, made into the arrays only if
                # a later step does not stop every position (the usual second step does)
                if callable(q_size):
                    q_size = q_size()
                self.first = (np.array(err, dtype=float), pending & (err <= SYSTEM_ROUNDING * q_size))
                return codes
            last, streak, rounding_steps, stalls_kept, runaway = self._kept()
            prev = at(last)
            if callable(q_size):
                q_size = q_size()
            if self.can_diverge:
                growth = np.where(err > prev, at(streak) + 1, 0)
                self._put(streak, rows, growth)
                hit = pending & (growth >= SYSTEM_DIVERGE_STREAK) & (q_size > at(runaway))
                codes[hit] = DIVERGED
                pending &= ~hit
            rounding = pending & (err <= SYSTEM_ROUNDING * q_size)
            steps = at(rounding_steps) + rounding
            stalls = at(stalls_kept) + (rounding & (err >= prev))
            self._put(rounding_steps, rows, steps)
            self._put(stalls_kept, rows, stalls)
            codes[rounding & ((stalls >= 2) | (steps >= 6))] = PRECISION_LIMIT
            self._put(last, rows, err)
        return codes

    @staticmethod
    def _put(kept: Any, rows: Any, value: Any) -> None:
        if rows is None:
            kept[...] = value
        else:
            kept[rows] = value


# --- the counts of a step that raised -----------------------------------------------------------

RAISED_COUNTS = "linkage_counts"
"""The attribute of an exception that carries the counts of the step it ended (:func:`counts_made`)."""


def counts_made(exc: BaseException, nfev: int, njev: int) -> BaseException:
    """The one counting rule of every loop: an evaluation of F or J counts once it has
    returned, those of a step that then raises among them (a reader of "3 Jacobian
    evaluations" reads how many were made); the one that raised made nothing and does not.
    A method's step that raises after evaluating says so here, on the exception it re-raises
    (returned: its counts so far, ``nfev`` and ``njev``), and the loop it ends reads them
    back (:data:`COUNTS_ON_RAISE`, :func:`state_after`): a generated loop that counts in its
    own names and the generic one, which counts in a method's state, report the same numbers."""
    setattr(exc, RAISED_COUNTS, (nfev, njev))
    return exc


def counts_after(exc: BaseException, nfev: int, njev: int) -> tuple[int, int]:
    """The counts a loop reports after a step raised ``exc``: those :func:`counts_made` put
    on it (taken off, so an exception object raised again carries none into another run),
    else the loop's own ``nfev`` and ``njev`` (its step's evaluations, counted as they
    returned)."""
    made = getattr(exc, RAISED_COUNTS, None)
    if made is None:
        return nfev, njev
    delattr(exc, RAISED_COUNTS)
    return made  # type: ignore[no-any-return]


COUNTS_ON_RAISE = "nfev, njev = _counts_after(exc, nfev, njev)"
""":func:`counts_after` in a generated loop that counts in ``nfev`` and ``njev`` (its
``Loop.on_raise``; ``_counts_after`` is the function)."""


def state_after(exc: BaseException, state: Any) -> Any:
    """:func:`counts_after` for the generic loop, whose counts are its state's fields (a
    state whose method puts none on the exception, a scalar method's, is left as it is)."""
    if getattr(exc, RAISED_COUNTS, None) is None or not hasattr(state, "njev"):
        return state
    nfev, njev = counts_after(exc, state.nfev, state.njev)
    return state._replace(nfev=nfev, njev=njev)
