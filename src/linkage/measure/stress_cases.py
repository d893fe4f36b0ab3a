"""The cases of ``linkage stress`` (:mod:`linkage.measure.stress`): random four-bars and
Freudenstein equations, bad starts, tiny tolerances and non-finite values, each with its
reference roots from 40-digit mpmath or a closed form, never from the methods under test."""

from __future__ import annotations

import math
import random
import sys
from collections.abc import Callable
from typing import Any

from ..problems.catalog import Case
from ..problems.classic import mp_root
from ..units import degrees, radians

EPS = sys.float_info.epsilon


# --- family 2: random four-bar loop systems ---------------------------------------------------


def fourbar_cases(rng: random.Random, count: int) -> list[dict[str, Any]]:
    from ..problems.closed_form import Indeterminate, cos_band_arcs, fourbar_positions

    out: list[dict[str, Any]] = []
    while len(out) < count:
        scale = 10 ** rng.uniform(-6, 6)
        ratios = [10 ** rng.uniform(-3, 3) for _ in range(3)]
        r1 = scale
        r2, r3, r4 = (scale * x for x in ratios)
        near_limit = rng.random() < 0.3
        lo, hi = (r3 - r4) ** 2, (r3 + r4) ** 2
        arcs = cos_band_arcs(
            (r1 * r1 + r2 * r2 - hi) / (2 * r1 * r2), (r1 * r1 + r2 * r2 - lo) / (2 * r1 * r2), 0.0
        )
        if arcs == []:
            continue
        if arcs is None:
            theta2 = rng.uniform(-180, 180)
            near_limit = False
        else:
            a, b = arcs[rng.randrange(len(arcs))]
            if b - a < 1e-6:
                continue
            theta2 = (b - 1e-8 if rng.random() < 0.5 else a + 1e-8) if near_limit else rng.uniform(a, b)
        try:
            if not fourbar_positions(r1, r2, r3, r4, 0.0, theta2=radians(theta2)):
                continue
        except Indeterminate:
            continue
        sols = mp_fourbar_positions(r1, r2, r3, r4, theta2)
        if not sols:
            continue
        branch = rng.choice(sorted(sols))
        exact = sols[branch]
        perturb = 0.0 if near_limit else rng.uniform(-8, 8)
        out.append(
            {
                "links": (r1, r2, r3, r4),
                "theta2": theta2,
                "branch": branch,
                "exact": exact,
                "guess": (degrees(exact["theta3"]) + perturb, degrees(exact["theta4"]) - perturb),
                "near_limit": near_limit,
                "scale": scale,
            }
        )
    return out


def fourbar_equation_cases(rng: random.Random, count: int) -> list[Case]:
    """Random Freudenstein equations: (R2 + cos a) cos phi + sin a sin phi = R1 cos a + R3, so
    phi = atan2(sin a, R2 + cos a) +- acos(K / sqrt(A^2 + B^2)) in closed form; some
    within 1e-8 deg of the limit where the two roots merge."""
    from ..problems.freudenstein import fourbar_equation

    out: list[Case] = []
    while len(out) < count:
        r1, r2 = 10 ** rng.uniform(-3, 3), 10 ** rng.uniform(-3, 3)
        alpha = rng.uniform(-180, 180)
        a = radians(alpha)
        big_a, big_b = r2 + math.cos(a), math.sin(a)
        norm = math.hypot(big_a, big_b)
        if norm == 0.0:
            continue
        near = rng.random() < 0.2
        # choose R3 so that |K| / norm is a random ratio below 1 (or within 1e-12 of it)
        ratio = (1 - 1e-12) if near else rng.uniform(-0.99, 0.99)
        r3 = ratio * norm - r1 * math.cos(a)
        roots = _mp_fourbar_roots(alpha, r1, r2, r3)
        if roots is None:
            continue
        p = fourbar_equation(alpha, r1, r2, r3)
        # f's rounding (terms of size |K|, |A|, |B| cancel) moves a root by eps_f / |f'|
        terms = abs(r1 * math.cos(a)) + abs(r3) + abs(r2) + 2.0  # the sizes that cancel in f
        slope = min(abs(p.fprime(r)) for r in roots)  # type: ignore[misc]
        slack = 16 * EPS * terms / slope if slope > 0 else math.inf
        root = roots[0]
        width = max(1e-6, min(abs(roots[0] - roots[1]) / 3, rng.uniform(0.1, 20)))
        bracket = (root - width * rng.uniform(0.1, 1), root + width * rng.uniform(0.1, 1))
        if p.f(bracket[0]) * p.f(bracket[1]) >= 0:
            bracket = None  # type: ignore[assignment]
        x0 = root + rng.uniform(-1, 1) * (width if not near else 1e-3)
        out.append(
            Case(
                "fourbar-equation",
                f"R=({r1:.3g},{r2:.3g},{r3:.3g}) alpha={alpha:.4g}",
                p.f,
                p.fprime,
                bracket,
                x0,
                x0 + 0.1 * width,
                roots + tuple(r + 360 * k for r in roots for k in (-1, 1)),
                tol=1e-10,
                g=None,
                slack=slack,
            )
        )
    return out


