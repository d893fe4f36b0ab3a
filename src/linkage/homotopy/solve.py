"""Every isolated solution of a square polynomial system: total-degree homotopy, the
Cauchy endgame, and each endpoint classified, refined and checked.

Each endpoint is one of
- ``finite``: a nonsingular solution, refined by Newton's method to full precision; its
  residual, its condition number and its distance from the nearest other solution are
  reported;
- ``singular``: a finite solution where the Jacobian is singular (a cycle number above 1,
  or a condition number above :data:`SINGULAR_CONDITION`): a double root, such as two
  assemblies meeting at a change point;
- ``infinite``: the path went to infinity (X0 -> 0 in projective coordinates): the
  system's total degree counts solutions that a mechanism does not have;
- ``failed``: the tracker could not follow the path (its reason is kept). A failed path is
  retracked with smaller steps before it is reported, and never dropped.

:attr:`Solutions.certificates` adds Smale's alpha test at each finite endpoint (:mod:`.alpha`),
computed when first asked for.

The Cauchy endgame (Morgan, Sommese and Wampler, "Computing singular solutions to
nonlinear analytic systems", Numer. Math. 58, 1991): near t = 1 a path is X(s) analytic
in s = (1 - t)^(1/c), c its cycle number; tracking t around circles |1 - t| = r until the
path closes gives c, and the mean of equally spaced samples over the c loops is the
trapezoid rule for Cauchy's integral, the endpoint X(1), to an error that falls
geometrically with the samples.
"""

from __future__ import annotations

import time
from functools import cached_property

import numpy as np

from ..records import frozen
from .alpha import Certificate, certify, has_real_structure, normalised, undistinguished
from .polynomials import PolySystem
from .start import start_for
from .tracker import Homotopy, PathHomotopy, PathLog, track

ENDGAME_RADIUS = 0.01
"""Where the endgame starts: t = 1 - ENDGAME_RADIUS."""
ENDGAME_SAMPLES = 8
"""Samples per loop around t = 1 (the trapezoid rule's error falls as r^samples)."""
MAX_CYCLE = 8
ENDGAME_RADII = 14
"""Radii tried, each a quarter of the last (down to 0.01 / 4^13 = 1.5e-10), until two in a
row give the same cycle number and agreeing estimates. Near a limit position two roots
nearly meet, and the homotopy's branch point lies about the gap from t = 1: a circle that
encloses it swaps the two paths (a false cycle number 2) until the radius falls below it."""
CLOSED = 1e-6
"""A loop around t = 1 has closed when the path is back within this of where it started."""
AGREE = 1e-9
"""Two endgame estimates agree when they differ by this against |X|."""
INFINITE = 1e-8
"""|X0| / |X| below this: the endpoint is at infinity."""
SINGULAR_CONDITION = 1e8
"""A finite solution whose condition (:func:`condition`) exceeds this is singular: a
double root computed in double precision sits about sqrt(eps) = 1.5e-8 from its twin, and
its condition is then about 1e8."""
REAL = 1e-9
"""A solution is real when it is within this of its conjugate (:meth:`PolySystem.realness`),
against max(1, |x|)."""


@frozen
class Endpoint:
    """Where one path ended, and what it is."""

    kind: str  # finite, singular, infinite, failed
    x: np.ndarray | None  # the affine point (complex), None at infinity or failed
    real: bool
    residual: float  # relative_residual: max |F_i(x)| / (F_i's terms' sizes at x)
    condition: float  # :func:`condition` at x (inf where singular or not finite)
    cycle: int  # the endgame's cycle number (0 where the path failed before it)
    steps: int
    rejected: int
    newton: int
    smallest_step: float
    retracked: bool
    note: str = ""
    endgame: bool = True  # the Cauchy endgame ran (False: tracked to t = 1 itself, nonsingular there)


