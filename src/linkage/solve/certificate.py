"""Evidence that a small step or a closed bracket is a root: a sign change that is not a
jump or a pole, or |f| at f's own rounding level (the open methods' certification, test 5
of :mod:`linkage.iterate`, and the bracketing methods' final check)."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import Any

from ..problems.scalar import ScalarProblem
from ..result import STATUS_MEMBERS, Status


def check_sign_change(problem: ScalarProblem, x: float, fx: float | None, lo: float, hi: float,
                      f_ends: tuple[float, float], detail: str,
                      shrink_from: float | None = None) -> tuple[Status, str, int]:
    """A bracket [lo, hi] with a sign change that closed on a root has a small residual;
    one that closed on a jump or a pole does not. When |f| at x is not far below its size
    at ``f_ends``, bisect [lo, hi] further, keeping the sign change, until |f| falls to
    1e-3 of that size (the same shortcut as above: at a root it does, after a few
    halvings whatever point x the method ended on), at most down to the rounding level;
    at a jump |f| stays, at a pole it grows or f cannot be evaluated.
    ``shrink_from``: for the certification of an open method's small step, the size |f|
    must instead fall 16 times below (|f| at the ends of [x - w, x + w], which lie next
    to x)."""
    if fx is None or fx == 0.0:
        return Status.CONVERGED_STEP, detail, 0
    start_size = max(abs(f_ends[0]), abs(f_ends[1]))
    if not math.isfinite(start_size) or abs(fx) <= 1e-3 * start_size:
        return Status.CONVERGED_STEP, detail, 0
    lo, hi = sorted((lo, hi))
    if 0.0 in f_ends:
        return Status.CONVERGED_STEP, detail, 0  # f is exactly zero at an end: a root there
    if hi - lo <= 64.0 * math.ulp(max(abs(lo), abs(hi))):
        # A sign change within a few ulps with |f| still above 1e-3 of its size at the
        # ends (the shortcut above did not take it): a root's |f| at the floats next to
        # it is its slope times an ulp, far below that unless the user's bracket was
        # itself a few thousand ulps wide. So this is a jump, or a pole when |f| grew.
        # (An open method's certificate interval is only its tolerance wide, a few ulps
        # at tight tolerances: there only |f| above the ends, a pole, is held against it.)
        if shrink_from is not None and abs(fx) <= start_size:
            return Status.CONVERGED_STEP, detail, 0
        kind = "a pole" if abs(fx) > start_size else "a jump"
        return (Status.DISCONTINUITY, f"|f| is {abs(fx):.3g} at x = {x!r} across a sign change a few ulps "
                f"wide ({start_size:.3g} at the bracket's ends): f changes sign through {kind}", 0)
    target = 1e-3 * start_size if shrink_from is None else shrink_from / 16.0
    evals = 0
    ulp = math.ulp(max(abs(lo), abs(hi)))
    seen = [(x, fx)]
    try:
        flo = problem.f(lo)
        evals = 1
        seen.append((lo, flo))
        smallest = abs(fx)
        for _ in range(64):
            mid = 0.5 * lo + 0.5 * hi
            if hi - lo <= 64.0 * ulp or mid in (lo, hi):
                break
            fm = problem.f(mid)
            evals += 1
            if fm == 0.0:
                return Status.CONVERGED_STEP, detail, evals
            seen.append((mid, fm))
            if abs(fm) < smallest:
                smallest = abs(fm)
                if smallest <= target:
                    return Status.CONVERGED_STEP, detail, evals
            if (fm < 0.0) == (flo < 0.0):
                lo, flo = mid, fm
            else:
                hi = mid
    except (ArithmeticError, ValueError) as exc:
        return (Status.DISCONTINUITY, f"f cannot be evaluated inside the final bracket ({exc}): a pole or "
                f"a gap, not a root", evals)
    # |f| that does not shrink may be rounding noise around a root (an ill-conditioned
    # root such as an expanded (x - 1)^3), not a jump: f's own noise next to a point
    # tells. After a bracketing method the point must lie a million ulps clear of the
    # sign change, or its neighbours would read f across a jump (the noise band of such
    # a root is far wider); an open method's interval is only its tolerance wide, and
    # its own best point is read.
    clear = seen if shrink_from is not None else [
        (v, fv) for v, fv in seen if min(abs(v - lo), abs(v - hi)) > 1e6 * ulp]
    if clear:
        x_small, f_small = min(clear, key=lambda p: abs(p[1]))
        noise, n = at_noise_level(problem, x_small, f_small, abs(hi - lo) + 1.0)
        evals += n
        if noise:
            return Status.CONVERGED_STEP, detail, evals
    return (Status.DISCONTINUITY,
            f"|f| is {abs(fx):.3g} at x = {x!r} and does not shrink with the bracket", evals)


def at_noise_level(problem: ScalarProblem, x: float, fx: float, width: float) -> tuple[bool, int]:
    """Whether f(x) is indistinguishable from zero by f's own evaluation noise: f at the
    floats next to x (up to 4 each side, within ``width``) changes sign, or |f(x)| is
    within the spread of those values. (A jump or a pole has values that are steady, or
    smooth, next to x; a root's are rounding noise.) Returns (verdict, evaluations)."""
    near = []
    evals = 0
    for direction in (math.inf, -math.inf):
        t = x
        for _ in range(4):
            t = math.nextafter(t, direction)
            if abs(t - x) > width:
                break
            v = value_or_none(problem.f, t)
            evals += 1
            if v is not None:
                near.append(v)
    if not near:
        return False, evals
    if any(v == 0.0 or (v < 0.0) != (fx < 0.0) for v in near):
        return True, evals
    return abs(fx) <= max(*near, fx) - min(*near, fx), evals


def final_bracket(state: Any) -> tuple[float, float]:
    """The bracket a bracketing method closed on, from its final state."""
    if hasattr(state, "xblk"):
        return state.x, state.xblk
    return state.a, state.b


def value_or_none(f: Callable[[float], float], x: float) -> float | None:
    """f(x), or None where it fails or is not a finite float."""
    try:
        v = f(x)
    except (ArithmeticError, ValueError, TypeError):
        return None
    return v if isinstance(v, float) and math.isfinite(v) else None


_BIG = sys.float_info.max


def certify_root(problem: ScalarProblem, x: float, fx: float | None, width: float) -> tuple[Status, str, int]:
    """Evidence that a root of f lies within ``width`` of x, for an open method's small step.

    Accepted: |f(x)| within its own rounding bound (``problem.fbound``: f is zero to the
    precision it can be computed with), or a sign change of f across [x - width, x + width]
    that is not a jump or a pole (:func:`check_sign_change`). Otherwise ``STALLED``: a
    small step is only a symptom (Newton near a pole, an overflowing power, a flat f).
    Where no double but x lies within ``width`` of x (the tolerance is below half the
    spacing of doubles there: x = 1e17 deg, where that spacing is 16 deg), no evidence can
    place a root within it, and a zero step says only that x + step rounds to x:
    ``PRECISION_LIMIT``, unless f(x) is exactly zero. Returns (status, detail, extra
    evaluations of f).
    """
    if not isinstance(fx, (int, float)) or not math.isfinite(fx):
        return Status.STALLED, f"f = {fx!r} at the last iterate", 0
    if fx == 0.0:
        return STATUS_MEMBERS.CONVERGED_STEP, "", 0
    if x - width == x and x + width == x:
        return (Status.PRECISION_LIMIT,
                f"no double but {problem.var} = {x!r} lies within the tolerance {width:.3g} of it (doubles "
                f"there are {math.ulp(x):.3g} apart), so no root can be shown within it; f = {fx:.3g}", 0)
    if problem.fbound is not None:
        bound = value_or_none(problem.fbound, x)
        if bound is not None and abs(fx) <= bound:
            return STATUS_MEMBERS.CONVERGED_STEP, "", 0
    lo, hi = max(x - width, -_BIG), min(x + width, _BIG)
    flo, fhi = value_or_none(problem.f, lo), value_or_none(problem.f, hi)
    evals = 2
    if flo is not None and fhi is not None and (flo == 0.0 or fhi == 0.0 or (flo < 0.0) != (fhi < 0.0)):
        ends = max(abs(flo), abs(fhi))
        status, detail, extra = check_sign_change(problem, x, fx, lo, hi, (flo, fhi), "", ends)
        return status, detail, evals + extra
    # No sign change across the whole interval: look inside it, on both sides of x (a root
    # pair, or a root where f is rounding noise and the ends happen to share a sign).
    for a, fa in ((lo, flo), (hi, fhi)):
        for frac in (0.5, 0.25, 0.125):
            b = x + (a - x) * frac
            fb = value_or_none(problem.f, b)
            evals += 1
            if fb is not None and (fb == 0.0 or (fb < 0.0) != (fx < 0.0)):
                inner = sorted((x, b))
                status, detail, extra = check_sign_change(problem, x, fx, inner[0], inner[1], (fx, fb), "",
                                                          max(abs(fx), abs(fb)))
                return status, detail, evals + extra
        del fa
    if problem.fbound is None:
        # no rounding bound for a plain callable: read f's own noise next to x
        noise, n = at_noise_level(problem, x, fx, width)
        evals += n
        if noise:
            return Status.CONVERGED_STEP, "", evals
    shown = ", ".join(f"f({v:.17g}) = {fv:.3g}" if fv is not None else f"f({v:.17g}) is undefined"
                      for v, fv in ((lo, flo), (hi, fhi)))
    return (Status.STALLED,
            f"f = {fx:.3g} at {problem.var} = {x!r}; no sign change within +-{width:.3g} ({shown})"
            + ("" if problem.fbound is None else " and |f| is above its rounding level"), evals)
