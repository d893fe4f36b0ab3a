"""The baselines ``linkage bench`` compares the library with: each the same work written
plainly by hand, with no checks, the floor any library pays over. They are the reference
of the speed figures (README, "Performance"), so they use nothing of the engines they are
compared with; tests/test_bench.py holds each to the library's answer."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ..units import degrees


def hand_newton(f: Callable[[float], float], fp: Callable[[float], float], x: float, tol: float) -> float:
    """The floor: Newton in ten lines of plain Python."""
    for _ in range(100):
        step = f(x) / fp(x)
        x -= step
        if abs(step) <= tol:
            return x
    return x


def hand_newton_2x2(
    F: Callable[..., list[float]], J: Callable[..., list[list[float]]], q: Sequence[float], tol: float
) -> tuple[float, float]:
    """The floor for a four-bar: Newton with Cramer's rule, no checks."""
    a, b = q
    for _ in range(50):
        f1, f2 = F((a, b))
        (j11, j12), (j21, j22) = J((a, b))
        det = j11 * j22 - j12 * j21
        da = (-f1 * j22 + f2 * j12) / det
        db = (-f2 * j11 + f1 * j21) / det
        a, b = a + da, b + db
        if abs(da) <= tol and abs(db) <= tol:
            break
    return a, b


def fourbar_open(theta2: Any, r1: float, r2: float, r3: float, r4: float) -> tuple[Any, Any]:
    """theta3, theta4 (deg) of a four-bar (ground r1 along x from O2 to O4, crank r2,
    coupler r3, rocker r4) at every crank angle ``theta2`` (rad, a numpy array): the
    intersection of the circle of radius r3 about the crank pin A with the circle of radius
    r4 about O4, on the side where sin(theta4 - theta3) > 0 for a crank-rocker drawn as
    sample_inputs/crank_rocker.toml is (Norton, *Design of Machinery*, section 4.5: the open
    configuration). Written tight: in place where numpy allows, one temporary at a time."""
    import numpy as np

    ax = np.cos(theta2)
    ax *= r2
    ay = np.sin(theta2)
    ay *= r2
    dx = ax - r1  # O4 -> A
    d2 = dx * dx
    d2 += ay * ay
    a = d2 + (r4 * r4 - r3 * r3)  # 2 d times the distance from O4 to the chord, along O4 -> A
    a /= 2.0 * d2
    h = np.square(a)  # (h / d)^2 = (r4 / d)^2 - (a / d)^2
    np.subtract(r4 * r4 / d2, h, out=h)
    np.sqrt(h, out=h)
    bx = a * dx
    bx += h * ay  # B - O4 = a (A - O4) - h perp(A - O4), the open side
    by = a * ay
    by -= h * dx
    t4 = np.arctan2(by, bx)
    bx += r1 - ax
    by -= ay
    t3 = np.arctan2(by, bx)
    return degrees(t3), degrees(t4)