def _mp_fourbar_roots(alpha: float, r1: float, r2: float, r3: float) -> tuple[float, float] | None:
    """Both roots (deg) of the Freudenstein equation in closed form, at 40 digits, from the
    exact double inputs: phi = atan2(B, A) +- acos(K / sqrt(A^2 + B^2))."""
    import mpmath as mp

    with mp.workdps(40):
        a = mp.radians(mp.mpf(alpha))
        big_a, big_b = mp.mpf(r2) + mp.cos(a), mp.sin(a)
        k = mp.mpf(r1) * mp.cos(a) + mp.mpf(r3)
        ratio = k / mp.sqrt(big_a**2 + big_b**2)
        if abs(ratio) > 1:
            return None
        base, half = mp.atan2(big_b, big_a), mp.acos(ratio)
        return float(mp.degrees(base + half)), float(mp.degrees(base - half))


# --- families 3 to 5 ---------------------------------------------------------------------------


def bad_start_cases() -> list[Case]:
    from ..problems.expression import equation_problem

    def eq(text: str) -> tuple[Callable[[float], float], Callable[[float], float]]:
        p = equation_problem(text)
        return p.f, p.fprime  # type: ignore[return-value]

    q, qp = eq("x**2 - 4*x + 1")
    c, cp = eq("x**3 - 2*x + 2")
    a, ap = eq("atan(x)")
    k, kp = eq("x - 0.8*sin(x) - 1")
    roots_q = (2 - math.sqrt(3), 2 + math.sqrt(3))
    return [
        Case("bad-starts", "f' = 0 at the start", q, qp, None, 2.0, 2.5, roots_q),
        Case("bad-starts", "near f' = 0 (P1, x0 = 2.5)", q, qp, None, 2.5, 2.4, roots_q),
        Case("bad-starts", "Newton cycle x^3 - 2x + 2 from 0", c, cp, None, 0.0, 1.0, (-1.7692923542386314,)),
        Case("bad-starts", "inflection, atan from 1.5", a, ap, None, 1.5, 1.6, (0.0,)),
        Case("bad-starts", "far start, atan from 1e6", a, ap, None, 1e6, 2e6, (0.0,)),
        Case("bad-starts", "far start, Kepler from 1e3", k, kp, None, 1e3, 900.0, (mp_root_kepler(),)),
        Case("bad-starts", "no real root, x**2 + 1e-3", *eq("x**2 + 1e-3"), None, 1.0, 0.5, ()),
    ]


def mp_root_kepler() -> float:
    import mpmath as mp

    return mp_root(lambda x: x - mp.mpf("0.8") * mp.sin(x) - 1, 0.0, 3.0)


def tiny_tol_cases() -> list[Case]:
    out = []
    for tol in (EPS, EPS / 4, 1e-20, 1e-300):
        out.append(
            Case(
                "tiny-tol",
                f"sqrt 2, tol {tol:.2g}",
                lambda x: x * x - 2,
                lambda x: 2 * x,
                (1.0, 2.0),
                1.0,
                2.0,
                (math.sqrt(2),),
                tol=tol,
            )
        )
        out.append(
            Case(
                "tiny-tol",
                f"Freudenstein four-bar, tol {tol:.2g}",
                *_fourbar_fd(),
                (50.0, 60.0),
                50.0,
                60.0,
                (54.887763188779143,),
                tol=tol,
            )
        )
        out.append(
            Case(
                "tiny-tol",
                f"x**2 - 4 (exact root 2), tol {tol:.2g}",
                lambda x: x * x - 4,
                lambda x: 2 * x,
                (0.0, 3.0),
                3.0,
                2.5,
                (2.0,),
                tol=tol,
            )
        )
    return out


