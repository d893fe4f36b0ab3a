"""The Moré-Garbow-Hillstrom square systems: MINPACK's test set for hybrd/hybrj.

J. J. Moré, B. S. Garbow, K. E. Hillstrom, "Testing unconstrained optimization
software", ACM TOMS 7 (1981), problems in the form MINPACK's hybrd tests use them:
22 (problem, n) pairs, each from the standard start x0 scaled by 1, 10 and 100
(a zero start scaled by s becomes s in every coordinate): 66 cases. Every residual
has its exact Jacobian, written out here from the definitions.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from ..records import frozen

Vec = list[float]


@frozen
class SquareSystem:
    name: str
    n: int
    F: Callable[[Vec], Vec]
    J: Callable[[Vec], list[Vec]]
    x0: tuple[float, ...]

    def start(self, factor: float) -> tuple[float, ...]:
        if factor == 1.0:
            return self.x0
        if all(v == 0.0 for v in self.x0):
            return tuple(factor for _ in self.x0)
        return tuple(factor * v for v in self.x0)


def _zeros(n: int) -> list[Vec]:
    return [[0.0] * n for _ in range(n)]


def rosenbrock() -> SquareSystem:
    def F(x: Vec) -> Vec:
        return [10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]]

    def J(x: Vec) -> list[Vec]:
        return [[-20.0 * x[0], 10.0], [-1.0, 0.0]]

    return SquareSystem("Rosenbrock", 2, F, J, (-1.2, 1.0))


def powell_singular() -> SquareSystem:
    r5, r10 = math.sqrt(5.0), math.sqrt(10.0)

    def F(x: Vec) -> Vec:
        return [x[0] + 10.0 * x[1], r5 * (x[2] - x[3]), (x[1] - 2.0 * x[2]) ** 2, r10 * (x[0] - x[3]) ** 2]

    def J(x: Vec) -> list[Vec]:
        a, b = 2.0 * (x[1] - 2.0 * x[2]), 2.0 * r10 * (x[0] - x[3])
        return [[1.0, 10.0, 0.0, 0.0], [0.0, 0.0, r5, -r5], [0.0, a, -2.0 * a, 0.0], [b, 0.0, 0.0, -b]]

    return SquareSystem("Powell singular", 4, F, J, (3.0, -1.0, 0.0, 1.0))


def powell_badly_scaled() -> SquareSystem:
    def F(x: Vec) -> Vec:
        return [1e4 * x[0] * x[1] - 1.0, math.exp(-x[0]) + math.exp(-x[1]) - 1.0001]

    def J(x: Vec) -> list[Vec]:
        return [[1e4 * x[1], 1e4 * x[0]], [-math.exp(-x[0]), -math.exp(-x[1])]]

    return SquareSystem("Powell badly scaled", 2, F, J, (0.0, 1.0))


def wood() -> SquareSystem:
    def F(x: Vec) -> Vec:
        t1, t2 = x[1] - x[0] ** 2, x[3] - x[2] ** 2
        return [-200.0 * x[0] * t1 - (1.0 - x[0]),
                200.0 * t1 + 20.2 * (x[1] - 1.0) + 19.8 * (x[3] - 1.0),
                -180.0 * x[2] * t2 - (1.0 - x[2]),
                180.0 * t2 + 20.2 * (x[3] - 1.0) + 19.8 * (x[1] - 1.0)]

    def J(x: Vec) -> list[Vec]:
        j = _zeros(4)
        j[0][0] = -200.0 * (x[1] - 3.0 * x[0] ** 2) + 1.0
        j[0][1] = -200.0 * x[0]
        j[1][0] = -400.0 * x[0]
        j[1][1] = 220.2
        j[1][3] = 19.8
        j[2][2] = -180.0 * (x[3] - 3.0 * x[2] ** 2) + 1.0
        j[2][3] = -180.0 * x[2]
        j[3][2] = -360.0 * x[2]
        j[3][3] = 200.2
        j[3][1] = 19.8
        return j

    return SquareSystem("Wood", 4, F, J, (-3.0, -1.0, -3.0, -1.0))


def helical_valley() -> SquareSystem:
    tpi = 2.0 * math.pi

    def theta(x: Vec) -> float:
        if x[0] > 0.0:
            return math.atan(x[1] / x[0]) / tpi
        if x[0] < 0.0:
            return math.atan(x[1] / x[0]) / tpi + 0.5
        return math.copysign(0.25, x[1])

    def F(x: Vec) -> Vec:
        return [10.0 * (x[2] - 10.0 * theta(x)), 10.0 * (math.hypot(x[0], x[1]) - 1.0), x[2]]

    def J(x: Vec) -> list[Vec]:
        r2 = x[0] ** 2 + x[1] ** 2
        r = math.sqrt(r2)
        return [[100.0 * x[1] / (tpi * r2), -100.0 * x[0] / (tpi * r2), 10.0],
                [10.0 * x[0] / r, 10.0 * x[1] / r, 0.0],
                [0.0, 0.0, 1.0]]

    return SquareSystem("Helical valley", 3, F, J, (-1.0, 0.0, 0.0))


def watson(n: int) -> SquareSystem:
    """The gradient of Watson's sum of squares; its Jacobian is that sum's Hessian."""
    ts = [i / 29.0 for i in range(1, 30)]

    def parts(x: Vec) -> list[tuple[float, Vec, float]]:
        # (r_i, dr_i/dx, weight of the rank-one second derivative -2 p p^T)
        out = []
        for t in ts:
            p = [t ** j for j in range(n)]  # t^(j-1), j = 1..n
            s1 = sum((j) * x[j] * t ** (j - 1) for j in range(1, n))
            s2 = sum(x[j] * p[j] for j in range(n))
            r = s1 - s2 * s2 - 1.0
            dr = [(j * t ** (j - 1) if j >= 1 else 0.0) - 2.0 * s2 * p[j] for j in range(n)]
            out.append((r, dr, t))
        return out

    def F(x: Vec) -> Vec:
        g = [0.0] * n
        for r, dr, _ in parts(x):
            for j in range(n):
                g[j] += r * dr[j]
        r30, r31 = x[0], x[1] - x[0] ** 2 - 1.0
        g[0] += r30 - 2.0 * x[0] * r31
        g[1] += r31
        return g

    def J(x: Vec) -> list[Vec]:
        h = _zeros(n)
        for r, dr, t in parts(x):
            p = [t ** j for j in range(n)]
            for j in range(n):
                for k in range(n):
                    h[j][k] += dr[j] * dr[k] - 2.0 * r * p[j] * p[k]
        r31 = x[1] - x[0] ** 2 - 1.0
        h[0][0] += 1.0 + 4.0 * x[0] ** 2 - 2.0 * r31
        h[0][1] += -2.0 * x[0]
        h[1][0] += -2.0 * x[0]
        h[1][1] += 1.0
        return h

    return SquareSystem(f"Watson n={n}", n, F, J, tuple(0.0 for _ in range(n)))


def chebyquad(n: int) -> SquareSystem:
    def cheb(y: float) -> tuple[Vec, Vec]:
        # T_1..T_n at y and their derivatives
        t = [1.0, y]
        d = [0.0, 1.0]
        for k in range(2, n + 1):
            t.append(2.0 * y * t[k - 1] - t[k - 2])
            d.append(2.0 * t[k - 1] + 2.0 * y * d[k - 1] - d[k - 2])
        return t[1:], d[1:]

    def F(x: Vec) -> Vec:
        f = [0.0] * n
        for xj in x:
            t, _ = cheb(2.0 * xj - 1.0)
            for i in range(n):
                f[i] += t[i] / n
        for i in range(n):
            k = i + 1
            if k % 2 == 0:
                f[i] += 1.0 / (k * k - 1.0)
        return f

    def J(x: Vec) -> list[Vec]:
        j = _zeros(n)
        for c, xj in enumerate(x):
            _, d = cheb(2.0 * xj - 1.0)
            for i in range(n):
                j[i][c] = 2.0 * d[i] / n
        return j

    return SquareSystem(f"Chebyquad n={n}", n, F, J, tuple((j + 1) / (n + 1) for j in range(n)))


def brown_almost_linear(n: int = 10) -> SquareSystem:
    def F(x: Vec) -> Vec:
        s = sum(x)
        f = [x[i] + s - (n + 1) for i in range(n - 1)]
        return [*f, math.prod(x) - 1.0]

    def J(x: Vec) -> list[Vec]:
        j = [[2.0 if c == i else 1.0 for c in range(n)] for i in range(n - 1)]
        last = []
        for c in range(n):
            p = 1.0
            for k in range(n):
                if k != c:
                    p *= x[k]
            last.append(p)
        return [*j, last]

    return SquareSystem(f"Brown almost-linear n={n}", n, F, J, tuple(0.5 for _ in range(n)))


def discrete_boundary(n: int = 10) -> SquareSystem:
    h = 1.0 / (n + 1)

    def F(x: Vec) -> Vec:
        out = []
        for i in range(n):
            t = (i + 1) * h
            left = x[i - 1] if i > 0 else 0.0
            right = x[i + 1] if i < n - 1 else 0.0
            out.append(2.0 * x[i] - left - right + h * h * (x[i] + t + 1.0) ** 3 / 2.0)
        return out

    def J(x: Vec) -> list[Vec]:
        j = _zeros(n)
        for i in range(n):
            t = (i + 1) * h
            j[i][i] = 2.0 + 1.5 * h * h * (x[i] + t + 1.0) ** 2
            if i > 0:
                j[i][i - 1] = -1.0
            if i < n - 1:
                j[i][i + 1] = -1.0
        return j

    return SquareSystem(f"Discrete boundary value n={n}", n, F, J,
                        tuple((i + 1) * h * ((i + 1) * h - 1.0) for i in range(n)))


def discrete_integral(n: int = 10) -> SquareSystem:
    h = 1.0 / (n + 1)
    ts = [(i + 1) * h for i in range(n)]

    def F(x: Vec) -> Vec:
        cubes = [(x[j] + ts[j] + 1.0) ** 3 for j in range(n)]
        out = []
        for i in range(n):
            a = sum(ts[j] * cubes[j] for j in range(i + 1))
            b = sum((1.0 - ts[j]) * cubes[j] for j in range(i + 1, n))
            out.append(x[i] + h * ((1.0 - ts[i]) * a + ts[i] * b) / 2.0)
        return out

    def J(x: Vec) -> list[Vec]:
        sq = [3.0 * (x[j] + ts[j] + 1.0) ** 2 for j in range(n)]
        j = _zeros(n)
        for i in range(n):
            for c in range(n):
                w = (1.0 - ts[i]) * ts[c] if c <= i else ts[i] * (1.0 - ts[c])
                j[i][c] = h * w * sq[c] / 2.0 + (1.0 if c == i else 0.0)
        return j

    return SquareSystem(f"Discrete integral equation n={n}", n, F, J,
                        tuple(t * (t - 1.0) for t in ts))


def trigonometric(n: int = 10) -> SquareSystem:
    def F(x: Vec) -> Vec:
        s = sum(math.cos(v) for v in x)
        return [n - s + (i + 1) * (1.0 - math.cos(x[i])) - math.sin(x[i]) for i in range(n)]

    def J(x: Vec) -> list[Vec]:
        j = [[math.sin(x[c]) for c in range(n)] for _ in range(n)]
        for i in range(n):
            j[i][i] += (i + 1) * math.sin(x[i]) - math.cos(x[i])
        return j

    return SquareSystem(f"Trigonometric n={n}", n, F, J, tuple(1.0 / n for _ in range(n)))


def variably_dimensioned(n: int = 10) -> SquareSystem:
    def F(x: Vec) -> Vec:
        s = sum((j + 1) * (x[j] - 1.0) for j in range(n))
        t = s * (1.0 + 2.0 * s * s)
        return [x[i] - 1.0 + (i + 1) * t for i in range(n)]

    def J(x: Vec) -> list[Vec]:
        s = sum((j + 1) * (x[j] - 1.0) for j in range(n))
        dt = 1.0 + 6.0 * s * s
        return [[(i + 1) * (c + 1) * dt + (1.0 if c == i else 0.0) for c in range(n)] for i in range(n)]

    return SquareSystem(f"Variably dimensioned n={n}", n, F, J, tuple(1.0 - (j + 1) / n for j in range(n)))


def broyden_tridiagonal(n: int = 10) -> SquareSystem:
    def F(x: Vec) -> Vec:
        return [(3.0 - 2.0 * x[i]) * x[i] - (x[i - 1] if i > 0 else 0.0)
                - 2.0 * (x[i + 1] if i < n - 1 else 0.0) + 1.0 for i in range(n)]

    def J(x: Vec) -> list[Vec]:
        j = _zeros(n)
        for i in range(n):
            j[i][i] = 3.0 - 4.0 * x[i]
            if i > 0:
                j[i][i - 1] = -1.0
            if i < n - 1:
                j[i][i + 1] = -2.0
        return j

    return SquareSystem(f"Broyden tridiagonal n={n}", n, F, J, tuple(-1.0 for _ in range(n)))


def broyden_banded(n: int = 10) -> SquareSystem:
    def band(i: int) -> range:
        return range(max(0, i - 5), min(n, i + 2))

    def F(x: Vec) -> Vec:
        return [x[i] * (2.0 + 5.0 * x[i] ** 2) + 1.0 - sum(x[j] * (1.0 + x[j]) for j in band(i) if j != i)
                for i in range(n)]

    def J(x: Vec) -> list[Vec]:
        j = _zeros(n)
        for i in range(n):
            for c in band(i):
                j[i][c] = 2.0 + 15.0 * x[i] ** 2 if c == i else -(1.0 + 2.0 * x[c])
        return j

    return SquareSystem(f"Broyden banded n={n}", n, F, J, tuple(-1.0 for _ in range(n)))


def mgh_systems() -> tuple[SquareSystem, ...]:
    """The 22 (problem, n) pairs of MINPACK's hybrd tests."""
    return (rosenbrock(), powell_singular(), powell_badly_scaled(), wood(), helical_valley(),
            watson(6), watson(9), *(chebyquad(n) for n in (1, 2, 3, 4, 5, 6, 7, 9)),
            brown_almost_linear(10), discrete_boundary(10), discrete_integral(10), trigonometric(10),
            variably_dimensioned(10), broyden_tridiagonal(10), broyden_banded(10))


FACTORS = (1.0, 10.0, 100.0)


def mgh_cases() -> list[tuple[str, SquareSystem, float]]:
    """The 66 cases: (label, system, start factor)."""
    return [(f"{s.name} x{factor:g}", s, factor) for s in mgh_systems() for factor in FACTORS]
