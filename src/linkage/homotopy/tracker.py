"""Path tracking for polynomial homotopies, every path of a homotopy as one numpy block.

H(X, t) = (1 - t) gamma G(X) + t F(X), with G a start system whose roots are known and
gamma a random complex number (the gamma trick: for all but finitely many gamma, no path
meets a singularity for t in [0, 1)). Points are projective, X = (X0, X1, ..., Xn), held
on a random affine patch a.X = 1, so a path going to infinity stays bounded. Each step
predicts with the classical fourth-order Runge-Kutta method along dX/dt = -H_X^-1 H_t and
corrects with Newton's method at the new t; a step whose corrector does not converge in
three iterations, or jumps, is halved (Sommese and Wampler 2005, ch. 2; Bertini's tracker,
Bates, Hauenstein, Sommese and Wampler, *Numerically Solving Polynomial Systems with
Bertini*, SIAM 2013, ch. 2). Near t = 1 the Cauchy endgame takes over (:mod:`.endgame`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..records import frozen
from .polynomials import HomogeneousForm
from .start import LinearProduct

CORRECTOR_TOL = 1e-11
"""A corrector has converged when its last Newton step is this small against |X|."""
CORRECTOR_STEPS = 3
MIN_STEP = 1e-13
MAX_STEPS = 20_000
"""Steps a path may take before it is called failed (a path wandering near a singularity)."""
UNDERFLOW, TOO_MANY_STEPS = 1, 2
"""A failed path's cause in :attr:`PathLog.cause` (0: it has not failed here): its step
size fell below MIN_STEP, or it took MAX_STEPS steps."""


class PathHomotopy(Protocol):
    """What the tracker and the endgame need of a homotopy: H on the patch with its
    Jacobians, and the target system (homogeneous) that t = 1 reaches."""

    target: HomogeneousForm

    def residual_and_jacobians(self, X: np.ndarray,
                               t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...

    def velocity(self, X: np.ndarray, t: np.ndarray, dt: np.ndarray) -> np.ndarray: ...


def velocity(h: PathHomotopy, X: np.ndarray, t: np.ndarray, dt: np.ndarray) -> np.ndarray:
    """dX along the path for a change dt of t: -H_X^-1 H_t dt (the patch held)."""
    _, J, Ht = h.residual_and_jacobians(X, t)
    return -solve_batched(J, Ht * dt[:, None])


@frozen
class Homotopy:
    """H(X, t) = (1 - t) gamma G + t F on the patch a.X = 1."""

    target: HomogeneousForm
    start: HomogeneousForm | LinearProduct
    gamma: complex
    patch: np.ndarray  # (n + 1,)

    def residual_and_jacobians(self, X: np.ndarray,
                               t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """[H; a.X - 1], its X-Jacobian (square, patch row last) and [H_t; 0]."""
        F, JF = self.target.both(X)
        G, JG = self.start.both(X)
        s = (1.0 - t)[:, None] * self.gamma
        H = s * G + t[:, None] * F
        Ht = F - self.gamma * G
        J = s[:, :, None] * JG + t[:, None, None] * JF
        P = X.shape[0]
        patch = np.broadcast_to(self.patch, (P, 1, X.shape[1]))
        return (np.concatenate([H, (X @ self.patch - 1.0)[:, None]], axis=1),
                np.concatenate([J, patch], axis=1),
                np.concatenate([Ht, np.zeros((P, 1), dtype=complex)], axis=1))

    def velocity(self, X: np.ndarray, t: np.ndarray, dt: np.ndarray) -> np.ndarray:
        return velocity(self, X, t, dt)


@dataclass
class PathLog:
    """What each path did: counts per path (arrays), and why a failed one failed (in words,
    and as a code, UNDERFLOW or TOO_MANY_STEPS, for callers that keep arrays)."""

    steps: np.ndarray
    rejected: np.ndarray
    newton: np.ndarray
    smallest_step: np.ndarray  # of the step sizes chosen for accepted steps (inf: none accepted)
    failure: list[str] = field(default_factory=list)
    cause: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int8))

    @classmethod
    def empty(cls, paths: int) -> PathLog:
        return cls(np.zeros(paths, int), np.zeros(paths, int), np.zeros(paths, int),
                   np.full(paths, np.inf), [""] * paths, np.zeros(paths, np.int8))


def solve_batched(J: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Batched solve; a singular matrix gives NaN for its path, not an exception."""
    try:
        return np.linalg.solve(J, b[..., None])[..., 0]
    except np.linalg.LinAlgError:
        out = np.full(b.shape, np.nan + 0j)
        for i in range(J.shape[0]):
            try:
                out[i] = np.linalg.solve(J[i], b[i])
            except np.linalg.LinAlgError:
                pass
        return out


