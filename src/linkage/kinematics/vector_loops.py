"""Loop equations over arrays of positions (the array engines' Phi and J: :mod:`.batch`,
:mod:`.closed`, the design engines), the linear solve J dq = -Phi at every position, and
the single solve's test of a singular J on arrays."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..problems.loops import DRIVER, LoopModel, Mechanism
from ..records import frozen
from .pose import implied

Term = tuple[float, Any, int, Any, int, float]
"""(sign, length, length index, angle, angle index, offset): an index >= 0 names an
unknown, -1 a fixed value, DRIVER the driver."""


@frozen
class LoopPlan:
    """A loop model's terms as :class:`VectorLoops` reads them, sorted once per model
    (``model.terms`` with the driver's places marked): each loop's terms whose length and
    angle are both fixed numbers are reduced to their x and y (their cosine and sine taken
    once, not on every sweep), the others kept in the loop's order."""

    n: int
    loops: tuple[tuple[tuple[Any, Any] | Term, ...], ...]
    driver_angle: bool
    """Whether a term's angle is the driver itself (no offset): where the cosine and sine
    of the driver values are worth taking once for several readers (``driver_trig``)."""
    driven: tuple[tuple[int, int], ...]
    """(loop, term) of each term that reads the driver (its length or angle), which
    :class:`VectorLoops` gives the driver values; every other term is read as it is."""

    @classmethod
    def of(cls, model: LoopModel) -> LoopPlan:
        loops = []
        for loop in model.terms:
            out: list[tuple[Any, Any] | Term] = []
            for sign, lc, lidx, ac, aidx, off in loop:
                if lidx < 0 and aidx < 0 and DRIVER not in (lidx, aidx):  # two fixed numbers
                    tt = ac + off
                    out.append((sign * lc * np.cos(tt), sign * lc * np.sin(tt)))
                else:
                    out.append((sign, lc, lidx, ac, aidx, off))
            loops.append(tuple(out))
        driver_angle = any(len(t) == 6 and t[4] == DRIVER and t[5] == 0.0 for loop in loops for t in loop)
        driven = tuple((li, ti) for li, loop in enumerate(loops) for ti, t in enumerate(loop)
                       if len(t) == 6 and DRIVER in (t[2], t[4]))
        return cls(model.n, tuple(loops), driver_angle, driven)


def numpy_cos_sin(x: Any) -> tuple[Any, Any]:
    """np.cos and np.sin of ``x``: the trigonometry :class:`VectorLoops` takes by default."""
    return np.cos(x), np.sin(x)


def loop_plan(m: Mechanism) -> LoopPlan:
    """The :class:`LoopPlan` of ``m``'s loop model, made once per mechanism (:func:`~.pose.implied`)."""
    return implied(m, "loop_plan", lambda m: LoopPlan.of(m.model))


class VectorLoops:
    """Phi and J over arrays of positions, from the compiled loop terms.

    Unknowns, residuals and Jacobian entries are kept as separate contiguous 1-D arrays
    (column by column): strided access into (N, m, n) arrays costs several times more.
    """

    cos_sin: Any = staticmethod(numpy_cos_sin)
    """cos and sin of an unknown angle's array, taken directly (see :meth:`_trig`)."""

    def __init__(self, model: LoopModel | LoopPlan, drv: np.ndarray,
                 driver_trig: tuple[np.ndarray, np.ndarray] | None = None, cos_sin: Any = None) -> None:
        """The loops of ``model`` at the driver values ``drv``; a :class:`LoopPlan` of it
        (kept by a caller that sweeps the same model again) gives the same loops.
        ``driver_trig``: cos and sin of ``drv`` (by ``cos_sin``), where the caller took them for its
        own use too; taken here when not given. ``cos_sin``: a function giving cos and sin
        of an array within a stated bound (:mod:`.half_angle`), for np.cos and np.sin."""
        if cos_sin is not None:
            self.cos_sin = cos_sin
        plan = model if isinstance(model, LoopPlan) else LoopPlan.of(model)
        terms: Sequence[Sequence[Any]] = plan.loops
        if plan.driven:  # those terms with the driver values in place (an index -1: a given value)
            terms = [list(loop) for loop in terms]
            for li, ti in plan.driven:
                t = terms[li][ti]
                terms[li][ti] = (t[0], drv if t[2] == DRIVER else t[1], -1 if t[2] < 0 else t[2],
                                 drv if t[4] == DRIVER else t[3], -1 if t[4] < 0 else t[4], t[5])
        self.setup(terms, plan.n, len(drv), None if driver_trig is None else (drv, *driver_trig))

    @classmethod
    def of_terms(cls, terms: Sequence[Sequence[Term]], n: int, size: int) -> VectorLoops:
        """Loops whose fixed lengths and angles may be arrays (one value per position):
        each term is (sign, length, length index, angle, angle index, offset), an index
        >= 0 naming an unknown, -1 a fixed value (a float or an array of ``size``)."""
        self = cls.__new__(cls)
        self.setup(terms, n, size)
        return self

    def setup(self, terms: Sequence[Sequence[tuple[Any, Any] | Term]], n: int, size: int,
              given: tuple[Any, Any, Any] | None = None) -> None:
        """``terms``: each loop's terms (:data:`Term`, no DRIVER index left), or for a term
        with nothing unknown its x and y already (:class:`LoopPlan`). ``given``: (an angle
        array, its cosine, its sine) for a term at that angle with no offset."""
        self.n = n
        self.m = 2 * len(terms)
        # Terms whose length and angle are both known do not change while iterating:
        # sum them once per position, in the loop's order from 0.0 (a sum of fixed values
        # stays one number until the first array joins it: the same additions, the same bits)
        fixed: list[Any] = [0.0] * self.m
        self.moving: list[tuple[int, float, Any, int, Any, int, float]] = []
        for li, loop in enumerate(terms):
            for term in loop:
                if len(term) == 2:
                    x, y = term
                elif term[2] < 0 and term[4] < 0:
                    sign, r, _, th, _, off = term
                    if given is not None and th is given[0] and off == 0.0:
                        # cos(th + 0) is cos(th); sin differs only in the sign of a zero,
                        # which a sum begun from 0.0 does not keep: the same fixed sums
                        c, s = given[1], given[2]
                    else:
                        tt = th + off
                        c, s = np.cos(tt), np.sin(tt)
                    x, y = sign * r * c, sign * r * s
                else:
                    self.moving.append((li, *term))  # type: ignore[arg-type]
                    continue
                fixed[2 * li] = fixed[2 * li] + x
                fixed[2 * li + 1] = fixed[2 * li + 1] + y
        self.fixed = [f if f.__class__ is np.ndarray and f.shape == (size,) else np.full(size, f)
                      for f in fixed]

    def evaluate(self, q: list[np.ndarray],
                 rows: np.ndarray | None) -> tuple[list[np.ndarray], list[list[Any]]]:
        """Phi (m arrays) and J (m x n arrays or zeros) at ``rows`` (None: all positions)."""
        def sub(a: Any) -> Any:
            return a if rows is None or not isinstance(a, np.ndarray) else a[rows]

        # replaced, never modified in place
        phi: list[Any] = list(self.fixed) if rows is None else [f[rows] for f in self.fixed]
        n = self.n
        jac: list[list[Any]] = [[0.0] * n for _ in range(self.m)]
        trig: dict[tuple[int, float], tuple[Any, Any]] = {}
        for li, sign, r, lidx, th, aidx, off in self.moving:
            rr = q[lidx] if lidx >= 0 else sub(r)
            if aidx >= 0 and rows is None:
                c, s = self._trig(trig, aidx, off, q[aidx])
            else:
                tt = q[aidx] if aidx >= 0 else sub(th)
                if off:
                    tt = tt + off
                c, s = self.cos_sin(tt)
            rc, rs = sign * rr * c, sign * rr * s
            phi[2 * li] = phi[2 * li] + rc
            phi[2 * li + 1] = phi[2 * li + 1] + rs
            if aidx >= 0:
                jac[2 * li][aidx] = jac[2 * li][aidx] - rs
                jac[2 * li + 1][aidx] = jac[2 * li + 1][aidx] + rc
            if lidx >= 0:
                jac[2 * li][lidx] = jac[2 * li][lidx] + sign * c
                jac[2 * li + 1][lidx] = jac[2 * li + 1][lidx] + sign * s
        return phi, jac

    def _trig(self, trig: dict[tuple[int, float], tuple[Any, Any]], aidx: int, off: float,
              qa: np.ndarray) -> tuple[Any, Any]:
        """cos and sin of an unknown angle (plus its offset) at every position, taken once
        per evaluation however many terms read them."""
        key = (aidx, off)
        if key not in trig:
            trig[key] = self.cos_sin(qa + off if off else qa)
        return trig[key]


def solve_linear(jac: list[list[Any]], phi: list[np.ndarray], k: int) -> tuple[list[np.ndarray], np.ndarray]:
    """dq with J dq = -Phi at every position, and det J. Cramer's rule for 2x2."""
    if len(jac) == 2 and len(jac[0]) == 2:
        (a, b), (c, d) = jac
        a, b, c, d = per_position(a, k), per_position(b, k), per_position(c, k), per_position(d, k)
        det = a * d - b * c
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            return [(b * phi[1] - d * phi[0]) * inv, (c * phi[0] - a * phi[1]) * inv], det
    n = len(jac[0])
    full = np.empty((k, len(jac), n))
    for i, row in enumerate(jac):
        for j, v in enumerate(row):
            full[:, i, j] = v
    with np.errstate(invalid="ignore"):  # positions not iterating hold NaN
        det = np.linalg.det(full)
    ok = np.isfinite(det) & (det != 0.0)
    dq = np.full((k, n), np.nan)
    if ok.any():
        rhs = -np.stack(phi, axis=1)
        dq[ok] = np.linalg.solve(full[ok], rhs[ok][..., None])[..., 0]
    return [dq[:, j] for j in range(n)], det


def per_position(v: Any, k: int) -> Any:
    """An entry of J at every position: itself where it is already (a constant entry, 0.0
    or a fixed length's cosine, broadcast; without numpy's broadcast_to where it is not
    needed, microseconds a call)."""
    return v if v.__class__ is np.ndarray and v.shape == (k,) else np.broadcast_to(v, (k,))


def singular_of(jac: list[list[Any]], det: np.ndarray) -> np.ndarray:
    """Where J is singular, by the single solve's test (the 2 x 2 test of
    :func:`~linkage.methods.newton_system.newton_direction`): |det J| not above
    SINGULAR_RATIO times |ad| + |bc| (invariant under row and column scaling), or not
    finite. A larger J: det J zero or not finite (the scalar's equilibrated-pivot test has
    no numpy twin yet)."""
    from ..rules import invertible_array

    with np.errstate(invalid="ignore", over="ignore"):
        if len(jac) == 2 and len(jac[0]) == 2:
            (a, b), (c, d) = jac
            return ~invertible_array(det, np.abs(a * d) + np.abs(b * c)) | ~np.isfinite(det)
        return ~np.isfinite(det) | (det == 0.0)