@frozen
class Solutions:
    """Every path's endpoint, and the homotopy that made them."""

    system: PolySystem
    endpoints: tuple[Endpoint, ...]
    gamma: complex
    seconds: float
    start: str = "total degree"  # the start system: "total degree" or "linear product"

    @property
    def bezout(self) -> int:
        """The total-degree (Bezout) bound, whichever start was tracked."""
        return self.system.bezout

    @property
    def bound(self) -> int:
        """The start system's root count, the paths tracked: the bound on isolated roots."""
        return len(self.endpoints)

    def count(self, kind: str) -> int:
        return sum(e.kind == kind for e in self.endpoints)

    @property
    def finite(self) -> list[Endpoint]:
        return [e for e in self.endpoints if e.kind == "finite"]

    @property
    def real(self) -> list[Endpoint]:
        return [e for e in self.endpoints if e.kind in ("finite", "singular") and e.real]

    @cached_property
    def certificates(self) -> tuple[Certificate | None, ...]:
        """Smale's alpha test (:func:`.alpha.certify`, at 50 digits) at each finite endpoint,
        None at the others; computed when first asked for (a few milliseconds an endpoint, as
        much as the whole solve of a six-bar's assemblies)."""
        if not any(e.kind == "finite" for e in self.endpoints):
            return (None,) * len(self.endpoints)
        scaled, structure = normalised(self.system), has_real_structure(self.system)
        return tuple(certify(self.system, e.x, structure, scaled) if e.kind == "finite" and e.x is not None
                     else None for e in self.endpoints)

    @property
    def certified(self) -> list[tuple[Endpoint, Certificate]]:
        """The finite endpoints that the alpha test certifies, with their certificates."""
        return [(e, c) for e, c in zip(self.endpoints, self.certificates) if c is not None and c.certified]

    @property
    def undistinguished(self) -> list[tuple[int, int]]:
        """Pairs among :attr:`certified` (indices into it) that the alpha test cannot tell
        apart: empty when every certified root is certainly a different root."""
        pairs = self.certified
        return undistinguished([e.x for e, _ in pairs], [c for _, c in pairs])  # type: ignore[misc]


def _norm(X: np.ndarray) -> np.ndarray:
    return np.sqrt((np.abs(X) ** 2).sum(axis=-1))


SINGULAR_RESIDUAL = 1e-7
"""A singular endpoint's relative residual: a double root is found to about sqrt(eps)."""


def _projective_residual(h: PathHomotopy, X: np.ndarray) -> np.ndarray:
    """max_i |F_i(X)| / (sum |coefficients of F_i| |X|^d_i), F the target system."""
    F = h.target.evaluate(X)
    size = _norm(X)
    coef = np.abs(h.target.coefficients).sum(axis=1)
    degree = h.target.exponents.sum(axis=1).max(initial=1)
    return (np.abs(F) / (coef[None, :] * size[:, None] ** degree)).max(axis=1)