def _norm(X: np.ndarray) -> np.ndarray:
    return np.sqrt((X.real ** 2 + X.imag ** 2).sum(axis=1))


def track(h: PathHomotopy, X: np.ndarray, tau: np.ndarray, tau_end: np.ndarray,
          t_of: Callable[[np.ndarray], np.ndarray], dt_of: Callable[[np.ndarray], np.ndarray],
          log: PathLog, index: np.ndarray, step: np.ndarray,
          max_step: float, corrector_tol: float = CORRECTOR_TOL) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Track paths ``index`` from parameter ``tau`` to ``tau_end`` (real; t = t_of(tau),
    dt/dtau = dt_of(tau)), with per-path step sizes ``step``. Returns (X, ok, step): a path
    that fails keeps its last point, ``ok`` False and its reason in ``log.failure``.
    ``corrector_tol``: a corrector has converged when its last step is this small against
    |X| (a path whose Jacobian's condition is k cannot be corrected below about k eps: a
    parameter homotopy of degree-8 equations, :mod:`.ninepoint`, needs 1e-9; Bertini's
    default is 1e-5 before its endgame)."""
    X = X.copy()
    tau = tau.astype(float).copy()
    step = np.minimum(step.astype(float).copy(), max_step)
    good = np.zeros(len(tau), int)
    ok = np.ones(len(tau), bool)
    active = tau < tau_end
    while active.any():
        a = np.flatnonzero(active)
        Xa, ta, ha = X[a], tau[a], np.minimum(step[a], tau_end[a] - tau[a])
        # fourth-order Runge-Kutta predictor
        k1 = h.velocity(Xa, t_of(ta), dt_of(ta))
        k2 = h.velocity(Xa + 0.5 * ha[:, None] * k1, t_of(ta + 0.5 * ha), dt_of(ta + 0.5 * ha))
        k3 = h.velocity(Xa + 0.5 * ha[:, None] * k2, t_of(ta + 0.5 * ha), dt_of(ta + 0.5 * ha))
        k4 = h.velocity(Xa + ha[:, None] * k3, t_of(ta + ha), dt_of(ta + ha))
        Xp = Xa + (ha / 6.0)[:, None] * (k1 + 2 * k2 + 2 * k3 + k4)
        t_new = t_of(ta + ha)
        size = _norm(Xp)
        moved = _norm(Xp - Xa)
        converged = np.zeros(len(a), bool)
        first = np.full(len(a), np.inf)
        last = np.full(len(a), np.inf)
        for it in range(CORRECTOR_STEPS):
            R, J, _ = h.residual_and_jacobians(Xp, t_new)
            dX = solve_batched(J, R)
            Xp = Xp - dX
            d = _norm(dX)
            if it == 0:
                first = d
            # a corrector that does not contract is heading for another path
            contracting = (it == 0) | (d <= 0.5 * last)
            last = np.where(contracting, d, np.inf)
            converged |= last <= corrector_tol * size
            log.newton[index[a]] += 1
            if converged.all():
                break
        # the predictor is fourth order: a first correction that is not small against the
        # step itself means the step left its path's neighbourhood (path jumping)
        accept = converged & np.isfinite(_norm(Xp)) & (first <= 0.25 * moved + corrector_tol * size)
        log.steps[index[a]] += 1
        acc, rej = a[accept], a[~accept]
        X[acc] = Xp[accept]
        tau[acc] = np.where(tau_end[acc] - (ta[accept] + ha[accept]) <= 1e-15 * np.abs(tau_end[acc]),
                            tau_end[acc], ta[accept] + ha[accept])
        # the step size chosen, not the step cut short to end at tau_end: a last step of the
        # rounding left over (1e-15) is no sign of a hard path
        log.smallest_step[index[acc]] = np.minimum(log.smallest_step[index[acc]], step[acc])
        good[acc] += 1
        grow = acc[good[acc] >= 3]
        step[grow] = np.minimum(2.0 * step[grow], max_step)
        good[grow] = 0
        step[rej] *= 0.5
        good[rej] = 0
        log.rejected[index[rej]] += 1
        for i in rej[step[rej] < MIN_STEP]:
            ok[i] = False
            where = complex(t_of(tau[i:i + 1])[0])
            log.failure[index[i]] = f"step size below {MIN_STEP:g} at t = {where:.6g}"
            log.cause[index[i]] = UNDERFLOW
        for i in a[log.steps[index[a]] >= MAX_STEPS]:
            if ok[i]:
                ok[i] = False
                log.failure[index[i]] = f"more than {MAX_STEPS} steps"
                log.cause[index[i]] = TOO_MANY_STEPS
        active = ok & (tau < tau_end)
    return X, ok, step
