"""The classic scalar test collections, with references computed independently.

The Alefeld-Potra-Shi test functions (ACM TOMS 748, 1995, Table 1, with their parameters
and brackets) and Chandrupatla's test functions (Adv. Eng. Software 28, 1997), plus a
jump, a pole and a triple root inside a bracket. Reference roots come from closed forms
or from 200 bisections at 60 digits in mpmath, never from the methods under test.
Part of the one registry of test problems (:mod:`linkage.problems.catalog`).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import Any

from ..records import frozen

EPS = sys.float_info.epsilon


@frozen
class Case:
    family: str
    name: str
    f: Callable[[float], float]
    fprime: Callable[[float], float] | None
    bracket: tuple[float, float] | None
    x0: float | None
    x1: float | None
    roots: tuple[float, ...]  # reference roots (empty: there is none)
    tol: float = 1e-10
    rtol: float = 0.0
    note: str = ""
    g: Callable[[float], float] | None = None
    slack: float = 0.0  # conditioning: how far rounding in f alone can move the root


# --- family 1: the classic collections ------------------------------------------------------


def _aps_cases() -> list[
    tuple[
        str,
        Callable[[float], float],
        Callable[[float], float] | None,
        tuple[float, float],
        float,
        Callable[[Any], Any],
        float | None,
    ]
]:
    """(name, f, f', bracket, x0, mpmath f, closed-form root or None), TOMS 748 Table 1."""
    import mpmath as mp

    exp, sin, cos = math.exp, math.sin, math.cos
    out: list[Any] = []
    out.append(
        (
            "aps01",
            lambda x: sin(x) - x / 2,
            lambda x: cos(x) - 0.5,
            (math.pi / 2, math.pi),
            3.0,
            lambda x: mp.sin(x) - x / 2,
            None,
        )
    )
    for k in range(1, 11):

        def f2(x: float, _k: int = 0) -> float:
            return -2.0 * sum((2 * i - 5) ** 2 / (x - i * i) ** 3 for i in range(1, 21))

        def fp2(x: float) -> float:
            return 6.0 * sum((2 * i - 5) ** 2 / (x - i * i) ** 4 for i in range(1, 21))

        out.append(
            (
                f"aps02.{k}",
                f2,
                fp2,
                (k * k + 1e-9, (k + 1) ** 2 - 1e-9),
                k * k + 1.0,
                lambda x: -2 * mp.fsum((2 * i - 5) ** 2 / (x - i * i) ** 3 for i in range(1, 21)),
                None,
            )
        )
    for a, b in ((-40, -1), (-100, -2), (-200, -3)):
        out.append(
            (
                f"aps03.{a},{b}",
                lambda x, a=a, b=b: a * x * exp(b * x),
                lambda x, a=a, b=b: a * (b * x + 1) * exp(b * x),
                (-9.0, 31.0),
                -2.0,
                lambda x, a=a, b=b: a * x * mp.exp(b * x),
                0.0,
            )
        )
    for n, a, br, x0 in (
        [(n, 0.2, (0.0, 5.0), 2.5) for n in (4, 6, 8, 10, 12)]
        + [(n, 1.0, (0.0, 5.0), 2.5) for n in (4, 6, 8, 10, 12)]
        + [(n, 1.0, (-0.95, 4.05), 1.5) for n in (8, 10, 12, 14)]
    ):
        out.append(
            (
                f"aps04.{n},{a},{br[0]}",
                lambda x, n=n, a=a: x**n - a,
                lambda x, n=n: n * x ** (n - 1),
                br,
                x0,
                lambda x, n=n, a=a: x**n - mp.mpf(a),
                1.0 if a == 1.0 else None,
            )
        )
    out.append(
        ("aps05", lambda x: sin(x) - 0.5, cos, (0.0, 1.5), 1.3, lambda x: mp.sin(x) - 0.5, math.pi / 6)
    )
    for n, x0 in zip(
        (1, 2, 3, 4, 5, 20, 40, 60, 80, 100), (0.5,) * 4 + (0.4, 0.1, 0.05, 1 / 30, 0.025, 0.02)
    ):
        out.append(
            (
                f"aps06.{n}",
                lambda x, n=n: 2 * x * exp(-n) - 2 * exp(-n * x) + 1,
                lambda x, n=n: 2 * exp(-n) + 2 * n * exp(-n * x),
                (0.0, 1.0),
                x0,
                lambda x, n=n: 2 * x * mp.exp(-n) - 2 * mp.exp(-n * x) + 1,
                None,
            )
        )
    for n in (5, 10, 20):
        out.append(
            (
                f"aps07.{n}",
                lambda x, n=n: (1 + (1 - n) ** 2) * x - (1 - n * x) ** 2,
                lambda x, n=n: (1 + (1 - n) ** 2) + 2 * n * (1 - n * x),
                (0.0, 1.0),
                0.4,
                lambda x, n=n: (1 + (1 - n) ** 2) * x - (1 - n * x) ** 2,
                None,
            )
        )
    for n in (2, 5, 10, 15, 20):
        out.append(
            (
                f"aps08.{n}",
                lambda x, n=n: x * x - (1 - x) ** n,
                lambda x, n=n: 2 * x + n * (1 - x) ** (n - 1),
                (0.0, 1.0),
                0.9,
                lambda x, n=n: x * x - (1 - x) ** n,
                None,
            )
        )
    for n in (1, 2, 4, 5, 8, 15, 20):
        out.append(
            (
                f"aps09.{n}",
                lambda x, n=n: (1 + (1 - n) ** 4) * x - (1 - n * x) ** 4,
                lambda x, n=n: (1 + (1 - n) ** 4) + 4 * n * (1 - n * x) ** 3,
                (0.0, 1.0),
                0.5,
                lambda x, n=n: (1 + (1 - n) ** 4) * x - (1 - n * x) ** 4,
                None,
            )
        )
    for n in (1, 5, 10, 15, 20):
        out.append(
            (
                f"aps10.{n}",
                lambda x, n=n: exp(-n * x) * (x - 1) + x**n,
                lambda x, n=n: exp(-n * x) * (-n * (x - 1) + 1) + n * x ** (n - 1),
                (0.0, 1.0),
                0.9,
                lambda x, n=n: mp.exp(-n * x) * (x - 1) + x**n,
                None,
            )
        )
    for n in (2, 5, 15, 20):
        out.append(
            (
                f"aps11.{n}",
                lambda x, n=n: (n * x - 1) / ((n - 1) * x),
                lambda x, n=n: 1 / (n - 1) / x**2,
                (0.01, 1.0),
                0.01,
                lambda x, n=n: (n * x - 1) / ((n - 1) * x),
                1.0 / n,
            )
        )
    for n in (2, 3, 4, 5, 6, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31, 33):
        out.append(
            (
                f"aps12.{n}",
                lambda x, n=n: x ** (1.0 / n) - n ** (1.0 / n),
                lambda x, n=n: x ** ((1.0 - n) / n) / n,
                (1.0, 100.0),
                1.1,
                lambda x, n=n: mp.root(x, n) - mp.root(n, n),
                float(n),
            )
        )

    def f13(x: float) -> float:
        if x == 0.0:
            return 0.0
        y = 1.0 / (x * x)
        return 0.0 if y > 709.0 else x / exp(y)

    out.append(("aps13", f13, None, (-1.0, 4.0), 1.5, None, 0.0))
    for n in range(1, 41):
        out.append(
            (
                f"aps14.{n}",
                lambda x, n=n: -n / 20.0 if x <= 0 else n / 20.0 * (x / 1.5 + sin(x) - 1),
                None,
                (-1e4, math.pi / 2),
                1.0,
                lambda x, n=n: n / 20.0 * (x / 1.5 + mp.sin(x) - 1),
                None,
            )
        )
    for n in list(range(20, 41)) + list(range(100, 1001, 100)):

        def f15(x: float, n: int = n) -> float:
            if x < 0:
                return -0.859
            if x > 2e-3 / (1 + n):
                return math.e - 1.859
            return exp((n + 1) * x / 2 * 1000) - 1.859

        out.append((f"aps15.{n}", f15, None, (-1e4, 1e-4), -2.0, None, math.log(1.859) / (500.0 * (n + 1))))
    return out


def _chandrupatla_cases() -> list[
    tuple[str, Callable[[float], float], tuple[float, float], Any, float | None]
]:
    import mpmath as mp

    exp = math.exp
    xi = 0.61489
    funs: list[tuple[str, Callable[[float], float], Any, float | None, list[tuple[float, float]]]] = [
        (
            "fun1",
            lambda x: x**3 - 2 * x - 5,
            lambda x: x**3 - 2 * x - 5,
            None,
            [(2, 3), (1, 10), (1, 100), (-1e4, 1e4), (-1e10, 1e10)],
        ),
        (
            "fun2",
            lambda x: 1 - 1 / x**2,
            None,
            1.0,
            [(0.5, 1.51), (1e-4, 1e4), (1e-6, 1e6), (1e-10, 1e10), (1e-12, 1e12)],
        ),
        (
            "fun3",
            lambda x: (x - 3) ** 3,
            None,
            3.0,
            [(0, 5), (-10, 10), (-1e4, 1e4), (-1e6, 1e6), (-1e10, 1e10)],
        ),
        (
            "fun4",
            lambda x: 6 * (x - 2) ** 5,
            None,
            2.0,
            [(0, 5), (-10, 10), (-1e4, 1e4), (-1e6, 1e6), (-1e10, 1e10)],
        ),
        ("fun5", lambda x: x**9, None, 0.0, [(-1, 4), (-2, 5), (-1, 10), (-5, 50), (-10, 100)]),
        ("fun6", lambda x: x**19, None, 0.0, [(-1, 4), (-2, 5), (-1, 10), (-5, 50), (-10, 100)]),
        (
            "fun7",
            lambda x: 0.0 if abs(x) < 3.8e-4 else x * exp(-(x**-2)),
            None,
            0.0,
            [(-1, 4), (-2, 5), (-1, 10), (-5, 50), (-10, 100)],
        ),
        (
            "fun8",
            lambda x: -(3062 * (1 - xi) * exp(-x)) / (xi + (1 - xi) * exp(-x)) - 1013 + 1628 / x,
            lambda x: -(3062 * (1 - xi) * mp.exp(-x)) / (xi + (1 - xi) * mp.exp(-x)) - 1013 + 1628 / x,
            None,
            [(2e-4, 2), (2e-4, 3), (2e-4, 9), (2e-4, 27), (2e-4, 81)],
        ),
        (
            "fun9",
            lambda x: exp(x) - 2 - 0.01 / x**2 + 0.000002 / x**3,
            lambda x: mp.exp(x) - 2 - mp.mpf("0.01") / x**2 + mp.mpf("0.000002") / x**3,
            None,
            [(2e-4, 1), (2e-4, 3), (2e-4, 9), (2e-4, 27), (2e-4, 81)],
        ),
    ]
    out = []
    for name, f, fmp, root, brackets in funs:
        for k, br in enumerate(brackets):
            out.append((f"{name}.{k + 1}", f, (float(br[0]), float(br[1])), fmp, root))
    return out


def mp_root(fmp: Callable[[Any], Any], a: float, b: float) -> float:
    """The root in [a, b] by 200 bisections at 60 digits: slow, and obviously right."""
    import mpmath as mp

    with mp.workdps(60):
        lo, hi = mp.mpf(a), mp.mpf(b)
        flo = fmp(lo)
        if flo == 0:
            return float(lo)
        for _ in range(200):
            mid = (lo + hi) / 2
            fm = fmp(mid)
            if fm == 0:
                return float(mid)
            if (fm < 0) == (flo < 0):
                lo, flo = mid, fm
            else:
                hi = mid
        return float((lo + hi) / 2)


def classic_cases() -> list[Case]:
    cases = []
    for name, f, fp, br, x0, fmp, root in _aps_cases():
        r = root if root is not None else mp_root(fmp, *br)
        cases.append(Case("classic", name, f, fp, br, x0, None, (r,), tol=1e-300, rtol=4 * EPS))
    for name, f, br, fmp, root in _chandrupatla_cases():
        r = root if root is not None else mp_root(fmp, *br)
        cases.append(Case("classic", name, f, None, br, None, None, (r,), tol=1e-300, rtol=4 * EPS))
    cases += [
        Case(
            "classic",
            "jump at 1",
            lambda x: (-1.0 if x < 1 else 1.0) + 0.1 * x,
            None,
            (0.5, 1.7),
            None,
            None,
            (),
            note="f jumps across zero at x = 1 without being zero: no root",
        ),
        Case(
            "classic",
            "pole at 1",
            lambda x: 1.0 / (1.0 - x) if x != 1 else math.inf,
            None,
            (0.3, 1.9),
            None,
            None,
            (),
            note="f changes sign through a pole: no root",
        ),
        Case(
            "classic",
            "triple root",
            lambda x: (x - 1.5) ** 3,
            lambda x: 3 * (x - 1.5) ** 2,
            (0.0, 4.0),
            3.0,
            None,
            (1.5,),
            tol=1e-12,
        ),
    ]
    return cases