def _endgame(h: PathHomotopy, X: np.ndarray, index: np.ndarray, log: PathLog, step: np.ndarray,
             max_step: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cauchy's endgame for paths at t = 1 - ENDGAME_RADIUS: (estimates, cycle numbers, ok).
    Around a circle the steps are in its angle, up to one sample's arc; along the real line
    between radii, in t, up to the radius itself."""
    P = len(index)
    estimate = np.full(X.shape, np.nan + 0j)
    cycle = np.zeros(P, int)
    ok = np.ones(P, bool)
    done = np.zeros(P, bool)
    previous = np.full(X.shape, np.nan + 0j)
    r = ENDGAME_RADIUS
    for k in range(ENDGAME_RADII):
        live = np.flatnonzero(ok & ~done)
        if not len(live):
            break
        start = X[live].copy()
        cur = start.copy()
        sums = start.copy()
        closed = np.zeros(len(live), bool)
        loops = np.zeros(len(live), int)
        for loop in range(1, MAX_CYCLE + 1):
            going = np.flatnonzero(~closed & ok[live])
            if not len(going):
                break
            for j in range(ENDGAME_SAMPLES):
                lo, hi = 2 * np.pi * j / ENDGAME_SAMPLES, 2 * np.pi * (j + 1) / ENDGAME_SAMPLES
                cur[going], good, step[live[going]] = track(
                    h, cur[going], np.full(len(going), lo), np.full(len(going), hi),
                    lambda p, r=r: 1.0 - r * np.exp(1j * p), lambda p, r=r: -1j * r * np.exp(1j * p),
                    log, index[live[going]], np.full(len(going), hi - lo), hi - lo)
                ok[live[going[~good]]] = False
                going = going[good]
                if j < ENDGAME_SAMPLES - 1:
                    sums[going] += cur[going]
            back = _norm(cur[going] - start[going]) <= CLOSED * _norm(start[going])
            closed[going[back]] = True
            loops[going] = loop
            sums[going[~back]] += cur[going[~back]]  # the next loop's first sample
        finished = closed & ok[live]
        est = np.full(start.shape, np.nan + 0j)
        est[finished] = sums[finished] / (loops[finished] * ENDGAME_SAMPLES)[:, None]
        ok[live[~closed]] = False
        for i in live[~closed]:
            if not log.failure[index[i]]:
                log.failure[index[i]] = f"the path did not close within {MAX_CYCLE} loops around t = 1"
        agree = finished & (_norm(est - previous[live]) <= AGREE * _norm(est)) & (loops == cycle[live])
        # around a branch point short of t = 1 (two roots that nearly meet) the mean of the
        # swapped paths is their midpoint at every radius that encloses it, and agrees with
        # itself: an endpoint of cycle above 1 must also be a root, to sqrt(eps)
        several = agree & (loops > 1)
        if several.any():
            res = _projective_residual(h, est[several])
            agree[np.flatnonzero(several)[res > SINGULAR_RESIDUAL]] = False
        estimate[live[finished]] = est[finished]
        # a path at infinity at two radii in a row needs no more: it is no solution
        at_infinity = finished & (loops == cycle[live]) & (np.abs(est[:, 0]) <= INFINITE * _norm(est)) & (
            np.abs(previous[live][:, 0]) <= INFINITE * _norm(previous[live]))
        agree |= at_infinity
        previous[live[finished]] = est[finished]
        cycle[live[finished]] = loops[finished]
        done[live[agree]] = True
        # closer: along the real line to the next radius
        nxt = np.flatnonzero(ok & ~done)
        if not len(nxt) or k == ENDGAME_RADII - 1:
            break
        r_new = r / 4.0
        X[nxt], good, step[nxt] = track(h, X[nxt], np.full(len(nxt), 1.0 - r), np.full(len(nxt), 1.0 - r_new),
                                        lambda t: t + 0j, lambda t: np.ones_like(t) + 0j,
                                        log, index[nxt], np.full(len(nxt), r), r)
        ok[nxt[~good]] = False
        r = r_new
    # a path whose estimates never agreed keeps its last estimate (singular endpoints
    # converge slowly); classification judges it
    return estimate, cycle, ok


def weights(x: np.ndarray) -> np.ndarray:
    """Each variable's size at x, max(1, |x_v|): the unit its perturbations are measured in."""
    return np.maximum(1.0, np.abs(x))


def equation_sizes(system: PolySystem, x: np.ndarray) -> np.ndarray:
    """Each equation's natural size at x: sum over its terms of |c| prod_v w_v^e_v, w the
    :func:`weights` (what |F_i| is measured against: rounding in evaluating F_i is about eps
    times this). x (n,): (m,); or many points x (P, n): (P, m)."""
    form = system.homogeneous
    X = np.atleast_2d(x)
    W = np.concatenate([np.ones((len(X), 1)), weights(X)], axis=1).astype(complex)
    sizes = (np.abs(form.coefficients) @ form.monomials(W).real).T
    return sizes if np.ndim(x) == 2 else sizes[0]


def condition(system: PolySystem, x: np.ndarray) -> float:
    """mu = 1 / sigma_min(D J W): J = dF/dx at x, each row scaled by D_i = 1 /
    :func:`equation_sizes` and each column by W_v = :func:`weights`. A scale-free stand-in
    for Shub and Smale's condition number (a 1 x 1 Jacobian has the 2-norm condition number
    1 even at a triple root): how much a relative change of the equations moves the root,
    relative to each variable's size; small for a simple root, unbounded at a multiple one."""
    J = system.jacobian(x[None])[0]
    if not np.all(np.isfinite(J)):
        return np.inf
    M = J * weights(x)[None, :] / equation_sizes(system, x)[:, None]
    smallest = float(np.linalg.svd(M, compute_uv=False)[-1])
    return np.inf if smallest == 0.0 else 1.0 / smallest


def relative_residual(system: PolySystem, x: np.ndarray) -> float:
    """max_i |F_i(x)| / :func:`equation_sizes` (x): about eps at a root computed to rounding."""
    F = system.evaluate(x[None])[0]
    return float(np.max(np.abs(F) / equation_sizes(system, x)))


def relative_residuals(system: PolySystem, X: np.ndarray) -> np.ndarray:
    """:func:`relative_residual` at many points X (P, n) at once: (P,)."""
    return np.max(np.abs(system.evaluate(X)) / equation_sizes(system, X), axis=1)


def _refine(system: PolySystem, x: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Newton's method on F at one affine point, while it contracts: (x, residual, mu)."""
    last = np.inf
    F = system.evaluate(x[None])[0]
    for _ in range(12):
        J = system.jacobian(x[None])[0]
        try:
            dx = np.linalg.solve(J, F)
        except np.linalg.LinAlgError:
            break
        size = float(np.linalg.norm(dx))
        F_new = system.evaluate((x - dx)[None])[0]
        # at a multiple root rounding noise over a vanishing J throws Newton anywhere: a
        # step must contract and must not raise the residual
        if not np.isfinite(size) or size > 0.5 * last or np.linalg.norm(F_new) > np.linalg.norm(F):
            break
        x, F, last = x - dx, F_new, size
        if size <= 1e-16 * max(1.0, float(np.linalg.norm(x))):
            break
    return x, relative_residual(system, x), condition(system, x)


def polish_real(system: PolySystem, x: np.ndarray, steps: int = 60) -> tuple[np.ndarray, float]:
    """Newton's method on F in real arithmetic from the real point x, each step halved until
    it lowers max|F| (near a singular J a full step overshoots): (x, the relative residual
    as :class:`Endpoint` reports it)."""
    x = np.asarray(x, dtype=float)

    def worst(z: np.ndarray) -> float:
        return float(np.abs(system.evaluate(z[None].astype(complex))[0]).max())

    res = worst(x)
    for _ in range(steps):
        J = system.jacobian(x[None].astype(complex))[0].real
        F = system.evaluate(x[None].astype(complex))[0].real
        try:
            dx = np.linalg.solve(J, F)
        except np.linalg.LinAlgError:
            break
        factor = 1.0
        while factor > 1e-6:
            trial = x - factor * dx
            r = worst(trial)
            if r < res:
                break
            factor *= 0.5
        else:
            break
        x, res = trial, r
        if res == 0.0:
            break
    return x, relative_residual(system, x.astype(complex))


def solve(system: PolySystem, seed: int = 0, max_step: float = 0.1) -> Solutions:
    """Every isolated solution of a square system: one path per root of the start system
    (:func:`.start.start_for`: a linear product matched to ``system.groups`` where that
    needs fewer paths, else x_i^d_i = 1, Bezout's bound of them)."""
    if len(system.polynomials) != system.n:
        raise ValueError(f"{len(system.polynomials)} equations in {system.n} unknowns: not square")
    began = time.perf_counter()
    rng = np.random.default_rng(seed)
    gamma = complex(np.exp(2j * np.pi * rng.random()))
    patch = rng.normal(size=system.n + 1) + 1j * rng.normal(size=system.n + 1)
    patch /= np.linalg.norm(patch)
    start = start_for(system, rng)
    target = system.homogenised(start.degrees) if start.degrees != system.degrees else system.homogeneous
    h = Homotopy(target, start.form, gamma, patch)
    endpoints = track_all(system, h, on_patch(start.points, patch), max_step)
    return Solutions(system, tuple(endpoints), gamma, time.perf_counter() - began, start.kind)


def on_patch(x: np.ndarray, patch: np.ndarray) -> np.ndarray:
    """Affine points (P, n) as projective ones (1, x) scaled onto the patch a.X = 1."""
    X = np.concatenate([np.ones((len(x), 1), dtype=complex), x], axis=1)
    return X / (X @ patch)[:, None]


def track_all(system: PolySystem, h: PathHomotopy, X: np.ndarray, max_step: float = 0.1) -> list[Endpoint]:
    """Every path of ``h`` from the projective points X (on its patch) to t = 1, each endpoint
    classified against ``system`` (the target, affine). A failed path, or two paths on one
    nonsingular solution (one jumped), is tracked again with smaller steps."""
    endpoints = _run(system, h, X, np.arange(len(X)), max_step, retracked=False)
    again = [i for i, e in enumerate(endpoints) if e.kind == "failed"] + _duplicates(endpoints)
    if again:
        idx = np.array(sorted(set(again)))
        for i, e in zip(idx, _run(system, h, X[idx], idx, max_step / 16.0, retracked=True)):
            endpoints[i] = e
    return endpoints


def _duplicates(endpoints: list[Endpoint]) -> list[int]:
    """Paths whose endpoints coincide at a well-conditioned root (a nonsingular root ends one
    path only: two on it mean one jumped, and a root was missed). An endpoint reached with
    cycle number 2 at a root of small condition is such a pair too."""
    fin = [(i, e.x) for i, e in enumerate(endpoints)
           if e.kind in ("finite", "singular") and e.x is not None and e.condition <= SINGULAR_CONDITION]
    out = []
    for a in range(len(fin)):
        for b in range(a + 1, len(fin)):
            i, xi = fin[a]
            j, xj = fin[b]
            if np.linalg.norm(xi - xj) <= 1e-8 * max(1.0, float(np.linalg.norm(xi))):
                out += [i, j]
    return out


STRAIGHT_CONDITION = 1e6
"""A path tracked on from t = 1 - ENDGAME_RADIUS to t = 1 itself ends there without the
endgame when its end is finite (|X0| / |X| above ENDGAME_FINITE) and the target's Jacobian
on the patch, rows scaled to unit length, has a condition number below this: a
nonsingular root, reached by a converged corrector (cycle number 1). Every other path,
singular or going to infinity, takes the endgame from t = 1 - ENDGAME_RADIUS."""
ENDGAME_FINITE = 1e-4


def _straight(h: PathHomotopy, X: np.ndarray, ok: np.ndarray, log: PathLog,
              step: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which paths end at a nonsingular root when tracked straight on to t = 1, and their
    ends: (mask over all paths, ends). The attempt's steps are added to the paths' logs; a
    path whose attempt fails is not failed (the endgame takes it), so its reason is dropped."""
    P = len(X)
    mask = np.zeros(P, bool)
    live = np.flatnonzero(ok)
    if not len(live):
        return mask, X
    trial = PathLog.empty(len(live))
    ends, good, _ = track(h, X[live], np.full(len(live), 1.0 - ENDGAME_RADIUS), np.ones(len(live)),
                          lambda t: t + 0j, lambda t: np.ones_like(t) + 0j, trial, np.arange(len(live)),
                          step[live].copy(), ENDGAME_RADIUS)
    log.steps[live] += trial.steps
    log.rejected[live] += trial.rejected
    log.newton[live] += trial.newton
    log.smallest_step[live] = np.minimum(log.smallest_step[live], trial.smallest_step)
    finite = np.abs(ends[:, 0]) > ENDGAME_FINITE * _norm(ends)
    _, J, _ = h.residual_and_jacobians(ends, np.ones(len(live)))
    J = J / np.maximum(_norm(J), 1e-300)[:, :, None]
    with np.errstate(all="ignore"):
        cond = np.linalg.cond(J)
    mask[live] = good & finite & (cond <= STRAIGHT_CONDITION)
    out = X.copy()
    out[live] = ends
    return mask, out


def _run(system: PolySystem, h: PathHomotopy, X: np.ndarray, paths: np.ndarray, max_step: float,
         retracked: bool) -> list[Endpoint]:
    P = len(X)
    log = PathLog.empty(P)
    index = np.arange(P)
    step = np.full(P, max_step / 4.0)
    X, ok, step = track(h, X, np.zeros(P), np.full(P, 1.0 - ENDGAME_RADIUS), lambda t: t + 0j,
                        lambda t: np.ones_like(t) + 0j, log, index, step, max_step)
    est = np.full(X.shape, np.nan + 0j)
    cycle = np.zeros(P, int)
    straight, ends = _straight(h, X, ok, log, step)
    est[straight], cycle[straight] = ends[straight], 1
    live = np.flatnonzero(ok & ~straight)
    if len(live):
        e, c, good = _endgame(h, X[live], live, log, step[live], max_step)
        est[live], cycle[live] = e, c
        ok[live[~good]] = False
    out = []
    for i in range(P):
        common = dict(cycle=int(cycle[i]), steps=int(log.steps[i]), rejected=int(log.rejected[i]),
                      newton=int(log.newton[i]), smallest_step=float(log.smallest_step[i]),
                      retracked=retracked, endgame=not straight[i])
        if not ok[i] or not np.all(np.isfinite(est[i])):
            out.append(Endpoint("failed", None, False, np.inf, np.inf, note=log.failure[i] or "no estimate",
                                **common))
            continue
        Xi = est[i]
        if abs(Xi[0]) <= INFINITE * np.linalg.norm(Xi):
            out.append(Endpoint("infinite", None, False, np.inf, np.inf, **common))
            continue
        x, residual, cond = _refine(system, Xi[1:] / Xi[0])
        singular = cycle[i] > 1 or not cond <= SINGULAR_CONDITION
        real = system.realness(x) <= REAL
        if real:
            x = system.nearest_real(x)
        out.append(Endpoint("singular" if singular else "finite", x, real, residual, cond, **common))
    return out