def _fourbar_fd() -> tuple[Callable[[float], float], Callable[[float], float]]:
    from ..problems.freudenstein import fourbar_equation

    p = fourbar_equation(70.0)
    return p.f, p.fprime  # type: ignore[return-value]


def non_finite_cases() -> list[Case]:
    nan, inf = math.nan, math.inf
    return [
        Case(
            "non-finite",
            "f is NaN left of 0.5",
            lambda x: nan if x < 0.5 else x - 1,
            lambda x: 1.0,
            (0.0, 2.0),
            0.0,
            0.2,
            (1.0,),
        ),
        Case(
            "non-finite",
            "f is inf at the start",
            lambda x: inf if x == 0 else x - 1,
            lambda x: 1.0,
            (0.0, 2.0),
            0.0,
            3.0,
            (1.0,),
        ),
        Case("non-finite", "f' is NaN", lambda x: x - 1, lambda x: nan, None, 3.0, 2.0, (1.0,)),
        Case(
            "non-finite",
            "f overflows",
            lambda x: math.exp(x) - 1e300 if x < 700 else math.exp(x),
            lambda x: math.exp(x),
            None,
            800.0,
            790.0,
            (math.log(1e300),),
        ),
        Case(
            "non-finite",
            "sqrt(x) - 1 from -1 (domain)",
            lambda x: math.sqrt(x) - 1,
            lambda x: 0.5 / math.sqrt(x),
            None,
            -1.0,
            0.5,
            (1.0,),
        ),
        Case("non-finite", "NaN start", lambda x: x - 1, lambda x: 1.0, (nan, 2.0), nan, nan, (1.0,)),
        Case("non-finite", "inf bracket", lambda x: x - 1, lambda x: 1.0, (-inf, inf), inf, 2.0, (1.0,)),
    ]


def mp_fourbar_positions(
    r1: float, r2: float, r3: float, r4: float, theta2_deg: float
) -> dict[str, dict[str, float]]:
    """Both branches (rad) at 40 digits: the double-precision circle intersection loses
    half its digits when the circles are nearly tangent (a tiny coupler)."""
    import mpmath as mp

    with mp.workdps(40):
        t2 = mp.radians(mp.mpf(theta2_deg))
        ax, ay = mp.mpf(r2) * mp.cos(t2), mp.mpf(r2) * mp.sin(t2)
        dx, dy = ax - r1, ay
        d = mp.sqrt(dx * dx + dy * dy)
        if d == 0 or d > r3 + r4 or d < abs(mp.mpf(r3) - r4):
            return {}
        a = (mp.mpf(r4) ** 2 - mp.mpf(r3) ** 2 + d * d) / (2 * d)
        h = mp.sqrt(max(mp.mpf(r4) ** 2 - a * a, 0))
        ux, uy = dx / d, dy / d
        out = {}
        for sign in (1, -1):
            bx, by = r1 + a * ux - sign * h * uy, a * uy + sign * h * ux
            t3, t4 = mp.atan2(by - ay, bx - ax), mp.atan2(by, bx - r1)
            out["open" if mp.sin(t4 - t3) > 0 else "crossed"] = {"theta3": float(t3), "theta4": float(t4)}
        return out


def fourbar_mechanism(it: dict[str, Any]) -> Any:
    """A random four-bar of :func:`fourbar_cases` as a mechanism (metres, closed form)."""
    from ..kinematics.loading import parse_mechanism

    r1, r2, r3, r4 = it["links"]
    unit = {"unit": "m"}
    doc = {
        "name": "random four-bar",
        "length_unit": "m",
        "parameters": {
            "r1": {"value": r1, **unit},
            "r2": {"value": r2, **unit},
            "r3": {"value": r3, **unit},
            "r4": {"value": r4, **unit},
            "theta1": {"value": 0.0, "unit": "deg"},
        },
        "driver": {"name": "theta2", "value": it["theta2"], "unit": "deg"},
        "unknowns": {
            "theta3": {"guess": it["guess"][0], "unit": "deg"},
            "theta4": {"guess": it["guess"][1], "unit": "deg"},
        },
        "loops": [
            {
                "name": "L",
                "vectors": [
                    {"length": "r2", "angle": "theta2"},
                    {"length": "r3", "angle": "theta3"},
                    {"length": "r4", "angle": "theta4", "sign": -1},
                    {"length": "r1", "angle": "theta1", "sign": -1},
                ],
            }
        ],
    }
    return parse_mechanism(doc)
