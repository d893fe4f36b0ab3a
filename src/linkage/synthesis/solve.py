"""Freudenstein's equation run backwards: the precision points' spacing, the linear system
for (R1, R2, R3), the real linkage of a solution, and the rules a design is judged by (its
transmission angle, its branch, whether it assembles), each with its numpy twin beside it
for the search (docs/synthesis.md)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..errors import InputError
from ..records import frozen
from ..units import degrees, radians
from .request import BRANCH_TOL_DEG, Request


@frozen
class Linkage:
    """The real linkage of a solution: positive lengths (input a, coupler b, output c,
    ground d) and whether the input or output link is drawn the other way (a negative R2
    or R1 is a link turned by 180 deg: its angle is alpha + 180 or phi + 180)."""

    a: float
    b: float
    c: float
    d: float
    input_turned: bool
    output_turned: bool

    @property
    def coefficients(self) -> tuple[float, float, float]:
        """R1, R2, R3 of the real linkage (its own angles: alpha', phi')."""
        return real_coefficients(self.a, self.b, self.c, self.d)

    def alpha_shift(self) -> float:
        return 180.0 if self.input_turned else 0.0

    def phi_shift(self) -> float:
        return 180.0 if self.output_turned else 0.0


def real_coefficients(a: Any, b: Any, c: Any, d: Any) -> tuple[Any, Any, Any]:
    """R1 = d/c, R2 = d/a, R3 = (a^2 - b^2 + c^2 + d^2) / (2ac) of positive lengths: numbers
    or arrays alike (the same operations either way)."""
    return d / c, d / a, (a * a - b * b + c * c + d * d) / (2.0 * a * c)



def chebyshev_xs(n: int, lo: float, hi: float) -> list[float]:
    """Chebyshev spacing: x_j = (lo + hi)/2 - (hi - lo)/2 cos((2j - 1) pi / (2n)), ascending."""
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    return [mid - half * math.cos((2 * j - 1) * math.pi / (2 * n)) for j in range(1, n + 1)]


def uniform_xs(n: int, lo: float, hi: float) -> list[float]:
    """Equal steps with both ends included."""
    return [lo + (hi - lo) * j / (n - 1) for j in range(n)]


def precision_xs(req: Request) -> list[float]:
    if req.at is not None:
        return list(req.at)
    lo, hi = req.x_range
    return uniform_xs(req.points, lo, hi) if req.spacing == "uniform" else chebyshev_xs(req.points, lo, hi)


def system(alphas_deg: Sequence[float], phis_deg: Sequence[float]) -> tuple[list[list[float]], list[float]]:
    """Freudenstein's equation at each point as a row of A R = b:
    [cos alpha, -cos phi, 1] . (R1, R2, R3) = cos(alpha - phi)."""
    rows, rhs = [], []
    for al, ph in zip(alphas_deg, phis_deg):
        a, p = radians(al), radians(ph)
        rows.append([math.cos(a), -math.cos(p), 1.0])
        rhs.append(math.cos(a - p))
    return rows, rhs


COND_LIMIT = 1e12


def solve_coefficients(
    alphas_deg: Sequence[float], phis_deg: Sequence[float]
) -> tuple[tuple[float, float, float], float]:
    """(R1, R2, R3) and the residual norm: three points solved exactly, more by least squares
    through a QR factorisation (never the normal equations, which square the condition)."""
    import numpy as np

    rows, rhs = system(alphas_deg, phis_deg)
    a, b = np.array(rows), np.array(rhs)
    cond = np.linalg.cond(a)
    if not np.isfinite(cond) or cond > COND_LIMIT:
        raise InputError(
            f"the precision points give a singular system for R1, R2, R3 (condition "
            f"number {cond:.3g}): move them apart or change the angle ranges"
        )
    if len(rows) == 3:
        r = np.linalg.solve(a, b)
    else:
        q, tri = np.linalg.qr(a)
        r = np.linalg.solve(tri, q.T @ b)
    residual = float(np.linalg.norm(a @ r - b))
    return (float(r[0]), float(r[1]), float(r[2])), residual


def solve_coefficients_np(alphas_deg: Any, phis_deg: Any) -> Any:
    """:func:`solve_coefficients` for many candidates at once (three points each): arrays
    of shape (n, 3) in, (n, 3) of R out; NaN rows where the system is singular."""
    import numpy as np

    a, p = radians(alphas_deg), radians(phis_deg)
    mat = np.stack([np.cos(a), -np.cos(p), np.ones_like(a)], axis=-1)
    rhs = np.cos(a - p)
    cond = np.linalg.cond(mat)
    good = np.isfinite(cond) & (cond <= COND_LIMIT)
    out = np.full(a.shape, np.nan)
    if good.any():
        out[good] = np.linalg.solve(mat[good], rhs[good][..., None])[..., 0]
    return out


ZERO_R = 1e-12
"""R1 or R2 within this (relative to the largest R, or 1) of zero is zero: a link 1e12
grounds long is no link."""


def linkage_of(r: Sequence[float], ground: float) -> tuple[Linkage | None, str | None]:
    """The real linkage of (R1, R2, R3) for a ground ``ground``, or None and why not.
    R1 = d/c, R2 = d/a, R3 = (a^2 - b^2 + c^2 + d^2) / (2ac) with a, c signed: a negative
    one is the link drawn the other way (length |a|, angle + 180 deg)."""
    r1, r2, r3 = r
    if not all(math.isfinite(v) for v in r):
        return None, "R1, R2, R3 are not finite"
    tiny = ZERO_R * max(1.0, abs(r1), abs(r2), abs(r3))
    if abs(r1) <= tiny or abs(r2) <= tiny:
        # said as 0, which by ZERO_R it is: its rounding (a sign, 1e-16) is the LAPACK
        # kernel's, different from one CPU to another
        which = "output link (R1 = 0)" if abs(r1) <= tiny else "input link (R2 = 0)"
        return None, f"the {which} would be infinitely long: R = d / length is zero to rounding"
    d = ground
    a, c = d / r2, d / r1
    b2 = a * a + c * c + d * d - 2.0 * a * c * r3
    if not b2 > 0.0:
        return None, (
            f"the coupler's squared length b^2 = a^2 + c^2 + d^2 - 2 a c R3 = {b2:.6g} is "
            "not positive: no real linkage fits these precision points"
        )
    return Linkage(abs(a), math.sqrt(b2), abs(c), d, a < 0.0, c < 0.0), None


def linkage_of_np(r: Any, ground: float) -> tuple[Any, Any, Any, Any, Any, Any]:
    """:func:`linkage_of` over rows of R: (a, b, c, d, input_turned, output_turned), NaN
    lengths where there is no real linkage."""
    import numpy as np

    r1, r2, r3 = r[..., 0], r[..., 1], r[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        a, c = ground / r2, ground / r1
        b2 = a * a + c * c + ground * ground - 2.0 * a * c * r3
        tiny = ZERO_R * np.maximum(1.0, np.maximum(np.abs(r1), np.maximum(np.abs(r2), np.abs(r3))))
        ok = np.isfinite(a) & np.isfinite(c) & (np.abs(r1) > tiny) & (np.abs(r2) > tiny) & (b2 > 0.0)
        b = np.where(ok, np.sqrt(np.where(ok, b2, 1.0)), np.nan)
    return (
        np.where(ok, np.abs(a), np.nan),
        b,
        np.where(ok, np.abs(c), np.nan),
        np.full(a.shape, float(ground)),
        a < 0.0,
        c < 0.0,
    )


def transmission_deg(k: Linkage, alpha_real_deg: float, phi_real_deg: float) -> float:
    """The transmission angle (deg, folded into 0..90) of the real linkage at its own angles:
    between the coupler A -> B and the output link O4 -> B (closed_form.transmission), with O4 at
    the origin, O2 at (d, 0), A = O2 + a e^(i alpha'), B = c e^(i phi')."""
    from ..problems.closed_form import transmission

    a_pt = complex(k.d, 0.0) + k.a * complex(
        math.cos(radians(alpha_real_deg)), math.sin(radians(alpha_real_deg))
    )
    b_pt = k.c * complex(math.cos(radians(phi_real_deg)), math.sin(radians(phi_real_deg)))
    t3 = degrees(math.atan2((b_pt - a_pt).imag, (b_pt - a_pt).real))
    return transmission(t3, phi_real_deg)


def transmission_deg_np(a: Any, c: Any, d: Any, alpha_real_deg: Any, phi_real_deg: Any) -> Any:
    """:func:`transmission_deg` over arrays."""
    import numpy as np

    from ..problems.closed_form import transmission_np

    al, ph = radians(alpha_real_deg), radians(phi_real_deg)
    ax, ay = d + a * np.cos(al), a * np.sin(al)
    bx, by = c * np.cos(ph), c * np.sin(ph)
    t3 = degrees(np.arctan2(by - ay, bx - ax))
    return transmission_np(t3, phi_real_deg)


def branch_label(k: Linkage, alpha_real_deg: float, phi_real_deg: float) -> str:
    """open or crossed (the project's words, problems.assembly) of a real position."""
    from ..problems.freudenstein import file_convention

    return str(file_convention(alpha_real_deg, phi_real_deg, (k.a, k.b, k.c, k.d))["branch"])


def off_branch(alpha_real_deg: float, phi_real_deg: float, real_r: Sequence[float], sign: float) -> bool:
    """Whether a precision point (its real angles) lies on the other assembly than the
    branch ``sign`` (freudenstein.branch_root) followed from point 1, reached or not: its
    own root (the one on its phi's side, freudenstein.branch_sign: the point itself for an
    exact fit, the nearer root for least squares, whose points lie off the linkage by the
    fit's error) and the followed branch's root differ by more than BRANCH_TOL_DEG. At a
    limit position the two meet (no defect); where the linkage cannot be assembled at
    all there is neither (the grashof defect says so)."""
    from ..problems.freudenstein import branch_root, branch_sign

    own = branch_sign(alpha_real_deg, phi_real_deg, *real_r)
    if own == sign:
        return False
    apart = math.remainder(
        branch_root(alpha_real_deg, *real_r, own) - branch_root(alpha_real_deg, *real_r, sign), 360.0
    )
    return abs(apart) > BRANCH_TOL_DEG


def off_branch_np(alpha_real_deg: Any, phi_real_deg: Any, r1: Any, r2: Any, r3: Any, sign: Any) -> Any:
    """:func:`off_branch` over arrays (broadcast)."""
    import numpy as np

    from ..problems.freudenstein import branch_root_np, branch_sign_np

    own = branch_sign_np(alpha_real_deg, phi_real_deg, r1, r2, r3)
    apart = branch_root_np(alpha_real_deg, r1, r2, r3, own) - branch_root_np(alpha_real_deg, r1, r2, r3, sign)
    with np.errstate(invalid="ignore"):
        return (own != sign) & (np.abs(np.remainder(apart + 180.0, 360.0) - 180.0) > BRANCH_TOL_DEG)


def grashof_of(k: Linkage) -> str:
    from ..problems.closed_form import grashof

    return grashof(k.d, k.a, k.b, k.c)


def assembly_gap(real_r: Sequence[float], alpha0_deg: float, alpha1_deg: float) -> bool:
    """Whether the linkage of ``real_r`` cannot be assembled somewhere in the input range
    (its own alpha, either order), between grid points or not: it assembles at alpha iff
    |K| <= |(R2 + cos a, sin a)| (freudenstein.branch_root), i.e. iff
    g(cos a) = 1 + R2^2 + 2 R2 cos a - (R1 cos a + R3)^2 >= 0, a parabola in cos a opening
    downwards, so its least over the range is at the least or the greatest cos a there."""
    r1, r2, r3 = real_r
    lo, hi = sorted((alpha0_deg, alpha1_deg))
    ends = (math.cos(radians(lo)), math.cos(radians(hi)))
    top = 1.0 if math.floor(hi / 360.0) >= math.ceil(lo / 360.0) else max(ends)
    bottom = -1.0 if math.floor((hi - 180.0) / 360.0) >= math.ceil((lo - 180.0) / 360.0) else min(ends)
    return min(1.0 + r2 * r2 + 2.0 * r2 * c - (r1 * c + r3) ** 2 for c in (bottom, top)) < 0.0


def assembly_gap_np(r1: Any, r2: Any, r3: Any, alpha0_deg: Any, alpha1_deg: Any) -> Any:
    """:func:`assembly_gap` over arrays."""
    import numpy as np

    lo, hi = np.minimum(alpha0_deg, alpha1_deg), np.maximum(alpha0_deg, alpha1_deg)
    c_lo, c_hi = np.cos(radians(lo)), np.cos(radians(hi))
    top = np.where(np.floor(hi / 360.0) >= np.ceil(lo / 360.0), 1.0, np.maximum(c_lo, c_hi))
    bottom = np.where(
        np.floor((hi - 180.0) / 360.0) >= np.ceil((lo - 180.0) / 360.0), -1.0, np.minimum(c_lo, c_hi)
    )

    def g(c: Any) -> Any:
        return 1.0 + r2 * r2 + 2.0 * r2 * c - (r1 * c + r3) ** 2

    with np.errstate(invalid="ignore"):
        return np.minimum(g(bottom), g(top)) < 0.0



